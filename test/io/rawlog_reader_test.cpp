// RawlogReader on the committed fixtures (both rawlog formats), on rawlogs built here with MRPT to
// pin odometry interpolation and sensor poses, and on broken inputs (missing, garbage, truncated).
#include "evidential_slam/io/rawlog_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/ground_truth.h"
#include "rawlog_fixtures.h"
#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

using test::dataPath;
using test::scratchDir;

constexpr size_t kFixtureScans = 159;

std::vector<RawlogScan> readAll(const std::string& path, RawlogReader::Status* status,
                                RawlogCounts* counts = nullptr,
                                const RawlogReaderConfig& config = {},
                                std::string* message = nullptr) {
  RawlogReader reader(config);
  std::string error;
  EXPECT_TRUE(reader.open(path, &error)) << error;
  std::vector<RawlogScan> scans;
  RawlogScan s;
  while ((*status = reader.next(&s)) == RawlogReader::Status::kScan) scans.push_back(s);
  if (counts) *counts = reader.counts();
  if (message) *message = reader.message();
  return scans;
}

double angleDiff(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

TEST(RawlogReader, ReadsActionsSensoryFramesFixture) {
  RawlogReader::Status status;
  RawlogCounts counts;
  const auto scans = readAll(dataPath("sim.rawlog"), &status, &counts);
  // simul-gridmap style logs end with an action that has no frame: still a clean end.
  EXPECT_EQ(status, RawlogReader::Status::kEnd);
  ASSERT_EQ(scans.size(), kFixtureScans);
  EXPECT_EQ(counts.scans, kFixtureScans);
  EXPECT_EQ(counts.scans_without_odometry, 0u);
  EXPECT_EQ(counts.odometry_samples, kFixtureScans);

  std::vector<StampedPose> truth;
  std::string error;
  ASSERT_TRUE(readGroundTruth(dataPath("sim.GT.txt"), &truth, &error)) << error;
  ASSERT_EQ(truth.size(), kFixtureScans);

  for (size_t i = 0; i < scans.size(); ++i) {
    const LaserScan& s = scans[i].scan;
    ASSERT_EQ(s.size(), 181u);
    ASSERT_EQ(s.bearings.size(), 181u);
    ASSERT_EQ(s.valid.size(), 181u);
    EXPECT_TRUE(s.isConsistent(nullptr));
    EXPECT_EQ(scans[i].label, "LASER");
    EXPECT_NEAR(s.stamp, truth[i].stamp, 1e-5);
    // 180 degrees counter-clockwise (rightToLeft), right to left.
    EXPECT_NEAR(s.bearings.front(), -M_PI / 2, 1e-5);
    EXPECT_NEAR(s.bearings.back(), M_PI / 2, 1e-5);
    EXPECT_GT(s.max_range, 0.0f);
    // simul-gridmap declares 0.01 m range noise (CObservation2DRangeScan::stdError); the beam
    // models use it as their lower bound on σ.
    EXPECT_FLOAT_EQ(s.range_sigma, 0.01f);
  }
  // Odometry starts at the origin and follows the true motion up to the simulated noise.
  EXPECT_NEAR(scans[0].odometry.x, 0.0, 1e-12);
  EXPECT_NEAR(scans[0].odometry.theta, 0.0, 1e-12);
  for (size_t i = 1; i < scans.size(); ++i) {
    const Pose2 odo_step = scans[i - 1].odometry.between(scans[i].odometry);
    const Pose2 true_step = truth[i - 1].pose.between(truth[i].pose);
    EXPECT_NEAR(odo_step.x, true_step.x, 0.05) << i;
    EXPECT_NEAR(odo_step.y, true_step.y, 0.05) << i;
    // The simulated heading noise grows with the turn (sigma 0.05 rad/rad).
    EXPECT_NEAR(angleDiff(odo_step.theta, true_step.theta), 0.0,
                0.03 + 0.25 * std::abs(true_step.theta))
        << i;
  }
}

TEST(RawlogReader, ObservationOnlyFixtureMatchesActionsFormat) {
  RawlogReader::Status sf_status, obs_status;
  RawlogCounts counts;
  const auto sf = readAll(dataPath("sim.rawlog"), &sf_status);
  RawlogReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(dataPath("sim_obs.rawlog"), &error)) << error;
  std::vector<RawlogScan> obs;
  RawlogScan s;
  while ((obs_status = reader.next(&s)) == RawlogReader::Status::kScan) obs.push_back(s);
  EXPECT_EQ(obs_status, RawlogReader::Status::kEnd);
  EXPECT_EQ(reader.format(), RawlogFormat::kObservations);
  ASSERT_EQ(obs.size(), sf.size());
  for (size_t i = 0; i < obs.size(); ++i) {
    EXPECT_DOUBLE_EQ(obs[i].scan.stamp, sf[i].scan.stamp);
    EXPECT_NEAR(obs[i].odometry.x, sf[i].odometry.x, 1e-9);
    EXPECT_NEAR(obs[i].odometry.y, sf[i].odometry.y, 1e-9);
    EXPECT_NEAR(angleDiff(obs[i].odometry.theta, sf[i].odometry.theta), 0.0, 1e-9);
    EXPECT_EQ(obs[i].scan.ranges, sf[i].scan.ranges);
  }
}

