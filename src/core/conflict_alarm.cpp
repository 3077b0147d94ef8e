#include "evidential_slam/core/conflict_alarm.h"

#include "evidential_slam/core/parameter_rows.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {

ConflictAlarmConfig::ConflictAlarmConfig() {
  ES_CONFLICT_ALARM_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool ConflictAlarmConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_CONFLICT_ALARM_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

ConflictAlarm::ConflictAlarm(const ConflictAlarmConfig& config) : config_(config) {}

void ConflictAlarm::reset() {
  window_.clear();
  above_ = 0;
  in_alarm_ = false;
}

void ConflictAlarm::rearm() {
  above_ = 0;
  in_alarm_ = false;
}

void ConflictAlarm::setConfig(const ConflictAlarmConfig& config) {
  config_ = config;
  while (window_.size() > static_cast<size_t>(std::max(1, config_.baseline_scans))) {
    window_.pop_front();
  }
}

double ConflictAlarm::baseline() const {
  return window_.empty() ? 0.0 : *std::max_element(window_.begin(), window_.end());
}

ConflictAlarmState ConflictAlarm::update(double added) {
  ConflictAlarmState s;
  s.added = std::isfinite(added) ? std::max(0.0, added) : 0.0;
  s.baseline = baseline();
  s.ratio = s.baseline > 0.0 ? s.added / s.baseline : 0.0;
  const bool warm =
      static_cast<int>(window_.size()) >= std::min(config_.warmup_scans, config_.baseline_scans);
  s.above = config_.enabled && warm && s.added > config_.min_added &&
            s.added > config_.threshold_factor * s.baseline;
  above_ = s.above ? above_ + 1 : 0;
  s.alarm = above_ >= std::max(1, config_.confirm_scans);
  s.rising = s.alarm && !in_alarm_;
  in_alarm_ = s.alarm;
  if (!s.above) {  // a scan above the threshold must not raise the baseline it is judged against
    window_.push_back(s.added);
    while (window_.size() > static_cast<size_t>(config_.baseline_scans)) window_.pop_front();
  }
  return s;
}

}  // namespace evidential_slam
