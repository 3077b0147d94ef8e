// Conflict alarm (beyond the paper, from its discussion of external conflict): a localisation
// failure or a change of the environment makes a scan contradict the map far more than usual.
//
// Its input is how much of the map's confident evidence a scan contradicts (ScanConflict::
// contradiction, anomaly.h: ΣK over its hits in the map's open space and its passes through
// obstacles the map holds, about a number of cells): a kidnap does both at once, and its passes
// keep contradicting after the first scans have drawn the ghost walls into the map.
//
// Its baseline is the run's own envelope: the largest input of the last `baseline_scans` quiet
// scans. A scan is above the threshold when its input exceeds `threshold_factor` times that and the
// floor `min_added`; the alarm fires when `confirm_scans` consecutive scans are above it. On real
// robots a correct scan contradicts the map too (chair and table legs seen from one side only,
// people, glass, range noise), by an amount that depends on the sensor and the place and grows
// over a few scans as the robot drives into clutter, so the envelope grows with it; a kidnap is a
// step: its first scan contradicts the map several times more than any scan before it
// (docs/decisions.md#conflict-alarm-the-runs-own-envelope). Scans above the threshold never
// enter the baseline they are judged against, so a fault that persists keeps alarming.
#pragma once

#include <cstddef>
#include <deque>
#include <string>

#include "evidential_slam/core/parameter_fields/conflict_alarm.h"

namespace evidential_slam {

struct ConflictAlarmConfig {
  ConflictAlarmConfig();  // the table's defaults
  ES_CONFLICT_ALARM_FIELDS

  bool isValid(std::string* why) const;
};

struct ConflictAlarmState {
  double added = 0.0;     // the alarm's input for this scan (ScanConflict::contradiction)
  double baseline = 0.0;  // the envelope before this scan: the largest input of recent quiet scans
  double ratio = 0.0;     // added / baseline (0 while the baseline is 0)
  bool above = false;     // this scan is above the threshold
  bool alarm = false;     // ... and so were the confirm_scans - 1 before it
  bool rising = false;    // ... and the previous scan did not alarm: a new alarm
};

class ConflictAlarm {
 public:
  explicit ConflictAlarm(const ConflictAlarmConfig& config = {});

  // Feeds what one processed scan added; returns the verdict for that scan.
  ConflictAlarmState update(double added);
  void reset();
  // Forgets the scans above the threshold and the alarm, keeps the baseline: after the fault was
  // acted on (a localizer spread its particles again), a new alarm needs confirm_scans again.
  void rearm();
  void setConfig(const ConflictAlarmConfig& config);
  const ConflictAlarmConfig& config() const { return config_; }
  // The largest value in the baseline window (0 when empty).
  double baseline() const;

 private:
  ConflictAlarmConfig config_;
  std::deque<double> window_;  // recent values below the threshold
  int above_ = 0;              // consecutive scans above the threshold, up to this one
  bool in_alarm_ = false;
};

}  // namespace evidential_slam
