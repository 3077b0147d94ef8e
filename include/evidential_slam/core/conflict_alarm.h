// Conflict alarm (beyond the paper, from its discussion of external conflict): each processed scan
// adds some conflict to the map; a localisation failure or a change of the environment makes a
// scan contradict the map far more than usual. The alarm compares what each scan added with a
// running baseline (the median of recent scans below the threshold) and fires when it exceeds it
// by a factor and a floor on `confirm_scans` consecutive scans: a filter left lost by a kidnap
// contradicts the map at every scan until it has rewritten it, while one scan the best particle
// placed wrong is a transient (on generated clean runs and on the Intel log, many alarms
// of single scans were such transients: docs/decisions.md#conflict-alarm-input).
//
// Its input is the conflict mass m(∅) the scan added in the map's open space
// (ScanConflict::open_space_added): on cells where the scan puts an obstacle (m̃(e)s(o) >= 1/2)
// and every cell within the forward model's hit window (BeamModel::openSpaceRadius) is believed
// free. Not all the m(∅) a scan adds: that is dominated by the surface band of walls the robot
// maps for the first times (cells partly wall, passed through by grazing beams and hit by others),
// several times more per scan while exploring than when revisiting, so a baseline that spans
// exploration hides a moving object that adds as much. That surface-band conflict lies next to
// cells the map holds occupied or has never seen; a moving object in mapped free space, or a scan
// placed at a wrong pose, puts hits where the map holds open floor, which a correct scan of a
// static world does not (docs/ros.md#conflict-alarm, for the numbers). The floor `min_added` is in
// the same unit, roughly the number of open-space cells newly contradicted.
#pragma once

#include <cstddef>
#include <deque>
#include <string>

#include "evidential_slam/core/parameters.def"

namespace evidential_slam {

struct ConflictAlarmConfig {
  ES_CONFLICT_ALARM_PARAMETERS(ES_DECLARE_PARAMETER_FIELD, )

  bool isValid(std::string* why) const;
};

struct ConflictAlarmState {
  double added = 0.0;     // what this scan added in open space (the alarm's input)
  double baseline = 0.0;  // running baseline before this scan
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
  void setConfig(const ConflictAlarmConfig& config);
  const ConflictAlarmConfig& config() const { return config_; }
  // Median of the baseline window (0 when empty).
  double baseline() const;

 private:
  ConflictAlarmConfig config_;
  std::deque<double> window_;  // recent values below the threshold
  int above_ = 0;              // consecutive scans above the threshold, up to this one
  bool in_alarm_ = false;
};

}  // namespace evidential_slam