TEST(RawlogReader, FiltersByLabel) {
  RawlogReader::Status status;
  RawlogCounts counts;
  RawlogReaderConfig config;
  config.laser_label = "LASER";
  EXPECT_EQ(readAll(dataPath("sim.rawlog"), &status, &counts, config).size(), kFixtureScans);
  config.laser_label = "NO_SUCH_LASER";
  EXPECT_TRUE(readAll(dataPath("sim.rawlog"), &status, &counts, config).empty());
  EXPECT_EQ(counts.scans, 0u);
  EXPECT_EQ(counts.other_observations, kFixtureScans);
}

TEST(RawlogReader, SurveyCountsWithoutKeeping) {
  RawlogSurvey survey;
  std::string error;
  ASSERT_TRUE(surveyRawlog(dataPath("sim_obs.rawlog"), {}, &survey, &error)) << error;
  EXPECT_EQ(survey.status, RawlogReader::Status::kEnd);
  EXPECT_EQ(survey.format, RawlogFormat::kObservations);
  EXPECT_EQ(survey.counts.scans, kFixtureScans);
  EXPECT_EQ(survey.counts.scans_emitted, kFixtureScans);
  EXPECT_EQ(survey.counts.odometry_samples, kFixtureScans);
  EXPECT_GT(survey.last_stamp, survey.first_stamp);
}

TEST(RawlogReader, MissingFileIsAClearError) {
  RawlogReader reader;
  std::string error;
  EXPECT_FALSE(reader.open(dataPath("no_such_file.rawlog"), &error));
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_FALSE(reader.open(ES_TEST_DATA_DIR, &error));
  EXPECT_NE(error.find("directory"), std::string::npos) << error;
  for (const char* device : {"/dev/zero", "/dev/urandom", "/dev/null"}) {
    EXPECT_FALSE(reader.open(device, &error)) << device;
    EXPECT_EQ(error,
              std::string("rawlog '") + device + "' is not a regular file (a device or a pipe)");
  }
}

