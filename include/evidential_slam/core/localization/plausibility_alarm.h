// Kidnap alarm on the scans' plausibility (localization): a robot carried elsewhere, or a filter
// that lost it, makes its scans less plausible at the particles than while the filter tracked,
// even where a noisy laser contradicts nothing the map holds with confidence.
//
// Its input is each update's log evidence: the scan's log plausibility per weighed beam under the
// predicted cloud, (1 / beams) log Σ w Pl (LocalizationUpdate::log_evidence). It stays high while
// any likely particle explains the scan (a cloud spread in a turn, the mixture proposal's samples
// around a scan match), and falls when none does. Its baseline is the run's own, as the conflict
// alarm's: over the last kBaselineUpdates quiet updates at which the filter had converged, the
// median and the envelope, how far the deepest of them fell below that median. An update is
// below the baseline when it falls more than `factor` times the envelope below the median (a
// kidnap is a step several times deeper than any dip while tracking: people, clutter, a turn);
// the alarm fires when `confirm` consecutive updates are below. The envelope is never taken below
// kMinEnvelope. Updates below never enter the baseline, so a filter left lost keeps alarming. The
// alarm is armed as soon as the baseline holds kMinBaseline updates: no warm-up counted from the
// start, the baseline begins at the first converged updates.
#pragma once

#include <cstddef>
#include <deque>

namespace evidential_slam {

struct PlausibilityAlarmState {
  double value = 0.0;     // this update's log evidence per weighed beam
  double median = 0.0;    // the baseline's median before this update (0 while not armed)
  double envelope = 0.0;  // max(median - its smallest value, kMinEnvelope) (0 while not armed)
  double ratio = 0.0;     // (median - value) / envelope: how far below, in envelopes
  bool armed = false;     // the baseline held kMinBaseline updates
  bool below = false;     // ratio > factor
  bool alarm = false;     // ... and so were the confirm - 1 updates before it
  bool rising = false;    // ... and the previous update did not alarm: a new alarm
};

class PlausibilityAlarm {
 public:
  // The baseline spans this many recent quiet converged updates.
  static constexpr size_t kBaselineUpdates = 50;
  // The fewest updates the median and envelope are taken from (fewer show too few dips).
  static constexpr size_t kMinBaseline = 10;
  // The smallest envelope, nats per beam: a beam's plausibility 0.1 % lower is no evidence of
  // anything (without it an exact simulated laser's near-constant plausibility makes any dip an
  // outlier).
  static constexpr double kMinEnvelope = 1e-3;

  // factor > 0: how many envelopes under the median an update is below; confirm >= 1: updates
  // below in a row that make the alarm.
  PlausibilityAlarm(double factor, int confirm);

  // Judges one update's value (a tracking update: not while a global localization searches);
  // `converged` (the cloud is narrow): a quiet update enters the baseline.
  PlausibilityAlarmState update(double value, bool converged);
  // New thresholds; the baseline is kept.
  void configure(double factor, int confirm);
  // Forgets the baseline and the alarm (a new start).
  void reset();
  // Forgets the updates below and the alarm, keeps the baseline: after the fault was acted on, a
  // new alarm needs `confirm` updates below again.
  void rearm();
  size_t baselineSize() const { return window_.size(); }

 private:
  double factor_;
  int confirm_;
  std::deque<double> window_;  // recent quiet converged values
  int below_ = 0;              // consecutive updates below, up to this one
  bool in_alarm_ = false;
};

}  // namespace evidential_slam
