// MRPT rawlog -> core LaserScan + odometry. See rawlog_reader.h for the contract.
//
// Objects are read one at a time: each is first pre-checked on its bytes (rawlog_precheck.h), then
// deserialised by MRPT from the same look-ahead buffer, with MRPT's reads capped at the object's
// checked length. The values MRPT hands back are checked before they are used.
#include "evidential_slam/io/rawlog_reader.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <system_error>

#include <mrpt/core/Clock.h>
#include <mrpt/core/exceptions.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/stamp_order.h"
#include "evidential_slam/io/error_text.h"
#include "rawlog_precheck.h"

namespace evidential_slam {
namespace io {
namespace {

// MRPT prints some exceptions to std::cerr before it returns (CFileGZInputStream::open); this
// keeps that text off the terminal.
class CerrCapture {
 public:
  CerrCapture() : old_(std::cerr.rdbuf(buffer_.rdbuf())) {}
  ~CerrCapture() { std::cerr.rdbuf(old_); }

 private:
  std::ostringstream buffer_;
  std::streambuf* old_;
};

// A number for a message ("nan", "inf", "1e+30").
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// The widest aperture a scan may claim: a full turn, with room for float rounding.
constexpr double kMaxAperture = 2.0 * M_PI + 1e-4;

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
  std::unique_ptr<mrpt::io::CStream> source;  // the gzip (or plain) file, or bytes in memory
  std::unique_ptr<detail::LookaheadStream> lookahead;
  std::unique_ptr<mrpt::serialization::CArchive> archive;

  RawlogCounts counts;
  RawlogFormat format = RawlogFormat::kUnknown;
  std::string message;
  bool stream_done = false;  // no more entries will be read
  Status final_status = Status::kEnd;

  OdometrySource source_kind = OdometrySource::kNone;
  bool warned_mixed_sources = false;
  mrpt::poses::CPose2D accumulated;  // integral of the action increments
  // An action collection was read and waits for its sensory frame; its increment and stamp.
  // As MRPT's CRawlog::getActionObservationPairOrObservation pairs them, what comes between the
  // two is skipped, and so is a sensory frame without an action before it.
  bool action_pending = false;
  std::optional<mrpt::poses::CPose2D> pending_increment;
  double pending_increment_stamp = 0.0;
  std::deque<OdometrySample> samples;
  std::deque<RawlogScan> pending;
  // The stamp policy of the session (core/stamp_order.h), for the scans and the odometry.
  StampOrder scan_order{config.stamps};
  StampOrder odometry_order{config.stamps};

  // Stops reading: the data from entry `entry` (1-based) on cannot be used.
  void fail(Status status, const std::string& why) {
    stream_done = true;
    final_status = status;
    message = why;
    if (status == Status::kError) pending.clear();
  }
  void corrupt(uint64_t entry, uint64_t at_byte, const std::string& why) {
    fail(Status::kError, "'" + path + "' is corrupt at rawlog entry " + std::to_string(entry) +
                             " (after " + std::to_string(at_byte) + " bytes of data): " + why);
  }
  // Data that cannot be read as an MRPT object: at the first entry, not a rawlog at all.
  void unreadable(uint64_t entry, uint64_t at_byte, const std::string& why) {
    if (entry == 1) {
      fail(Status::kError, "'" + path + "' is not an MRPT rawlog: " + why);
    } else {
      corrupt(entry, at_byte, why);
    }
  }
  void truncated(uint64_t entry, uint64_t at_byte) {
    if (entry <= 1) {
      fail(Status::kError,
           "'" + path + "' is not an MRPT rawlog (or is cut before its first entry)");
    } else {
      fail(Status::kTruncated, "'" + path + "' ends inside rawlog entry " + std::to_string(entry) +
                                   " (truncated or corrupt after " + std::to_string(at_byte) +
                                   " bytes of data); the entries before it were used");
    }
  }

  // Empty when the pose is a believable odometry reading; else what is wrong with it.
  std::string badOdometry(const mrpt::poses::CPose2D& p, const char* what) const {
    const double limit = config.limits.max_coordinate;
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.phi()) ||
        std::abs(p.x()) > limit || std::abs(p.y()) > limit) {
      return std::string("an ") + what + " of (" + number(p.x()) + ", " + number(p.y()) + ", " +
             number(p.phi()) + ") (coordinates must be finite and within " + number(limit) + " m)";
    }
    return {};
  }

