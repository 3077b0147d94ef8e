// Conflict alarm (beyond the paper, from its discussion of external conflict): each processed scan
// adds some external conflict (EC, bits) to the map; a localisation failure or a change of the
// environment makes a scan contradict the map far more than usual. The alarm compares each scan's
// EC with a running baseline (the median of recent non-alarming scans) and fires when it exceeds
// it by a factor.
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
  double min_bits = 1.0;          // ... and above this absolute floor (bits per scan)

  bool isValid(std::string* why) const;
};

struct ConflictAlarmState {
  double added_bits = 0.0;     // EC this scan added
  double baseline_bits = 0.0;  // running baseline before this scan
  double ratio = 0.0;          // added / baseline (0 while the baseline is 0)
  bool alarm = false;          // this scan is above the threshold
  bool rising = false;         // ... and the previous one was not: a new alarm
};

class ConflictAlarm {
 public:
  explicit ConflictAlarm(const ConflictAlarmConfig& config = {});

  // Feeds the EC (bits) one processed scan added; returns the verdict for that scan.
  ConflictAlarmState update(double added_bits);
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
