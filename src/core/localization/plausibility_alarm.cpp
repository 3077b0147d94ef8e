#include "evidential_slam/core/localization/plausibility_alarm.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace evidential_slam {

namespace {

// The median of `v` (not empty; reordered).
double medianOf(std::vector<double>* v) {
  const size_t n = v->size(), h = n / 2;
  std::nth_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(h), v->end());
  const double upper = (*v)[h];
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(h)));
}

}  // namespace

PlausibilityAlarm::PlausibilityAlarm(double factor, int confirm) { configure(factor, confirm); }

void PlausibilityAlarm::configure(double factor, int confirm) {
  factor_ = factor;
  confirm_ = std::max(1, confirm);
}

void PlausibilityAlarm::reset() {
  window_.clear();
  rearm();
}

void PlausibilityAlarm::rearm() {
  below_ = 0;
  in_alarm_ = false;
}

PlausibilityAlarmState PlausibilityAlarm::update(double value, bool converged) {
  PlausibilityAlarmState s;
  s.value = value;
  if (!std::isfinite(value)) return s;  // nothing weighed: no verdict, nothing changes
  s.armed = window_.size() >= kMinBaseline;
  if (s.armed) {
    std::vector<double> v(window_.begin(), window_.end());
    s.median = medianOf(&v);
    s.envelope =
        std::max(s.median - *std::min_element(window_.begin(), window_.end()), kMinEnvelope);
    s.ratio = (s.median - value) / s.envelope;
    s.below = s.ratio > factor_;
  }
  below_ = s.below ? below_ + 1 : 0;
  s.alarm = below_ >= confirm_;
  s.rising = s.alarm && !in_alarm_;
  in_alarm_ = s.alarm;
  if (!s.below && converged) {  // an update below must not lower the baseline it is judged against
    window_.push_back(value);
    while (window_.size() > kBaselineUpdates) window_.pop_front();
  }
  return s;
}

}  // namespace evidential_slam