  // Empty when MRPT's scan describes a possible sensor; else what is wrong with it.
  std::string badScan(const mrpt::obs::CObservation2DRangeScan& obs) const {
    const double aperture = obs.aperture;
    if (!std::isfinite(aperture) || aperture < 0.0 || aperture > kMaxAperture ||
        (aperture == 0.0 && obs.getScanSize() >= 2)) {
      return "a scan aperture of " + number(aperture) + " rad (wants (0, 2 pi])";
    }
    if (!std::isfinite(obs.maxRange) || obs.maxRange < 0.0f) {
      return "a scan maximum range of " + number(obs.maxRange) + " m";
    }
    if (!std::isfinite(obs.stdError) || obs.stdError < 0.0f) {
      return "a scan range noise of " + number(obs.stdError) + " m";
    }
    const auto& p = obs.sensorPose;
    const double limit = config.limits.max_sensor_offset;
    const auto R = p.getRotationMatrix();
    bool finite_rotation = true;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) finite_rotation = finite_rotation && std::isfinite(R(r, c));
    }
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()) ||
        std::abs(p.x()) > limit || std::abs(p.y()) > limit || std::abs(p.z()) > limit ||
        !finite_rotation) {
      return "a laser pose on the robot at (" + number(p.x()) + ", " + number(p.y()) + ", " +
             number(p.z()) + ") (must be finite and within " + number(limit) + " m)";
    }
    return {};
  }

  void addSample(double stamp, const mrpt::poses::CPose2D& pose, OdometrySource from) {
    if (source_kind == OdometrySource::kNone) source_kind = from;
    if (source_kind != from) {
      // Increments and absolute readings live in different odom frames: keep the first kind.
      warned_mixed_sources = true;
      return;
    }
    // Interpolation needs samples in time order: a sample a little older than the one before is
    // skipped; one stamped far off is an outlier, skipped once; a real jump back starts the
    // samples over.
    switch (odometry_order.next(stamp)) {
      case StampOrder::Verdict::kDropped:
        ++counts.odometry_out_of_order;
        return;
      case StampOrder::Verdict::kOutlier:
        ++counts.odometry_stamp_outliers;
        return;
      case StampOrder::Verdict::kJumpedBack:
        samples.clear();
        break;
      default:
        break;
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
    switch (scan_order.next(s.stamp)) {
      case StampOrder::Verdict::kDropped:
        ++counts.scans_out_of_order;
        return;
      case StampOrder::Verdict::kOutlier:
        ++counts.scan_stamp_outliers;
        return;
      default:
        break;
    }
    // The scan plane in the robot frame: the sensor's x axis gives the yaw; a sensor mounted upside
    // down (its z axis pointing down) sweeps the other way round.
    const auto R = obs.sensorPose.getRotationMatrix();
    const double yaw = std::atan2(R(1, 0), R(0, 0));
    const bool flipped = R(2, 2) < 0.0;
    s.sensor_pose = Pose2(obs.sensorPose.x(), obs.sensorPose.y(), yaw);
    s.max_range = obs.maxRange;
    // The sensor's declared range noise feeds the beam models, bounded as the node's is.
    s.range_sigma = clampDeclaredRangeSigma(obs.stdError);
    if (s.range_sigma < obs.stdError) ++counts.scans_noise_clamped;
    const size_t n = obs.getScanSize();
    s.ranges.resize(n);
    s.bearings.resize(n);
    s.valid.resize(n);
    for (size_t i = 0; i < n; ++i) {
      s.ranges[i] = obs.getScanRange(i);
      // MRPT spreads the aperture over n - 1 steps: a single beam would come out NaN.
      const float a = n == 1 ? 0.0f : obs.getScanAngle(i);
      s.bearings[i] = flipped ? -a : a;
      s.valid[i] = obs.getScanRangeValidity(i) ? 1 : 0;
    }
    pending.push_back(std::move(out));
    while (pending.size() > config.max_pending_scans) {
      pending.pop_front();
      ++counts.scans_without_odometry;
    }
  }

  // False (reading stopped with kError) when the observation holds an impossible value.
  bool handleObservation(const mrpt::obs::CObservation& obs, uint64_t entry) {
    if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs)) {
      const std::string bad = badScan(*scan);
      if (!bad.empty()) {
        corrupt(entry, lookahead->consumed(), bad);
        return false;
      }
      addScan(*scan);
    } else if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&obs)) {
      const std::string bad = badOdometry(odo->odometry, "odometry pose");
      if (!bad.empty()) {
        corrupt(entry, lookahead->consumed(), bad);
        return false;
      }
      addSample(toSeconds(odo->timestamp), odo->odometry, OdometrySource::kObservations);
    } else {
      ++counts.other_observations;
    }
    return true;
  }

  // An action collection: its movement waits for the sensory frame that follows (whose stamp it
  // takes: the action's own is invalid in e.g. simul.rawlog).
  bool handleActions(const mrpt::obs::CActionCollection& actions, uint64_t entry) {
    action_pending = true;
    pending_increment.reset();
    auto incrementOf = [](const mrpt::obs::CActionRobotMovement2D& move) {
      if (move.estimationMethod == mrpt::obs::CActionRobotMovement2D::emOdometry) {
        return move.rawOdometryIncrementReading;
      }
      return move.poseChange ? move.poseChange->getMeanVal() : mrpt::poses::CPose2D();
    };
    // Every movement, not only the best one: MRPT's choice passes over a NaN covariance.
    for (const auto& action : actions) {
      const auto* move = dynamic_cast<const mrpt::obs::CActionRobotMovement2D*>(action.get());
      const std::string bad = move ? badOdometry(incrementOf(*move), "odometry increment") : "";
      if (!bad.empty()) {
        corrupt(entry, lookahead->consumed(), bad);
        return false;
      }
    }
    const auto move = actions.getBestMovementEstimation();
    if (!move) return true;
    pending_increment = incrementOf(*move);
    pending_increment_stamp = toSeconds(move->timestamp);
    return true;
  }

  bool handleFrame(const mrpt::obs::CSensoryFrame& frame, uint64_t entry) {
    action_pending = false;
    if (pending_increment) {
      const mrpt::poses::CPose2D next = accumulated + *pending_increment;
      pending_increment.reset();
      const std::string bad = badOdometry(next, "odometry pose");
      if (!bad.empty()) {
        corrupt(entry, lookahead->consumed(), bad);
        return false;
      }
      accumulated = next;
      double stamp = pending_increment_stamp;
      for (const auto& obs : frame) {
        if (obs && obs->timestamp != INVALID_TIMESTAMP) {
          stamp = toSeconds(obs->timestamp);
          break;
        }
      }
      addSample(stamp, accumulated, OdometrySource::kActions);
    }
    for (const auto& obs : frame) {
      if (obs && !handleObservation(*obs, entry)) return false;
    }
    return true;
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

  // Reads one top-level object (an action collection, a sensory frame or an observation). False
  // once reading has stopped (final_status and message say why).
  bool readObject() {
    detail::LookaheadStream& in = *lookahead;
    const uint64_t entry = counts.entries + 1;
    const uint64_t start = in.consumed();
    if (!in.fill(1)) {
      // A non-empty file that yields no data at all (a broken gzip stream) is not "empty".
      const bool no_data_from_nonempty_file = start == 0 && in.getTotalBytesCount() > 0;
      if (in.sourceFailed() || no_data_from_nonempty_file) {
        // Broken gzip data, or a gzip file cut short, at an entry boundary.
        truncated(entry, start);
      } else {
        // Clean end. A trailing action collection without its sensory frame (simul-gridmap
        // writes one) carries no scan and is dropped.
        stream_done = true;
        final_status = Status::kEnd;
      }
      return false;
    }
    const detail::PrecheckResult check = detail::precheckRawlogObject(in, config.limits);
    if (check.verdict == detail::Precheck::kTruncated) {
      truncated(entry, start);
      return false;
    }
    if (check.verdict == detail::Precheck::kCorrupt) {
      unreadable(entry, start, check.why);
      return false;
    }
    const bool checked = check.verdict == detail::Precheck::kOk;
    if (!checked && !config.allow_unchecked_classes) {
      fail(Status::kError,
           "'" + path + "' holds a " + check.why + " at rawlog entry " + std::to_string(entry) +
               ", a class whose length fields the reader does not check before MRPT allocates "
               "for them (keep only the laser and odometry with rawlog-edit --keep-label, or "
               "allow unchecked classes)");
      return false;
    }
    if (!checked) ++counts.unchecked_entries;
    const std::string what = checked ? "an entry" : "a " + check.why;  // the class not checked

    mrpt::serialization::CSerializable::Ptr object;
    in.capReads(checked ? check.bytes : config.limits.max_object_bytes);
    try {
      object = archive->ReadObject();
    } catch (const std::bad_alloc&) {
      in.capReads(UINT64_MAX);
      corrupt(entry, start, what + " that asks for more memory than there is");
      return false;
    } catch (const std::exception& e) {
      in.capReads(UINT64_MAX);
      if (in.capHit()) {
        corrupt(entry, start,
                checked ? "an entry MRPT reads past its checked length"
                        : what + " longer than " + std::to_string(config.limits.max_object_bytes) +
                              " bytes");
      } else if (in.fill(1)) {
        unreadable(entry, start, oneLineMessage(e.what()));
      } else {
        truncated(entry, start);
      }
      return false;
    }
    in.capReads(UINT64_MAX);
    if (checked && in.consumed() - start != check.bytes) {
      corrupt(entry, start,
              "an entry MRPT reads as " + std::to_string(in.consumed() - start) +
                  " bytes where its check found " + std::to_string(check.bytes));
      return false;
    }
    counts.entries = entry;
    if (action_pending) {
      const auto* frame = dynamic_cast<const mrpt::obs::CSensoryFrame*>(object.get());
      return frame ? handleFrame(*frame, entry) : true;
    }
    if (const auto* actions = dynamic_cast<const mrpt::obs::CActionCollection*>(object.get())) {
      if (format == RawlogFormat::kUnknown) format = RawlogFormat::kActionsSensoryFrames;
      return handleActions(*actions, entry);
    }
    if (const auto* obs = dynamic_cast<const mrpt::obs::CObservation*>(object.get())) {
      if (format == RawlogFormat::kUnknown) format = RawlogFormat::kObservations;
      return handleObservation(*obs, entry);
    }
    return true;  // a sensory frame without an action before it
  }

  bool start(std::unique_ptr<mrpt::io::CStream> stream, std::string* error) {
    std::string why;
    if (!config.limits.isValid(&why)) {
      if (error) *error = "invalid rawlog reader limits: " + why;
      return false;
    }
    source = std::move(stream);
    lookahead = std::make_unique<detail::LookaheadStream>(*source);
    archive = mrpt::serialization::archiveUniquePtrFrom(*lookahead);
    return true;
  }
};