TEST(RawlogReader, GarbageIsNotARawlog) {
  const auto dir = scratchDir();
  const std::vector<std::string> garbage = {
      "t x y phi\n1 2 3 4\n",                      // a text file
      std::string("\x1f\x8b\x08\x00garbage", 12),  // a broken gzip header
      std::string(4096, '\xff'),                   // binary noise
      std::string("\x85"
                  "CFoo\x00\x88",
                  7),  // an unknown class
  };
  for (size_t i = 0; i < garbage.size(); ++i) {
    const auto path = dir / ("garbage" + std::to_string(i) + ".rawlog");
    test::writeText(path, garbage[i]);
    RawlogReader::Status status;
    RawlogCounts counts;
    std::string message;
    const auto scans = readAll(path.string(), &status, &counts, {}, &message);
    EXPECT_EQ(status, RawlogReader::Status::kError) << i;
    EXPECT_TRUE(scans.empty()) << i;
    EXPECT_NE(message.find("not an MRPT rawlog"), std::string::npos) << i << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(RawlogReader, EmptyFileHasNoScans) {
  const auto path = scratchDir() / "empty.rawlog";
  test::writeText(path, "");
  RawlogReader::Status status;
  EXPECT_TRUE(readAll(path.string(), &status).empty());
  EXPECT_EQ(status, RawlogReader::Status::kEnd);
}

// Decompresses a .rawlog with MRPT so the plain (non-gzip) form is covered too.
void gunzip(const std::string& in, const std::string& out) {
  mrpt::io::CFileGZInputStream src(in);
  std::ofstream dst(out, std::ios::binary);
  char buf[65536];
  size_t n;
  while ((n = src.Read(buf, sizeof(buf))) > 0 && n <= sizeof(buf)) dst.write(buf, n);
}

TEST(RawlogReader, ReadsPlainRawlog) {
  const auto path = scratchDir() / "plain.rawlog";
  gunzip(dataPath("sim.rawlog"), path.string());
  RawlogReader::Status status;
  EXPECT_EQ(readAll(path.string(), &status).size(), kFixtureScans);
  EXPECT_EQ(status, RawlogReader::Status::kEnd);
}

TEST(RawlogReader, TruncatedFileKeepsEntriesAndWarns) {
  const auto dir = scratchDir();
  const auto plain = dir / "plain.rawlog";
  gunzip(dataPath("sim.rawlog"), plain.string());
  for (const std::string& source : {dataPath("sim.rawlog"), plain.string()}) {
    size_t previous = 0;
    for (double fraction : {0.2, 0.5, 0.77, 0.93}) {
      const auto cut = dir / "cut.rawlog";
      std::string error;
      ASSERT_TRUE(test::truncateCopy(source, cut.string(), fraction, &error)) << error;
      RawlogReader::Status status;
      RawlogCounts counts;
      std::string message;
      const auto scans = readAll(cut.string(), &status, &counts, {}, &message);
      EXPECT_EQ(status, RawlogReader::Status::kTruncated) << source << " at " << fraction;
      EXPECT_NE(message.find("ends inside rawlog entry"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_GT(scans.size(), previous) << fraction;
      EXPECT_LT(scans.size(), kFixtureScans) << fraction;
      previous = scans.size();
    }
  }
}

// --- rawlogs built here -------------------------------------------------------------------------

class SyntheticLog {
 public:
  explicit SyntheticLog(const std::string& path) : file_(path), archive_(file_) {}
  void odometry(double t, double x, double y, double phi) {
    mrpt::obs::CObservationOdometry o;
    o.timestamp = mrpt::Clock::fromDouble(t);
    o.odometry = mrpt::poses::CPose2D(x, y, phi);
    archive_ << o;
  }
  void scan(double t, const mrpt::poses::CPose3D& sensor = {}, bool right_to_left = true,
            float std_error = 0.01f) {
    mrpt::obs::CObservation2DRangeScan s;
    s.stdError = std_error;
    s.timestamp = mrpt::Clock::fromDouble(t);
    s.sensorLabel = "LIDAR";
    s.aperture = static_cast<float>(M_PI);
    s.rightToLeft = right_to_left;
    s.maxRange = 30.0f;
    s.sensorPose = sensor;
    s.resizeScanAndAssign(5, 2.0f, true);
    s.setScanRangeValidity(4, false);
    archive_ << s;
  }

 private:
  mrpt::io::CFileGZOutputStream file_;
  mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZOutputStream> archive_;
};

TEST(RawlogReader, InterpolatesAbsoluteOdometryToScanTimes) {
  const auto path = (scratchDir() / "interp.rawlog").string();
  {
    SyntheticLog log(path);
    log.scan(1000.2);  // 0.8 s before the first odometry: no odometry, dropped
    log.odometry(1001.0, 0, 0, 0);
    log.scan(1001.5);  // between two samples, written before the later one
    log.odometry(1002.0, 1, 0, 0);
    log.scan(1002.5);
    log.odometry(1003.0, 2, 0, M_PI / 2);
    log.scan(1003.0);  // exactly on a sample
    log.scan(1003.3);  // 0.3 s after the last sample: held
    log.scan(1005.0);  // 2 s after it: dropped
  }
  RawlogReader::Status status;
  RawlogCounts counts;
  const auto scans = readAll(path, &status, &counts);
  EXPECT_EQ(status, RawlogReader::Status::kEnd);
  ASSERT_EQ(scans.size(), 4u);
  EXPECT_EQ(counts.scans, 6u);
  EXPECT_EQ(counts.scans_without_odometry, 2u);
  EXPECT_NEAR(scans[0].scan.stamp, 1001.5, 1e-6);
  EXPECT_NEAR(scans[0].odometry.x, 0.5, 1e-6);
  EXPECT_NEAR(scans[0].odometry.y, 0.0, 1e-6);
  // Half of the increment (1, 0, pi/2) from (1, 0, 0).
  EXPECT_NEAR(scans[1].odometry.x, 1.5, 1e-6);
  EXPECT_NEAR(scans[1].odometry.theta, M_PI / 4, 1e-6);
  EXPECT_NEAR(scans[2].odometry.x, 2.0, 1e-9);
  EXPECT_NEAR(scans[2].odometry.theta, M_PI / 2, 1e-9);
  EXPECT_NEAR(scans[3].odometry.x, 2.0, 1e-9);
  EXPECT_NEAR(scans[3].odometry.theta, M_PI / 2, 1e-9);
  // Validity and bearings come through.
  EXPECT_EQ(scans[0].scan.valid, (std::vector<uint8_t>{1, 1, 1, 1, 0}));
  EXPECT_EQ(scans[0].label, "LIDAR");
  EXPECT_FLOAT_EQ(scans[0].scan.max_range, 30.0f);
}

// A scan or an odometry sample older than the one before it is skipped (and reported): the
// scans come out in time order and the odometry is interpolated between in-order samples only.
TEST(RawlogReader, OutOfOrderStampsAreSkipped) {
  const auto path = (scratchDir() / "backwards.rawlog").string();
  {
    SyntheticLog log(path);
    log.odometry(10.0, 0, 0, 0);
    log.scan(10.0);
    log.odometry(11.0, 1, 0, 0);
    log.scan(11.0);
    log.odometry(10.5, 5, 5, 0);  // older than the sample before it
    log.scan(10.8);               // older than the scan before it
    log.odometry(12.0, 2, 0, 0);
    log.scan(11.5);
    log.scan(12.0);
  }
  RawlogReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(path, &error)) << error;
  std::vector<RawlogScan> scans;
  RawlogScan s;
  while (reader.next(&s) == RawlogReader::Status::kScan) scans.push_back(s);
  ASSERT_EQ(scans.size(), 4u);
  EXPECT_EQ(reader.counts().scans_out_of_order, 1u);
  EXPECT_EQ(reader.counts().odometry_out_of_order, 1u);
  EXPECT_EQ(reader.counts().odometry_samples, 3u);
  EXPECT_NEAR(scans[2].scan.stamp, 11.5, 1e-6);
  EXPECT_NEAR(scans[2].odometry.x, 1.5, 1e-6);  // between (1, 0) and (2, 0), not via (5, 5)
  EXPECT_NEAR(scans[2].odometry.y, 0.0, 1e-6);
  for (size_t i = 1; i < scans.size(); ++i) {
    EXPECT_GE(scans[i].scan.stamp, scans[i - 1].scan.stamp);
  }
  const auto warnings = reader.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("time went backwards"), std::string::npos) << warnings[0];
}

// One scan and one odometry sample stamped 3 h ahead (a driver's glitch): each is an outlier,
// skipped once, and the rest of the log is read (the reader once kept the future stamp and skipped
// every later scan as out of order). Three in a row are believed, as the session believes them.
TEST(RawlogReader, AFarFutureStampIsAnOutlierAndTheLogGoesOn) {
  const auto path = (scratchDir() / "future.rawlog").string();
  {
    SyntheticLog log(path);
    for (int i = 0; i < 10; ++i) {
      const double t = 10.0 + i;
      log.odometry(i == 4 ? t + 10800.0 : t, 0.1 * i, 0, 0);
      log.scan(i == 6 ? t + 10800.0 : t);
    }
  }
  RawlogReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(path, &error)) << error;
  std::vector<RawlogScan> scans;
  RawlogScan s;
  while (reader.next(&s) == RawlogReader::Status::kScan) scans.push_back(s);
  EXPECT_EQ(scans.size(), 9u);
  EXPECT_EQ(reader.counts().scan_stamp_outliers, 1u);
  EXPECT_EQ(reader.counts().odometry_stamp_outliers, 1u);
  EXPECT_EQ(reader.counts().scans_out_of_order, 0u);
  ASSERT_FALSE(scans.empty());
  EXPECT_NEAR(scans.back().scan.stamp, 19.0, 1e-6);
  EXPECT_NEAR(scans.back().odometry.x, 0.9, 1e-6);
  for (size_t i = 0; i < scans.size(); ++i) EXPECT_LT(scans[i].scan.stamp, 20.0);
  const auto warnings = reader.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("outliers"), std::string::npos) << warnings[0];

  // The same jump for time_jump_scans stamps in a row: time moved on.
  const auto jumped = (scratchDir() / "jumped.rawlog").string();
  {
    SyntheticLog log(jumped);
    for (int i = 0; i < 8; ++i) {
      const double t = 10.0 + i + (i >= 4 ? 10800.0 : 0.0);
      log.odometry(t, 0.1 * i, 0, 0);
      log.scan(t);
    }
  }
  RawlogReader later;
  ASSERT_TRUE(later.open(jumped, &error)) << error;
  scans.clear();
  while (later.next(&s) == RawlogReader::Status::kScan) scans.push_back(s);
  EXPECT_EQ(later.counts().scan_stamp_outliers, 2u);  // StampPolicy::scans - 1
  ASSERT_EQ(scans.size(), 6u);
  EXPECT_NEAR(scans.back().scan.stamp, 10817.0, 1e-6);
}

