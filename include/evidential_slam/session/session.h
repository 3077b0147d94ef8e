// What both front ends do around the SLAM engine (or, in localization mode, the Localizer on a
// fixed map), once: the checks on each scan (stamp, size,
// where the robot is), the order of the scans and the time-jump policy, the conflict alarm and its
// per-scan record. The offline runner feeds it a rawlog, the ROS node's worker thread feeds it
// LaserScans; both write its map files with writeMapFiles.
//
// Time stamps: a scan older than the previous one by at most time_jump_tolerance is dropped. A
// scan further back, or further ahead than time_jump_forward, is a jump: one jump alone is an
// outlier (a driver's glitch, a stamp of 0), dropped and reported. Only time_jump_scans jumps in
// a row are believed: back, the SLAM starts over (a looping bag); ahead, time goes on from there.
// A front end that sees its clock go back (ROS time of a looping bag) calls restart() at once.
// Before any restart the map is saved (writeMapFiles) into <reset_save_root>/before_reset_<stamp>/
// when save_before_reset is set and the front end gave a root.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evidential_slam/core/conflict_alarm.h"
#include "evidential_slam/core/localization/localizer.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/slam_engine.h"
#include "evidential_slam/core/stamp_order.h"

namespace evidential_slam {

// One processed scan: what it added to the best map and the alarm's verdict (conflict.csv).
struct ConflictRecord {
  double stamp = 0.0;
  double ec_added_bits = 0.0;
  double conflict_mass_added = 0.0;
  double open_space_conflict_added = 0.0;  // ScanUpdate::open_space_conflict_added
  ConflictAlarmState alarm;                // its input: ScanUpdate::contradiction_added
};

// What became of one scan given to the session.
struct SessionScanResult {
  enum class Order {
    kInOrder,    // handed to the engine
    kDropped,    // older than the previous scan, within the tolerance: not used
    kOutlier,    // its stamp jumped (back or ahead) while its neighbours' did not (yet): not used
    kRefused,    // beyond a limit (rays, distance from the start, stamp not finite): not used
    kRestarted,  // time jumped back for time_jump_scans scans: the SLAM started over with this one
  };
  Order order = Order::kInOrder;
  double stamp = 0.0;               // the scan's
  std::string message;              // one line, for every order but kInOrder
  ScanUpdate update;                // the engine's answer (kInOrder and kRestarted; SLAM mode)
  ConflictAlarmState alarm;         // when update.processed
  LocalizationUpdate localization;  // the Localizer's answer (localization mode)

  bool used() const { return order == Order::kInOrder || order == Order::kRestarted; }
  // Whichever engine ran: the scan passed its motion gate and updated the particles ...
  bool processed() const { return update.processed || localization.processed; }
  // ... or the engine refused it (rejectionReason() says why).
  bool rejected() const { return update.rejected || localization.rejected; }
  const std::string& rejectionReason() const {
    return localization.rejected ? localization.why : update.why;
  }
};

// Where localization starts: particles drawn around `pose` with `covariance` (x, y, θ), or, with
// `global`, spread over the map's free space (Localizer::globalLocalization).
struct LocalizationStart {
  bool global = false;
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// The one bound on poses that enter the SLAM (a start map's pose, --initial-pose, ~load_map's
// use_pose, /initialpose, a fresh map's first odometry): finite and within max_map_extent of the
// map frame's origin, so every cell index the SLAM computes stays far inside int and the work done
// over the map's extent stays bounded. False and a one-line `why` starting with `what`.
// The session's time_jump_* as the stamp policy the rawlog reader applies too.
StampPolicy stampPolicy(const SessionConfig& c);

bool poseWithinMapExtent(const Pose2& pose, double max_map_extent, const std::string& what,
                         std::string* why);

class MappingSession {
 public:
  // Throws std::invalid_argument for invalid parameters (check Parameters::isValid first).
  explicit MappingSession(const Parameters& params);

  SessionScanResult processScan(const Pose2& odometry, const LaserScan& scan);

