// MRPT rawlog -> core LaserScan + odometry. See rawlog_reader.h for the contract.
#include "evidential_slam/io/rawlog_reader.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>
#include <system_error>

#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

namespace evidential_slam {
namespace io {
namespace {

// Forwards reads to the gz stream and watches the byte level, because MRPT's rawlog reader returns
// false both at a clean end of file and inside a cut-off entry (its archive turns any failure
// inside an object into CExceptionEOF). Every MRPT object ends with a one-byte end flag (0x88) and
// starts with a one-byte header read, so a read that finds no data right after an end flag (or at
// the very start) is a clean end; anywhere else the file ends inside an object.
class CountingStream : public mrpt::io::CStream {
 public:
  explicit CountingStream(mrpt::io::CFileGZInputStream& in) : in_(in) {}
  size_t Read(void* buffer, size_t count) override {
    size_t n = in_.Read(buffer, count);
    const bool failed = n > count;  // a zlib error (-1) seen through size_t
    if (failed) n = 0;
    if (n < count && !hit_end_) {
      hit_end_ = true;
      end_at_boundary_ = !failed && n == 0 && count == 1 && (consumed_ == 0 || last_was_end_flag_);
    }
    last_was_end_flag_ = n == 1 && count == 1 && static_cast<uint8_t*>(buffer)[0] == kEndFlag;
    consumed_ += n;
    return n;
  }
  size_t Write(const void*, size_t) override { return 0; }
  uint64_t Seek(int64_t, TSeekOrigin) override { return consumed_; }
  uint64_t getTotalBytesCount() const override { return in_.getTotalBytesCount(); }
  uint64_t getPosition() const override { return consumed_; }
  uint64_t consumed() const { return consumed_; }
  // True once a read came back short; endedAtBoundary() says whether that was between objects.
  bool hitEnd() const { return hit_end_; }
  bool endedAtBoundary() const { return end_at_boundary_; }

 private:
  static constexpr uint8_t kEndFlag = 0x88;  // MRPT's SERIALIZATION_END_FLAG
  mrpt::io::CFileGZInputStream& in_;
  uint64_t consumed_ = 0;
  bool last_was_end_flag_ = false;
  bool hit_end_ = false;
  bool end_at_boundary_ = false;
};

// CRawlog's stream readers print caught exceptions to std::cerr; this keeps that text for our own
// one-line messages instead of letting it reach the terminal.
class CerrCapture {
 public:
  CerrCapture() : old_(std::cerr.rdbuf(buffer_.rdbuf())) {}
  ~CerrCapture() { std::cerr.rdbuf(old_); }
  // The captured text squeezed onto one line.
  std::string text() const {
    std::string s = buffer_.str();
    std::string out;
    bool space = false;
    for (char c : s) {
      if (c == '\n' || c == '\r' || c == '\t' || c == ' ') {
        space = !out.empty();
        continue;
      }
      if (space) out += ' ';
      space = false;
      out += c;
    }
    return out;
  }

 private:
  std::ostringstream buffer_;
  std::streambuf* old_;
};

double toSeconds(const mrpt::system::TTimeStamp& t) {
  return t == INVALID_TIMESTAMP ? 0.0 : mrpt::Clock::toDouble(t);
}

Pose2 toPose2(const mrpt::poses::CPose2D& p) { return Pose2(p.x(), p.y(), p.phi()); }

struct OdometrySample {
  double stamp;
  mrpt::poses::CPose2D pose;
};

enum class OdometrySource { kNone, kActions, kObservations };

}  // namespace

const char* toString(RawlogFormat format) {
  switch (format) {
    case RawlogFormat::kActionsSensoryFrames:
      return "actions/sensory-frames";
    case RawlogFormat::kObservations:
      return "observations";
    case RawlogFormat::kUnknown:
      break;
  }
  return "unknown";
}

struct RawlogReader::Impl {
  explicit Impl(const RawlogReaderConfig& c) : config(c) {}

  RawlogReaderConfig config;
  std::string path;
  mrpt::io::CFileGZInputStream file;
  std::unique_ptr<CountingStream> counting;
  std::unique_ptr<mrpt::serialization::CArchive> archive;
  size_t rawlog_entry = 0;