bool RawlogLimits::isValid(std::string* why) const {
  auto bad = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (max_beams < 1) return bad("max_beams must be >= 1");
  if (max_objects < 1) return bad("max_objects must be >= 1");
  if (max_matrix_elements < 16) return bad("max_matrix_elements must be >= 16 (a 4x4 pose)");
  if (max_object_bytes < 1024) return bad("max_object_bytes must be >= 1024");
  if (!(max_coordinate > 0.0)) return bad("max_coordinate must be > 0");
  if (!(max_sensor_offset > 0.0)) return bad("max_sensor_offset must be > 0");
  return true;
}

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
  if (!std::filesystem::is_regular_file(path, ec)) {
    return fail("rawlog '" + path + "' is not a regular file (a device or a pipe)");
  }
  Impl& d = *impl_;
  d.path = path;
  auto file = std::make_unique<mrpt::io::CFileGZInputStream>();
  std::string open_error;
  bool opened = false;
  {
    CerrCapture capture;
    try {
      opened = file->open(path, open_error);
    } catch (const std::exception& e) {
      open_error = e.what();
    }
  }
  if (!opened) {
    const std::string detail = oneLineMessage(open_error);
    return fail("cannot open rawlog '" + path + "'" +
                (detail == "(no message)" ? "" : ": " + detail));
  }
  return d.start(std::move(file), error);
}

