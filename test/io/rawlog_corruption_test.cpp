// RawlogReader on corrupt rawlogs built here with MRPT: length fields set to what would make MRPT
// allocate gigabytes (or crash: a beam count of 2^30 makes resizeScan write through a null
// pointer), impossible classes, versions and flags, and values MRPT reads but no sensor produces.
// Each must end reading with kError (or kTruncated when the data simply stops), fast, with one
// printable line that names the entry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include "evidential_slam/io/rawlog_reader.h"

namespace evidential_slam {
namespace io {
namespace {

// Serialised MRPT objects, back to back: a plain (uncompressed) rawlog.
class Bytes {
 public:
  Bytes& operator<<(const mrpt::serialization::CSerializable& object) {
    mrpt::io::CMemoryStream stream;
    auto archive = mrpt::serialization::archiveFrom(stream);
    archive << object;
    data_.append(static_cast<const char*>(stream.getRawBufferData()),
                 static_cast<size_t>(stream.getTotalBytesCount()));
    return *this;
  }
  Bytes& raw(const std::string& bytes) {
    data_ += bytes;
    return *this;
  }
  std::string& str() { return data_; }

 private:
  std::string data_;
};

mrpt::obs::CObservationOdometry odometry(double t, double x, double y = 0.0, double phi = 0.0) {
  mrpt::obs::CObservationOdometry o;
  o.timestamp = mrpt::Clock::fromDouble(t);
  o.odometry = mrpt::poses::CPose2D(x, y, phi);
  return o;
}

mrpt::obs::CObservation2DRangeScan scan(double t, size_t beams = 7) {
  mrpt::obs::CObservation2DRangeScan s;
  s.timestamp = mrpt::Clock::fromDouble(t);
  s.sensorLabel = "LIDAR";
  s.aperture = static_cast<float>(M_PI);
  s.maxRange = 30.0f;
  s.resizeScanAndAssign(beams, 2.0f, true);
  return s;
}

// Where the payload of the first serialised object of class `name` (a full MRPT class name)
// starts: after its name and its version byte.
size_t payloadOf(const std::string& bytes, const std::string& name) {
  const size_t at = bytes.find(name);
  EXPECT_NE(at, std::string::npos) << name;
  return at + name.size() + 1;
}

void put32(std::string* bytes, size_t at, uint32_t value) {
  ASSERT_LE(at + 4, bytes->size());
  std::memcpy(&(*bytes)[at], &value, 4);
}

struct Outcome {
  RawlogReader::Status status = RawlogReader::Status::kEnd;
  size_t scans = 0;
  std::string message;
  RawlogCounts counts;
};

Outcome readBytes(const std::string& bytes, const RawlogReaderConfig& config = {}) {
  RawlogReader reader(config);
  std::string error;
  Outcome o;
  EXPECT_TRUE(reader.openBytes(bytes, "test.rawlog", &error)) << error;
  RawlogScan s;
  while ((o.status = reader.next(&s)) == RawlogReader::Status::kScan) ++o.scans;
  o.message = reader.message();
  o.counts = reader.counts();
  return o;
}

// kError with a message holding `expect`, on one line of printable ASCII.
void expectCorrupt(const Outcome& o, const std::string& expect) {
  EXPECT_EQ(o.status, RawlogReader::Status::kError) << o.message;
  EXPECT_NE(o.message.find(expect), std::string::npos) << o.message;
  for (char c : o.message) {
    ASSERT_TRUE(c >= 0x20 && c < 0x7f) << "unprintable byte in: " << o.message;
  }
}

// An odometry sample and a 7-beam scan: a valid two-entry log to corrupt.
std::string twoEntries() {
  Bytes b;
  b << odometry(10.0, 0.0) << scan(10.0);
  return b.str();
}

// The scan's beam count: after its aperture, direction flag, maximum range and sensor pose
// (a CPose3D of version 3: twelve doubles and the end flag).
size_t beamCountAt(const std::string& bytes) {
  const size_t pose = payloadOf(bytes, "mrpt::poses::CPose3D");
  return pose + 12 * 8 + 1;
}

TEST(RawlogCorruption, ValidLogReads) {
  const Outcome o = readBytes(twoEntries());
  EXPECT_EQ(o.status, RawlogReader::Status::kEnd);
  EXPECT_EQ(o.scans, 1u);
  EXPECT_EQ(o.counts.entries, 2u);
  EXPECT_EQ(o.counts.unchecked_entries, 0u);
}

TEST(RawlogCorruption, HugeBeamCountIsRejectedBeforeMrptAllocates) {
  for (uint32_t beams : {100001u, 1u << 28, 1u << 30, 0xffffffffu}) {
    std::string bytes = twoEntries();
    put32(&bytes, beamCountAt(bytes), beams);
    const Outcome o = readBytes(bytes);
    expectCorrupt(o, "rawlog entry 2");
    expectCorrupt(o, std::to_string(beams) + " beams in a scan (more than the 100000 allowed)");
  }
}

TEST(RawlogCorruption, BeamCountBeyondTheDataIsATruncation) {
  std::string bytes = twoEntries();
  put32(&bytes, beamCountAt(bytes), 5000);  // within the limit, but the data ends first
  const Outcome o = readBytes(bytes);
  EXPECT_EQ(o.status, RawlogReader::Status::kTruncated) << o.message;
  EXPECT_NE(o.message.find("ends inside rawlog entry 2"), std::string::npos) << o.message;
}

TEST(RawlogCorruption, BeamLimitIsAConfig) {
  RawlogReaderConfig config;
  config.limits.max_beams = 6;
  expectCorrupt(readBytes(twoEntries(), config), "7 beams in a scan (more than the 6 allowed)");
  config.limits.max_beams = 7;
  EXPECT_EQ(readBytes(twoEntries(), config).status, RawlogReader::Status::kEnd);
}

TEST(RawlogCorruption, HugeLabelLength) {
  std::string bytes = twoEntries();
  const size_t label = bytes.find("LIDAR", beamCountAt(bytes));
  ASSERT_NE(label, std::string::npos);
  put32(&bytes, label - 4, 0x80000000u);
  expectCorrupt(readBytes(bytes),
                "a sensor label of 2147483648 bytes (more than the 4096 allowed)");
}

TEST(RawlogCorruption, HugeObjectCounts) {
  mrpt::obs::CActionCollection actions;
  mrpt::obs::CActionRobotMovement2D move;
  move.computeFromOdometry(mrpt::poses::CPose2D(0.1, 0, 0), {});
  actions.insert(move);
  mrpt::obs::CSensoryFrame frame;
  frame.insert(mrpt::obs::CObservation2DRangeScan::Create(scan(10.0)));
  Bytes b;
  b << actions << frame;
  {
    std::string bytes = b.str();
    put32(&bytes, payloadOf(bytes, "mrpt::obs::CActionCollection"), 1u << 30);
    expectCorrupt(readBytes(bytes), "1073741824 actions in a collection");
  }
  {
    std::string bytes = b.str();
    put32(&bytes, payloadOf(bytes, "mrpt::obs::CSensoryFrame"), 0xffffffffu);
    expectCorrupt(readBytes(bytes), "4294967295 observations in a sensory frame");
  }
  EXPECT_EQ(readBytes(b.str()).status, RawlogReader::Status::kEnd);
}

// MRPT's Thrun odometry model draws as many samples as the action says, at read time.
TEST(RawlogCorruption, MotionModelSampleCount) {
  mrpt::obs::CActionRobotMovement2D::TMotionModelOptions options;
  options.modelSelection = mrpt::obs::CActionRobotMovement2D::mmThrun;
  options.thrunModel.nParticlesCount = 50;
  mrpt::obs::CActionCollection actions;
  mrpt::obs::CActionRobotMovement2D move;
  move.computeFromOdometry(mrpt::poses::CPose2D(0.1, 0, 0), options);
  actions.insert(move);
  mrpt::obs::CSensoryFrame frame;
  frame.insert(mrpt::obs::CObservation2DRangeScan::Create(scan(10.0)));
  Bytes b;
  b << actions << frame;
  EXPECT_EQ(readBytes(b.str()).status, RawlogReader::Status::kEnd);
  // The count follows the increment (CPose2D: header, 3 doubles, end flag), the model and the
  // six Gaussian-model floats.
  std::string bytes = b.str();
  const size_t count_at = payloadOf(bytes, "mrpt::poses::CPose2D") + 24 + 1 + 4 + 24;
  uint32_t stored = 0;
  std::memcpy(&stored, &bytes[count_at], 4);
  ASSERT_EQ(stored, 50u);
  put32(&bytes, count_at, 0xfffffff0u);  // -16 as MRPT's int32
  expectCorrupt(readBytes(bytes), "a motion model of -16 samples");
}

TEST(RawlogCorruption, ImpossibleClassesVersionsAndFlags) {
  {  // an object that is no rawlog entry
    Bytes b;
    b << mrpt::poses::CPose2D(1, 2, 3);
    expectCorrupt(readBytes(b.str()),
                  "not an MRPT rawlog: a mrpt::poses::CPose2D where a rawlog entry was expected");
  }
  {  // a class name that is no class, with bytes that are no text
    const std::string name =
        "C\x01\xff\x7f"
        "foo";
    Bytes b;
    b << odometry(10.0, 0.0);
    b.raw(std::string(1, static_cast<char>(0x80 | name.size())) + name + "\x01\x88");
    expectCorrupt(readBytes(b.str()), "an object of unknown class 'C\\x01\\xff\\x7ffoo'");
  }
  {  // a version MRPT does not know
    std::string bytes = twoEntries();
    bytes[payloadOf(bytes, "mrpt::obs::CObservation2DRangeScan") - 1] = 9;
    expectCorrupt(readBytes(bytes), "a mrpt::obs::CObservation2DRangeScan of unknown version 9");
  }
  {  // a flag that decides what follows, neither 0 nor 1
    std::string bytes = twoEntries();
    const size_t label = bytes.find("LIDAR", beamCountAt(bytes));
    bytes[label + 5 + 8] = 2;  // has-intensity, after the label and the pitch step
    expectCorrupt(readBytes(bytes), "a has-intensity flag of 2");
  }
  {  // a null observation in a sensory frame (MRPT would hand out a null pointer)
    mrpt::obs::CActionCollection actions;
    mrpt::obs::CSensoryFrame frame;
    frame.insert(mrpt::obs::CObservation2DRangeScan::Create(scan(10.0)));
    Bytes b;
    b << actions << frame;
    std::string bytes = b.str();
    const std::string name = "mrpt::obs::CObservation2DRangeScan";
    const size_t at = bytes.find(name);
    // Replace the scan (header through end flag: the rest of the data) with "nullptr".
    bytes = bytes.substr(0, at - 1) + std::string(1, static_cast<char>(0x80 | 7)) + "nullptr" +
            "\x88" + "\x88";
    expectCorrupt(readBytes(bytes), "a null object where an observation was expected");
  }
  {  // a sensory frame holding a pose
    mrpt::obs::CActionCollection actions;
    mrpt::obs::CSensoryFrame frame;
    frame.insert(mrpt::obs::CObservation2DRangeScan::Create(scan(10.0)));
    Bytes b;
    b << actions << frame;
    std::string bytes = b.str();
    const size_t at = bytes.find("mrpt::obs::CObservation2DRangeScan");
    Bytes pose;
    pose << mrpt::poses::CPose2D(1, 2, 3);
    bytes = bytes.substr(0, at - 1) + pose.str() + "\x88";
    expectCorrupt(readBytes(bytes), "a mrpt::poses::CPose2D where an observation was expected");
  }
}

TEST(RawlogCorruption, ObjectLongerThanTheLimit) {
  RawlogReaderConfig config;
  config.limits.max_object_bytes = 1024;
  Bytes b;
  b << odometry(10.0, 0.0) << scan(10.0, 500);  // 500 beams: 2.5 kB
  expectCorrupt(readBytes(b.str(), config), "an object longer than 1024 bytes");
}

TEST(RawlogCorruption, ImpossibleScanValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct Case {
    float aperture, max_range, noise;
    const char* expect;
  };
  for (const Case& c : {Case{nan, 30.0f, 0.01f, "a scan aperture of nan rad"},
                        Case{inf, 30.0f, 0.01f, "a scan aperture of inf rad"},
                        Case{0.0f, 30.0f, 0.01f, "a scan aperture of 0 rad"},
                        Case{1e30f, 30.0f, 0.01f, "a scan aperture of 1e+30 rad"},
                        Case{-1.0f, 30.0f, 0.01f, "a scan aperture of -1 rad"},
                        Case{3.0f, nan, 0.01f, "a scan maximum range of nan m"},
                        Case{3.0f, -5.0f, 0.01f, "a scan maximum range of -5 m"},
                        Case{3.0f, 30.0f, nan, "a scan range noise of nan m"}}) {
    auto s = scan(10.0);
    s.aperture = c.aperture;
    s.maxRange = c.max_range;
    s.stdError = c.noise;
    Bytes b;
    b << odometry(10.0, 0.0) << s;
    const Outcome o = readBytes(b.str());
    expectCorrupt(o, c.expect);
    expectCorrupt(o, "corrupt at rawlog entry 2");
  }
  auto s = scan(10.0);
  s.sensorPose = mrpt::poses::CPose3D(std::nan(""), 0, 0, 0, 0, 0);
  Bytes b;
  b << odometry(10.0, 0.0) << s;
  expectCorrupt(readBytes(b.str()), "a laser pose on the robot at (nan, 0, 0)");
  // A full turn (as float) is a possible aperture.
  s = scan(10.0, 360);
  s.aperture = static_cast<float>(2.0 * M_PI);
  Bytes full;
  full << odometry(10.0, 0.0) << s;
  EXPECT_EQ(readBytes(full.str()).status, RawlogReader::Status::kEnd);
}

// MRPT spreads the aperture over n - 1 steps, so a one-beam scan's bearing would be NaN.
TEST(RawlogCorruption, OneBeamScanLooksAhead) {
  Bytes b;
  b << odometry(10.0, 0.0) << scan(10.0, 1);
  RawlogReader reader;
  std::string error;
  ASSERT_TRUE(reader.openBytes(b.str(), "one beam", &error)) << error;
  RawlogScan s;
  ASSERT_EQ(reader.next(&s), RawlogReader::Status::kScan) << reader.message();
  ASSERT_EQ(s.scan.bearings.size(), 1u);
  EXPECT_EQ(s.scan.bearings[0], 0.0f);
}

TEST(RawlogCorruption, ImpossibleOdometry) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double x : {nan, std::numeric_limits<double>::infinity(), 1e30, -2e5}) {
    SCOPED_TRACE(x);
    Bytes b;
    b << odometry(10.0, 0.0) << scan(10.0) << odometry(11.0, x);
    const Outcome o = readBytes(b.str());
    expectCorrupt(o, "corrupt at rawlog entry 3");
    expectCorrupt(o, "an odometry pose of (");
  }
  Bytes heading;
  heading << odometry(10.0, 0.0, 0.0, nan) << scan(10.0);
  expectCorrupt(readBytes(heading.str()), "an odometry pose of (0, 0, nan)");