// A scan's declared range noise is clamped to the largest laser_range_sigma, as the node's is:
// 1e30 m once hung the beam model.
TEST(RawlogReader, DeclaredRangeNoiseIsClampedAsTheNodes) {
  const auto path = (scratchDir() / "noise.rawlog").string();
  {
    SyntheticLog log(path);
    for (int i = 0; i < 3; ++i) {
      log.odometry(10.0 + i, 0.1 * i, 0, 0);
      log.scan(10.0 + i, {}, true, i == 1 ? 1e30f : 0.01f);
    }
  }
  RawlogReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(path, &error)) << error;
  std::vector<RawlogScan> scans;
  RawlogScan s;
  while (reader.next(&s) == RawlogReader::Status::kScan) scans.push_back(s);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_FLOAT_EQ(scans[0].scan.range_sigma, 0.01f);
  EXPECT_FLOAT_EQ(scans[1].scan.range_sigma, static_cast<float>(maxDeclaredRangeSigma()));
  EXPECT_EQ(maxDeclaredRangeSigma(), 2.0);  // laser_range_sigma's maximum in parameters.def
  EXPECT_EQ(reader.counts().scans_noise_clamped, 1u);
  EXPECT_EQ(clampDeclaredRangeSigma(5.0), clampDeclaredRangeSigma(1e30));
  EXPECT_EQ(clampDeclaredRangeSigma(-1.0), 0.0f);
}

