// What both front ends do around the SLAM engine, once: the order of the scans (a scan older than
// the previous one is dropped; a jump back beyond time_jump_tolerance, a looping bag, starts
// over), the conflict alarm and its per-scan record. The offline runner feeds it a rawlog, the
// ROS node's worker thread feeds it LaserScans; both write its map files with writeMapFiles.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evidential_slam/core/conflict_alarm.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/slam_engine.h"

namespace evidential_slam {

// One processed scan: what it added to the best map and the alarm's verdict (conflict.csv).
struct ConflictRecord {
  double stamp = 0.0;
  double ec_added_bits = 0.0;
  double conflict_mass_added = 0.0;
  ConflictAlarmState alarm;
};

// What became of one scan given to the session.
struct SessionScanResult {
  enum class Order {
    kInOrder,    // handed to the engine
    kDropped,    // older than the previous scan, within the tolerance: not used
    kRestarted,  // time jumped back beyond the tolerance: the SLAM started over with this scan
  };
  Order order = Order::kInOrder;
  double stamp = 0.0;        // the scan's
  std::string message;       // one line, for kDropped and kRestarted
  ScanUpdate update;         // the engine's answer (unless dropped)
  ConflictAlarmState alarm;  // when update.processed
};

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

  // Pauses or resumes mapping (SlamEngine::setMappingPaused): paused, scans localize on the maps
  // as they are and change none; they feed neither the conflict alarm nor the conflict record
  // (they add no conflict). Kept across reset() and startFromMap; startOver() does not change it.
  void setMappingPaused(bool paused) { engine_->setMappingPaused(paused); }
  bool mappingPaused() const { return engine_->mappingPaused(); }

  const SlamEngine& engine() const { return *engine_; }
  const Parameters& parameters() const { return params_; }
  const std::vector<ConflictRecord>& conflictLog() const { return conflict_log_; }
  uint64_t scansDropped() const { return dropped_; }
  uint64_t restarts() const { return restarts_; }

 private:
  Parameters params_;
  std::unique_ptr<SlamEngine> engine_;
  ConflictAlarm alarm_;
  std::vector<ConflictRecord> conflict_log_;
  bool have_last_stamp_ = false;
  double last_stamp_ = 0.0;
  uint64_t dropped_ = 0;
  uint64_t restarts_ = 0;
};

}  // namespace evidential_slam