  RawlogCounts counts;
  RawlogFormat format = RawlogFormat::kUnknown;
  std::string message;
  bool stream_done = false;  // no more entries will be read
  Status final_status = Status::kEnd;

  OdometrySource source = OdometrySource::kNone;
  bool warned_mixed_sources = false;
  mrpt::poses::CPose2D accumulated;  // integral of the action increments
  std::deque<OdometrySample> samples;
  std::deque<RawlogScan> pending;
  double last_scan_stamp = -std::numeric_limits<double>::infinity();

  void addSample(double stamp, const mrpt::poses::CPose2D& pose, OdometrySource from) {
    if (source == OdometrySource::kNone) source = from;
    if (source != from) {
      // Increments and absolute readings live in different odom frames: keep the first kind.
      warned_mixed_sources = true;
      return;
    }
    if (!samples.empty() && stamp < samples.back().stamp) {
      ++counts.odometry_out_of_order;  // interpolation needs samples in time order
      return;
    }
    ++counts.odometry_samples;
    samples.push_back({stamp, pose});
    while (samples.size() > 16) samples.pop_front();
  }

  void addScan(const mrpt::obs::CObservation2DRangeScan& obs) {
    if (!config.laser_label.empty() && obs.sensorLabel != config.laser_label) {
      ++counts.other_observations;
      return;
    }
    ++counts.scans;
    RawlogScan out;
    out.label = obs.sensorLabel;
    LaserScan& s = out.scan;
    s.stamp = toSeconds(obs.timestamp);
    if (s.stamp < last_scan_stamp) {
      ++counts.scans_out_of_order;
      return;
    }
    last_scan_stamp = s.stamp;
    // The scan plane in the robot frame: the sensor's x axis gives the yaw; a sensor mounted upside
    // down (its z axis pointing down) sweeps the other way round.
    const auto R = obs.sensorPose.getRotationMatrix();
    const double yaw = std::atan2(R(1, 0), R(0, 0));
    const bool flipped = R(2, 2) < 0.0;
    s.sensor_pose = Pose2(obs.sensorPose.x(), obs.sensorPose.y(), yaw);
    s.max_range = obs.maxRange;
    s.range_sigma = obs.stdError;  // the sensor's declared range noise feeds the beam models
    const size_t n = obs.getScanSize();
    s.ranges.resize(n);
    s.bearings.resize(n);
    s.valid.resize(n);
    for (size_t i = 0; i < n; ++i) {
      s.ranges[i] = obs.getScanRange(i);
      const float a = obs.getScanAngle(i);
      s.bearings[i] = flipped ? -a : a;
      s.valid[i] = obs.getScanRangeValidity(i) ? 1 : 0;
    }
    pending.push_back(std::move(out));
    while (pending.size() > config.max_pending_scans) {
      pending.pop_front();
      ++counts.scans_without_odometry;
    }
  }

