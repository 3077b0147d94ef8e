// Conflict alarm (beyond the paper, from its discussion of external conflict): each processed scan
// adds some conflict to the map; a localisation failure or a change of the environment makes a
// scan contradict the map far more than usual. The alarm compares what each scan added with a
// running baseline (the median of recent non-alarming scans) and fires when it exceeds it by a
// factor. Its input is the conflict mass m(∅) the scan added, summed over cells
// (ScanUpdate::conflict_mass_added): unlike EC in bits, which grows without bound on cells that
// already conflict and so is dominated by the same few cells scan after scan, it counts how many
// cells newly conflict.
#pragma once

#include <cstddef>
#include <deque>
#include <string>

namespace evidential_slam {

struct ConflictAlarmConfig {
  bool enabled = true;
  int baseline_scans = 50;  // processed scans in the running baseline (median)
  int warmup_scans = 10;    // no alarm before the baseline holds this many (or baseline_scans)
  double threshold_factor = 4.0;  // alarm when EC added > factor * baseline
  double min_added = 1.0;         // ... and above this floor (m(∅) summed over cells)

  bool isValid(std::string* why) const;
};

struct ConflictAlarmState {
  double added = 0.0;     // what this scan added (the alarm's input)
  double baseline = 0.0;  // running baseline before this scan
  double ratio = 0.0;     // added / baseline (0 while the baseline is 0)
  bool alarm = false;     // this scan is above the threshold
  bool rising = false;    // ... and the previous one was not: a new alarm
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
  std::deque<double> window_;  // recent non-alarming values
  bool in_alarm_ = false;
};

}  // namespace evidential_slam
