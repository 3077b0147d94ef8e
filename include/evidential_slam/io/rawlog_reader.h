// Streams an MRPT rawlog (.rawlog, gzip or plain) entry by entry and turns every 2-D laser scan
// into a core LaserScan plus the robot's absolute odometry pose at that scan. Both rawlog formats
// are read: Actions/SensoryFrame (odometry as CActionRobotMovement2D increments, accumulated here)
// and observation-only (CObservationOdometry absolute poses, interpolated to each scan's stamp).
// MRPT's types stay inside the .cpp: callers see core types only.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/core/stamp_order.h"

namespace evidential_slam {
namespace io {

// Bounds on what one rawlog entry may make the reader allocate or accept. MRPT allocates what a
// length field asks for before it reads the data, so these are checked on the bytes first; an
// entry beyond them, or with an impossible value, is corrupt (RawlogReader::Status::kError).
struct RawlogLimits {
  uint32_t max_beams = 100000;           // rays of one 2-D scan
  uint32_t max_objects = 1000;           // observations in a sensory frame, actions in a collection
  uint32_t max_string_bytes = 4096;      // a sensor label
  uint32_t max_matrix_elements = 1024;   // a pose or covariance matrix (rows x cols)
  uint32_t max_motion_samples = 10000;    // particles of an odometry action's Thrun motion model
  uint64_t max_object_bytes = 64u << 20;  // one action collection, sensory frame or observation
  double max_coordinate = 1e5;            // m, |x| and |y| of an odometry pose or increment
  double max_sensor_offset = 100.0;       // m, |x|, |y| and |z| of the laser on the robot

  bool isValid(std::string* why) const;
};

struct RawlogReaderConfig {
  // Only scans with this sensor label are read; empty = every CObservation2DRangeScan.
  std::string laser_label;
  // A scan more than this far in time (s) outside the span of the odometry samples gets no
  // odometry and is dropped (counted in scans_without_odometry).
  double max_odometry_gap = 0.5;
  // Scans waiting for a later odometry sample, at most; older ones are dropped beyond this
  // (bounds memory on a log whose odometry stops).
  size_t max_pending_scans = 256;
  RawlogLimits limits;
  // Objects of classes whose fields the reader does not check (other sensors: images, GPS, IMU,
  // beacons; 3-D odometry; non-Gaussian motion PDFs) are left to MRPT's own reading when true,
  // which allocates whatever their length fields ask; when false they stop reading (kError).
  bool allow_unchecked_classes = false;
  // The order of the scans' and the odometry's stamps, each on its own: the session's policy
  // (stampPolicy(SessionConfig) in session/session.h; core/stamp_order.h).
  StampPolicy stamps;
};

// One scan of the log with the odometry at its stamp.
struct RawlogScan {
  LaserScan scan;
  Pose2 odometry;     // absolute odometry pose (odom frame) at scan.stamp
  std::string label;  // sensor label of the observation
};

enum class RawlogFormat { kUnknown, kActionsSensoryFrames, kObservations };
const char* toString(RawlogFormat format);

struct RawlogCounts {
  uint64_t entries = 0;                 // rawlog entries read (MRPT's rawlogEntry counter)
  uint64_t scans = 0;                   // 2-D laser scans seen (matching the label)
  uint64_t scans_emitted = 0;           // scans handed out by next()
  uint64_t scans_without_odometry = 0;  // dropped: no odometry near their stamp
  uint64_t odometry_samples = 0;        // CActionRobotMovement2D / CObservationOdometry used
  // Time going backwards (a logger's clock jump, a reordered entry): such a scan or odometry
  // sample, older than the one before it, is skipped so the path never goes back in time.
  uint64_t scans_out_of_order = 0;
  uint64_t odometry_out_of_order = 0;
  // A stamp that jumped far back or ahead of the ones before it, alone (fewer than
  // StampPolicy::scans in a row): skipped, and the stream goes on.
  uint64_t scan_stamp_outliers = 0;
  uint64_t odometry_stamp_outliers = 0;
  uint64_t other_observations = 0;  // observations of other classes or labels, ignored
  // Scans whose declared range noise exceeded maxDeclaredRangeSigma() (core/parameters.h): clamped.
  uint64_t scans_noise_clamped = 0;
  // Entries holding a class whose layout the reader does not check, read by MRPT alone
  // (allow_unchecked_classes).
  uint64_t unchecked_entries = 0;
};

class RawlogReader {
 public:
  explicit RawlogReader(const RawlogReaderConfig& config = {});
  ~RawlogReader();
  RawlogReader(const RawlogReader&) = delete;
  RawlogReader& operator=(const RawlogReader&) = delete;

  // Opens `path`. False (and `error`, one line) when it is missing or unreadable, or the config's
  // limits are not valid. Whether it is a rawlog at all shows on the first next().
  bool open(const std::string& path, std::string* error);
  // Reads the (uncompressed) rawlog `bytes`; `name` stands for the file in messages.
  bool openBytes(std::string bytes, const std::string& name, std::string* error);

  enum class Status {
    kScan,       // `out` holds the next scan
    kEnd,        // clean end of file
    kTruncated,  // the file ends inside an entry: everything before it was returned (message())
    // The data is not a rawlog, or an entry is corrupt: a length beyond RawlogLimits or an
    // impossible class, version or value (a NaN aperture, an odometry pose 10^6 km away). The
    // scans before it may have been returned; message() names the entry.
    kError,
  };
  // Reads on until the next scan whose odometry is known, or the end.
  Status next(RawlogScan* out);

  const RawlogCounts& counts() const;
  RawlogFormat format() const;
  // Why reading stopped early (kTruncated / kError), one line without bytes of the file;
  // empty otherwise.
  const std::string& message() const;
  // Things the caller should pass on to the user (skipped scans, mixed odometry sources, time
  // going backwards).
  std::vector<std::string> warnings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Result of a pre-pass over a whole rawlog (deserialises every entry, keeps none).
struct RawlogSurvey {
  RawlogReader::Status status = RawlogReader::Status::kEnd;  // kEnd, kTruncated or kError
  std::string message;
  RawlogFormat format = RawlogFormat::kUnknown;
  RawlogCounts counts;
  double first_stamp = 0.0;
  double last_stamp = 0.0;
};

// Counts the scans and odometry samples of `path` for a progress bar and for early, clear errors
// (no laser, no odometry) before any work. Costs one decompress + deserialise pass, ~0.2 s for the
// 1732 scans of simul.rawlog (2.2 MB), against ~30 s of SLAM with 100 particles: cheap enough, and
// exact where a byte-position estimate would not be (gzip hides the uncompressed size). False (and
// `error`) when the file cannot be opened.
bool surveyRawlog(const std::string& path, const RawlogReaderConfig& config, RawlogSurvey* survey,
                  std::string* error);

}  // namespace io
}  // namespace evidential_slam