  // An increment of an action, and the pose its increments add up to.
  auto frameLog = [](double dx, int steps) {
    Bytes b;
    for (int i = 0; i < steps; ++i) {
      mrpt::obs::CActionCollection actions;
      mrpt::obs::CActionRobotMovement2D move;
      move.computeFromOdometry(mrpt::poses::CPose2D(dx, 0, 0), {});
      actions.insert(move);
      mrpt::obs::CSensoryFrame frame;
      frame.insert(mrpt::obs::CObservation2DRangeScan::Create(scan(10.0 + i)));
      b << actions << frame;
    }
    return b.str();
  };
  expectCorrupt(readBytes(frameLog(nan, 1)), "an odometry increment of (nan, 0, 0)");
  RawlogReaderConfig config;
  config.limits.max_coordinate = 50.0;
  expectCorrupt(readBytes(frameLog(30.0, 2), config), "an odometry pose of (60, 0, 0)");
  EXPECT_EQ(readBytes(frameLog(20.0, 2), config).status, RawlogReader::Status::kEnd);
}

// An observation of a class the pre-check does not know (here a comment) stops reading, unless
// unchecked classes are allowed: then MRPT reads it, the reader ignores it and the scans around it
// still come out.
TEST(RawlogCorruption, OtherObservationClassesOnlyWhenAllowed) {
  mrpt::obs::CObservationComment comment;
  comment.text = "hello";
  Bytes b;
  b << odometry(10.0, 0.0) << comment << scan(10.0) << odometry(11.0, 1.0);
  const Outcome strict = readBytes(b.str());
  expectCorrupt(strict, "holds a mrpt::obs::CObservationComment at rawlog entry 2");
  expectCorrupt(strict, "rawlog-edit --keep-label");
  RawlogReaderConfig config;
  config.allow_unchecked_classes = true;
  const Outcome o = readBytes(b.str(), config);
  EXPECT_EQ(o.status, RawlogReader::Status::kEnd) << o.message;
  EXPECT_EQ(o.scans, 1u);
  EXPECT_EQ(o.counts.unchecked_entries, 1u);
  EXPECT_EQ(o.counts.other_observations, 1u);
}

TEST(RawlogCorruption, LimitsAreValidated) {
  RawlogLimits limits;
  std::string why;
  EXPECT_TRUE(limits.isValid(&why)) << why;
  limits.max_beams = 0;
  EXPECT_FALSE(limits.isValid(&why));
  EXPECT_NE(why.find("max_beams"), std::string::npos) << why;
  RawlogReaderConfig config;
  config.limits.max_coordinate = std::nan("");
  RawlogReader reader(config);
  std::string error;
  EXPECT_FALSE(reader.openBytes(twoEntries(), "x", &error));
  EXPECT_NE(error.find("max_coordinate"), std::string::npos) << error;
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