TEST(RawlogReader, SensorPoseAndScanDirection) {
  const auto path = (scratchDir() / "sensor.rawlog").string();
  {
    SyntheticLog log(path);
    log.odometry(10.0, 0, 0, 0);
    log.scan(10.0, mrpt::poses::CPose3D(0.2, -0.1, 0.3, 0.4, 0, 0));
    log.scan(10.0, mrpt::poses::CPose3D(0.2, 0, 0.3, 0, 0, 0), /*right_to_left=*/false);
    // Mounted upside down (roll = pi): the scan sweeps clockwise in the robot frame.
    log.scan(10.0, mrpt::poses::CPose3D(0, 0, 0.3, 0.4, 0, M_PI));
  }
  RawlogReader::Status status;
  const auto scans = readAll(path, &status);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_NEAR(scans[0].scan.sensor_pose.x, 0.2, 1e-9);
  EXPECT_NEAR(scans[0].scan.sensor_pose.y, -0.1, 1e-9);
  EXPECT_NEAR(scans[0].scan.sensor_pose.theta, 0.4, 1e-9);
  EXPECT_NEAR(scans[0].scan.bearings.front(), -M_PI / 2, 1e-6);
  EXPECT_NEAR(scans[0].scan.bearings[2], 0.0, 1e-6);
  EXPECT_NEAR(scans[1].scan.bearings.front(), M_PI / 2, 1e-6);
  EXPECT_NEAR(scans[1].scan.bearings.back(), -M_PI / 2, 1e-6);
  EXPECT_NEAR(angleDiff(scans[2].scan.sensor_pose.theta, 0.4), 0.0, 1e-9);
  EXPECT_NEAR(scans[2].scan.bearings.front(), M_PI / 2, 1e-6);
}