  void handleObservation(const mrpt::obs::CObservation& obs) {
    if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs)) {
      addScan(*scan);
    } else if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&obs)) {
      addSample(toSeconds(odo->timestamp), odo->odometry, OdometrySource::kObservations);
    } else {
      ++counts.other_observations;
    }
  }

  void handleActionAndFrame(const mrpt::obs::CActionCollection& actions,
                            const mrpt::obs::CSensoryFrame& frame) {
    // The increment is the motion since the previous frame; it is stamped with the frame's first
    // valid observation stamp (the action's own stamp is invalid in e.g. simul.rawlog).
    const auto move = actions.getBestMovementEstimation();
    if (move) {
      mrpt::poses::CPose2D increment;
      if (move->estimationMethod == mrpt::obs::CActionRobotMovement2D::emOdometry) {
        increment = move->rawOdometryIncrementReading;
      } else if (move->poseChange) {
        increment = move->poseChange->getMeanVal();
      }
      accumulated = accumulated + increment;
      double stamp = toSeconds(move->timestamp);
      for (const auto& obs : frame) {
        if (obs && obs->timestamp != INVALID_TIMESTAMP) {
          stamp = toSeconds(obs->timestamp);
          break;
        }
      }
      addSample(stamp, accumulated, OdometrySource::kActions);
    }
    for (const auto& obs : frame) {
      if (obs) handleObservation(*obs);
    }
  }

  // Odometry at `stamp` from the retained samples: exact, interpolated between the samples around
  // it, or held from the nearest one within max_odometry_gap. `wait` is set when a later sample may
  // still arrive and settle it.
  bool odometryAt(double stamp, mrpt::poses::CPose2D* pose, bool* wait) const {
    *wait = false;
    if (samples.empty()) {
      *wait = !stream_done;
      return false;
    }
    // First sample strictly after the stamp; the one before it is at or before the stamp.
    const auto after =
        std::upper_bound(samples.begin(), samples.end(), stamp,
                         [](double t, const OdometrySample& s) { return t < s.stamp; });
    if (after == samples.begin()) {  // older than every sample
      if (after->stamp - stamp > config.max_odometry_gap) return false;
      *pose = after->pose;
      return true;
    }
    const auto before = std::prev(after);
    if (before->stamp == stamp) {
      *pose = before->pose;
      return true;
    }
    if (after == samples.end()) {  // newer than every sample
      if (!stream_done) {
        *wait = true;
        return false;
      }
      if (stamp - before->stamp > config.max_odometry_gap) return false;
      *pose = before->pose;
      return true;
    }
    // Interpolate along the increment between the two samples.
    const double a = (stamp - before->stamp) / (after->stamp - before->stamp);
    const mrpt::poses::CPose2D delta = after->pose - before->pose;
    *pose = before->pose + mrpt::poses::CPose2D(a * delta.x(), a * delta.y(), a * delta.phi());
    return true;
  }

  // Moves the oldest pending scan to `out` once its odometry is known.
  bool popResolved(RawlogScan* out) {
    while (!pending.empty()) {
      mrpt::poses::CPose2D pose;
      bool wait = false;
      if (odometryAt(pending.front().scan.stamp, &pose, &wait)) {
        *out = std::move(pending.front());
        pending.pop_front();
        out->odometry = toPose2(pose);
        ++counts.scans_emitted;
        return true;
      }
      if (wait) return false;
      pending.pop_front();
      ++counts.scans_without_odometry;
    }
    return false;
  }

  // Reads one rawlog entry (an action + sensory frame pair or an observation). False at the end.
  bool readEntry() {
    mrpt::obs::CActionCollection::Ptr actions;
    mrpt::obs::CSensoryFrame::Ptr frame;
    mrpt::obs::CObservation::Ptr observation;
    const uint64_t before = counting->consumed();
    const size_t entries_before = rawlog_entry;
    bool ok = false;
    std::string mrpt_error;
    {
      CerrCapture capture;
      try {
        ok = mrpt::obs::CRawlog::getActionObservationPairOrObservation(*archive, actions, frame,
                                                                       observation, rawlog_entry);
      } catch (const std::exception& e) {
        ok = false;
        std::cerr << e.what();
      }
      mrpt_error = capture.text();
    }
    if (ok) {
      counts.entries = rawlog_entry;
      if (observation) {
        if (format == RawlogFormat::kUnknown) format = RawlogFormat::kObservations;
        handleObservation(*observation);
      } else if (actions && frame) {
        if (format == RawlogFormat::kUnknown) format = RawlogFormat::kActionsSensoryFrames;
        handleActionAndFrame(*actions, *frame);
      }
      return true;
    }
    stream_done = true;
    counts.entries = rawlog_entry;
    // A non-empty file that yields no data at all (e.g. a broken gzip stream) is not "empty".
    const bool no_data_from_nonempty_file =
        counting->consumed() == 0 && file.getTotalBytesCount() > 0;
    if (counting->hitEnd() && counting->endedAtBoundary() && mrpt_error.empty() &&
        !no_data_from_nonempty_file) {
      // Clean end. A trailing action collection without its sensory frame (simul-gridmap writes
      // one) carries no scan and is dropped.
      final_status = Status::kEnd;
      return false;
    }
    // MRPT's exception text comes with a banner, a location and a call stack: keep the message.
    std::string detail = mrpt_error;
    const size_t msg = detail.find("Message:");
    if (msg != std::string::npos) detail = detail.substr(msg + 8);
    for (const char* cut : {" Location:", " Call stack", " Original exception:"}) {
      const size_t at = detail.find(cut);
      if (at != std::string::npos) detail.resize(at);
    }
    const size_t start = detail.find_first_not_of(' ');
    detail = start == std::string::npos ? std::string() : detail.substr(start);
    if (detail.size() > 120) detail = detail.substr(0, 117) + "...";
    if (entries_before == 0) {
      final_status = Status::kError;
      message = "'" + path + "' is not an MRPT rawlog (or is cut before its first entry)" +
                (detail.empty() ? std::string() : ": " + detail);
    } else {
      final_status = Status::kTruncated;
      message = "'" + path + "' ends inside rawlog entry " + std::to_string(entries_before + 1) +
                " (truncated or corrupt after " + std::to_string(before) +
                " bytes of data); the entries before it were used";
      if (!detail.empty()) message += ": " + detail;
    }
    return false;
  }
};