  // New run-time parameters (the start-up ones keep their values). False (and `why`) when
  // invalid; nothing changes then.
  bool reconfigure(const Parameters& params, std::string* why);
  // Starts over: no particles, no conflict record, and the map startFromMap gave (if any) or none.
  void reset();
  // Starts over from nothing: forgets the map startFromMap gave, then reset().
  void startOver();
  // A user's reset (a node's ~reset): saves the map as restart() does, then startOver(). One line
  // saying what was done (and where the map went) goes to `message`.
  void startOver(const std::string& reason, std::string* message);
  // Starts over for `reason` (e.g. "ROS time jumped back by 60 s"), after saving the map as
  // described above. One line saying what was done (and where the map went) goes to `message`.
  void restart(const std::string& reason, std::string* message);
  // Starts over on `map` at `pose` (SlamEngine::startFromMap, which says what `odometry` does),
  // e.g. a map file read with io::readMapFile. A map of another resolution than the session's
  // replaces the engine by one of the map's resolution (parameters().slam.resolution follows).
  // A later reset (a time jump back, a looping bag) starts on this map again. False (and `why`)
  // when the engine refuses it; nothing changes then.
  bool startFromMap(const EvidentialGridMap& map, const Pose2& pose, std::string* why,
                    const Pose2* odometry = nullptr);
  // The map a start at a pose the user gives (a node's /initialpose) should use: the best
  // particle's map, or, before the first scan, the map startFromMap gave or an empty one.
  EvidentialGridMap currentMap() const;
  // Localization mode: from now on scans go to a Localizer on `map` (never written) instead of
  // the SLAM engine, started as `start` says; reset() and restart() start it so again. The map's
  // resolution is used. False (and `why`) when the Localizer refuses the map or the start;
  // nothing changes then. startFromMap() and startOver() return to SLAM mode.
  bool startLocalization(const EvidentialGridMap& map, const LocalizationStart& start,
                         std::string* why);
  // Localization mode only: the particles start again as `start` says (a node's /initialpose,
  // ~global_localization) on the same map, and later resets start so too. False (and `why`) when
  // refused; nothing changes then.
  bool restartLocalization(const LocalizationStart& start, std::string* why);
  bool localizing() const { return localizer_ != nullptr; }
  // localizing() only.
  const Localizer& localizer() const { return *localizer_; }

  // Where maps are saved before a restart (a directory, created when needed); empty: not saved.
  void setResetSaveRoot(const std::string& root) { reset_save_root_ = root; }

  // Pauses or resumes mapping (SlamEngine::setMappingPaused): paused, scans localize on the maps
  // as they are and change none; they feed neither the conflict alarm nor the conflict record
  // (they add no conflict). Kept across reset() and startFromMap; startOver() does not change it.
  void setMappingPaused(bool paused) { engine_->setMappingPaused(paused); }
  bool mappingPaused() const { return engine_->mappingPaused(); }

  const SlamEngine& engine() const { return *engine_; }
  const Parameters& parameters() const { return params_; }
  const std::vector<ConflictRecord>& conflictLog() const { return conflict_log_; }
  uint64_t scansDropped() const { return dropped_; }
  uint64_t stampOutliers() const { return outliers_; }
  uint64_t scansRefused() const { return refused_; }
  uint64_t restarts() const { return restarts_; }
  // The directory of the last map saved before a restart (empty if none).
  const std::string& lastResetSave() const { return last_reset_save_; }

 private:
  // Saves the map before a restart; one line for the message.
  std::string saveBeforeReset();
  // Starts `localizer` as `start` says.
  static bool startLocalizer(Localizer* localizer, const LocalizationStart& start,
                             std::string* why);
  // Forgets the scans' order and origin (a new start).
  void forgetScanOrder();

  Parameters params_;
  std::unique_ptr<SlamEngine> engine_;
  std::unique_ptr<Localizer> localizer_;  // localization mode
  LocalizationStart localization_start_;
  ConflictAlarm alarm_;
  std::vector<ConflictRecord> conflict_log_;
  bool have_last_stamp_ = false;
  double last_stamp_ = 0.0;
  StampOrder order_;  // the stamps' order (time_jump_*)
  bool have_origin_ = false;
  Pose2 origin_;  // the odometry pose of the first scan used (max_map_extent is from here)
  std::string reset_save_root_;
  std::string last_reset_save_;
  uint64_t dropped_ = 0;
  uint64_t outliers_ = 0;
  uint64_t refused_ = 0;
  uint64_t restarts_ = 0;
};

}  // namespace evidential_slam