TEST(RawlogReader, BadRangesPassThrough) {
  const auto path = (scratchDir() / "bad.rawlog").string();
  std::string error;
  ASSERT_TRUE(test::makeVariant(dataPath("sim.rawlog"), path, test::Variant::kBadRanges, &error))
      << error;
  RawlogReader::Status status;
  const auto scans = readAll(path, &status);
  ASSERT_EQ(scans.size(), kFixtureScans);
  for (const auto& s : scans) {
    EXPECT_TRUE(std::isnan(s.scan.ranges[10]));
    EXPECT_TRUE(std::isinf(s.scan.ranges[20]));
    EXPECT_LT(s.scan.ranges[30], 0.0f);
  }
}

TEST(RawlogReader, NoOdometryMeansNoScansOut) {
  const auto path = (scratchDir() / "no_odo.rawlog").string();
  std::string error;
  ASSERT_TRUE(
      test::makeVariant(dataPath("sim_obs.rawlog"), path, test::Variant::kNoOdometry, &error))
      << error;
  RawlogReader::Status status;
  RawlogCounts counts;
  EXPECT_TRUE(readAll(path, &status, &counts).empty());
  EXPECT_EQ(counts.scans, kFixtureScans);
  EXPECT_EQ(counts.odometry_samples, 0u);
  EXPECT_EQ(counts.scans_without_odometry, kFixtureScans);
}

// The real Radish logs (observation-only, CObservationOdometry, 180/360 beams, invalid rays) are
// benchmark data outside the package (shared/ beside the clone, or $ES_RADISH_DIR); read them when
// this machine has them.
TEST(RawlogReader, RadishLogsWhenAvailable) {
  const char* env_dir = std::getenv("ES_RADISH_DIR");
  const std::string dir = std::string(env_dir != nullptr ? env_dir : ES_RADISH_DIR) + "/";
  const std::vector<std::pair<std::string, size_t>> logs = {{"intel", 180}, {"freiburg-079", 360}};
  bool any = false;
  for (const auto& [name, beams] : logs) {
    for (const std::string suffix : {".rawlog", ".sf.rawlog"}) {
      const std::string path = dir + name + suffix;
      if (!std::filesystem::exists(path)) continue;
      any = true;
      RawlogReader::Status status;
      RawlogCounts counts;
      const auto scans = readAll(path, &status, &counts);
      EXPECT_EQ(status, RawlogReader::Status::kEnd) << path;
      ASSERT_FALSE(scans.empty()) << path;
      EXPECT_EQ(counts.scans_without_odometry, 0u) << path;
      size_t invalid = 0;
      for (const auto& s : scans) {
        ASSERT_EQ(s.scan.size(), beams) << path;
        for (uint8_t v : s.scan.valid) invalid += v == 0;
      }
      EXPECT_GT(invalid, 0u) << path;
      std::vector<StampedPose> truth;
      std::string error;
      ASSERT_TRUE(readGroundTruth(dir + name + ".GT.txt", &truth, &error)) << error;
      EXPECT_EQ(truth.size(), scans.size()) << path;
    }
  }
  if (!any) GTEST_SKIP() << "no Radish logs in " << dir;
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