bool RawlogReader::openBytes(std::string bytes, const std::string& name, std::string* error) {
  impl_->path = name;
  return impl_->start(std::make_unique<detail::BytesStream>(std::move(bytes)), error);
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
    d.readObject();
  }
}

const RawlogCounts& RawlogReader::counts() const { return impl_->counts; }
RawlogFormat RawlogReader::format() const { return impl_->format; }
const std::string& RawlogReader::message() const { return impl_->message; }

std::vector<std::string> RawlogReader::warnings() const {
  std::vector<std::string> w;
  if (impl_->warned_mixed_sources) {
    w.push_back("the log has both odometry increments and absolute odometry observations; used " +
                std::string(impl_->source_kind == OdometrySource::kActions ? "the increments"
                                                                           : "the observations"));
  }
  if (impl_->counts.scans_out_of_order > 0 || impl_->counts.odometry_out_of_order > 0) {
    w.push_back("time went backwards in the log: skipped " +
                std::to_string(impl_->counts.scans_out_of_order) + " scans and " +
                std::to_string(impl_->counts.odometry_out_of_order) +
                " odometry samples older than the one before them");
  }
  if (impl_->counts.scan_stamp_outliers > 0 || impl_->counts.odometry_stamp_outliers > 0) {
    w.push_back("skipped " + std::to_string(impl_->counts.scan_stamp_outliers) + " scans and " +
                std::to_string(impl_->counts.odometry_stamp_outliers) +
                " odometry samples stamped far from the ones around them (outliers)");
  }
  if (impl_->counts.scans_noise_clamped > 0) {
    w.push_back(std::to_string(impl_->counts.scans_noise_clamped) +
                " scans declared a range noise (stdError) above " +
                number(maxDeclaredRangeSigma()) + " m, the largest laser_range_sigma: used that");
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