RawlogReader::RawlogReader(const RawlogReaderConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

RawlogReader::~RawlogReader() = default;

bool RawlogReader::open(const std::string& path, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return fail("rawlog '" + path + "' does not exist");
  if (std::filesystem::is_directory(path, ec)) return fail("rawlog '" + path + "' is a directory");
  Impl& d = *impl_;
  d.path = path;
  std::string open_error;
  bool opened = false;
  {
    CerrCapture capture;
    try {
      opened = d.file.open(path, open_error);
    } catch (const std::exception& e) {
      open_error = e.what();
    }
  }
  if (!opened) {
    return fail("cannot open rawlog '" + path + "'" +
                (open_error.empty() ? "" : ": " + open_error));
  }
  d.counting = std::make_unique<CountingStream>(d.file);
  d.archive = mrpt::serialization::archiveUniquePtrFrom(*d.counting);
  return true;
}

RawlogReader::Status RawlogReader::next(RawlogScan* out) {
  Impl& d = *impl_;
  if (!d.archive) {
    d.message = "rawlog not open";
    return Status::kError;
  }
  for (;;) {
    if (d.popResolved(out)) return Status::kScan;
    if (d.stream_done) {
      // Any scan still pending had no odometry near it; popResolved dropped it.
      return d.final_status;
    }
    d.readEntry();
  }
}

const RawlogCounts& RawlogReader::counts() const { return impl_->counts; }
RawlogFormat RawlogReader::format() const { return impl_->format; }
const std::string& RawlogReader::message() const { return impl_->message; }

std::vector<std::string> RawlogReader::warnings() const {
  std::vector<std::string> w;
  if (impl_->warned_mixed_sources) {
    w.push_back("the log has both odometry increments and absolute odometry observations; used " +
                std::string(impl_->source == OdometrySource::kActions ? "the increments"
                                                                      : "the observations"));
  }
  if (impl_->counts.scans_out_of_order > 0 || impl_->counts.odometry_out_of_order > 0) {
    w.push_back("time went backwards in the log: skipped " +
                std::to_string(impl_->counts.scans_out_of_order) + " scans and " +
                std::to_string(impl_->counts.odometry_out_of_order) +
                " odometry samples older than the one before them");
  }
  if (impl_->counts.scans_without_odometry > 0) {
    w.push_back(std::to_string(impl_->counts.scans_without_odometry) +
                " scans had no odometry within " + std::to_string(impl_->config.max_odometry_gap) +
                " s and were skipped");
  }
  return w;
}

bool surveyRawlog(const std::string& path, const RawlogReaderConfig& config, RawlogSurvey* survey,
                  std::string* error) {
  RawlogReader reader(config);
  if (!reader.open(path, error)) return false;
  *survey = RawlogSurvey();
  RawlogScan scan;
  bool first = true;
  RawlogReader::Status status;
  while ((status = reader.next(&scan)) == RawlogReader::Status::kScan) {
    if (first) survey->first_stamp = scan.scan.stamp;
    first = false;
    survey->last_stamp = scan.scan.stamp;
  }
  survey->status = status;
  survey->message = reader.message();
  survey->format = reader.format();
  survey->counts = reader.counts();
  return true;
}

}  // namespace io
}  // namespace evidential_slam
