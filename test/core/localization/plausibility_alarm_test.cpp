// The kidnap alarm on the scans' plausibility (plausibility_alarm.h): median and envelope of the
// baseline by hand, the alarm at the expected update, the baseline fed only by quiet converged
// updates, no warm-up beyond the baseline's first kMinBaseline updates, rearm and reset.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "evidential_slam/core/localization/plausibility_alarm.h"

namespace evidential_slam {
namespace {

// Ten converged updates. Sorted: -0.13 -0.12 -0.11 -0.10 -0.10 | -0.10 -0.10 -0.09 -0.08 -0.07,
// median (-0.10 - 0.10) / 2 = -0.10; the deepest fell to -0.13: envelope 0.03. With factor 3 an
// update is below under -0.10 - 3 * 0.03 = -0.19.
const std::vector<double> kQuiet = {-0.10, -0.12, -0.08, -0.11, -0.09,
                                    -0.10, -0.13, -0.07, -0.10, -0.10};

void feed(PlausibilityAlarm* alarm, const std::vector<double>& values, bool converged = true) {
  for (double v : values) {
    const PlausibilityAlarmState s = alarm->update(v, converged);
    EXPECT_FALSE(s.alarm) << v;
  }
}

TEST(PlausibilityAlarm, BaselineByHandAndAlarmAtTheSecondUpdateBelow) {
  PlausibilityAlarm alarm(3.0, 2);
  // Not armed before the baseline holds kMinBaseline = 10 updates: no verdict, whatever the value.
  for (size_t i = 0; i < kQuiet.size(); ++i) {
    const PlausibilityAlarmState s = alarm.update(kQuiet[i], true);
    EXPECT_FALSE(s.armed) << i;
    EXPECT_FALSE(s.below) << i;
  }
  ASSERT_EQ(alarm.baselineSize(), 10u);
  // The 11th: -0.20 lies (-0.10 + 0.20) / 0.03 = 3.333 envelopes under the median: below, the
  // first of two.
  PlausibilityAlarmState s = alarm.update(-0.20, true);
  EXPECT_TRUE(s.armed);
  EXPECT_NEAR(s.median, -0.10, 1e-12);
  EXPECT_NEAR(s.envelope, 0.03, 1e-12);
  EXPECT_NEAR(s.ratio, 10.0 / 3.0, 1e-9);
  EXPECT_TRUE(s.below);
  EXPECT_FALSE(s.alarm);
  EXPECT_EQ(alarm.baselineSize(), 10u);  // a value below stays out of the baseline
  // The 12th, below again: the alarm rises.
  s = alarm.update(-0.20, true);
  EXPECT_TRUE(s.alarm);
  EXPECT_TRUE(s.rising);
  // The 13th: still on, not a new alarm.
  s = alarm.update(-0.30, true);
  EXPECT_TRUE(s.alarm);
  EXPECT_FALSE(s.rising);
  // Re-armed (the particles were drawn again): the baseline is kept, a new alarm needs two again.
  alarm.rearm();
  EXPECT_EQ(alarm.baselineSize(), 10u);
  s = alarm.update(-0.20, true);
  EXPECT_TRUE(s.below);
  EXPECT_FALSE(s.alarm);
  s = alarm.update(-0.20, true);
  EXPECT_TRUE(s.rising);
  // Reset (a new start): the baseline is gone.
  alarm.reset();
  EXPECT_EQ(alarm.baselineSize(), 0u);
  EXPECT_FALSE(alarm.update(-5.0, true).armed);
}

TEST(PlausibilityAlarm, ThresholdIsFactorEnvelopesUnderTheMedian) {
  // The threshold -0.19: -0.195 (3.167 envelopes) is below, -0.185 (2.833) is not.
  PlausibilityAlarm alarm(3.0, 1);
  feed(&alarm, kQuiet);
  PlausibilityAlarmState s = alarm.update(-0.195, true);
  EXPECT_NEAR(s.ratio, 0.095 / 0.03, 1e-9);
  EXPECT_TRUE(s.alarm);  // one update below is enough with confirm 1
  PlausibilityAlarm other(3.0, 1);
  feed(&other, kQuiet);
  s = other.update(-0.185, true);
  EXPECT_NEAR(s.ratio, 0.085 / 0.03, 1e-9);
  EXPECT_FALSE(s.below);
  // It entered the baseline: 11 values, median -0.10, the deepest now -0.185 (envelope 0.085);
  // -0.30 lies (0.20 / 0.085) = 2.35 envelopes below: a dip like those seen is no longer an alarm.
  EXPECT_EQ(other.baselineSize(), 11u);
  s = other.update(-0.30, true);
  EXPECT_NEAR(s.envelope, 0.085, 1e-12);
  EXPECT_NEAR(s.ratio, 0.20 / 0.085, 1e-9);
  EXPECT_FALSE(s.below);
}

TEST(PlausibilityAlarm, AnIsolatedDipDoesNotAlarm) {
  PlausibilityAlarm alarm(3.0, 2);
  feed(&alarm, kQuiet);
  EXPECT_TRUE(alarm.update(-0.30, true).below);
  EXPECT_FALSE(alarm.update(-0.10, true).below);  // back: the count starts over
  const PlausibilityAlarmState s = alarm.update(-0.30, true);
  EXPECT_TRUE(s.below);
  EXPECT_FALSE(s.alarm);
}

TEST(PlausibilityAlarm, OnlyConvergedUpdatesEnterTheBaseline) {
  PlausibilityAlarm alarm(3.0, 2);
  // A wide cloud's updates are judged (once armed) but never make the baseline: nine converged
  // ones do not arm it.
  feed(&alarm, std::vector<double>(kQuiet.begin(), kQuiet.begin() + 9));
  feed(&alarm, {-0.5, -0.6, -0.7}, false);
  EXPECT_EQ(alarm.baselineSize(), 9u);
  EXPECT_FALSE(alarm.update(-0.10, true).armed);
  EXPECT_TRUE(alarm.update(-0.10, true).armed);  // the tenth came in the update before
}

TEST(PlausibilityAlarm, EnvelopeFloorAndWindow) {
  // A constant plausibility never dipped: the envelope is kMinEnvelope, 0.001.
  PlausibilityAlarm alarm(3.0, 1);
  feed(&alarm, std::vector<double>(10, -0.05));
  PlausibilityAlarmState s = alarm.update(-0.0535, true);
  EXPECT_NEAR(s.envelope, PlausibilityAlarm::kMinEnvelope, 1e-15);
  EXPECT_NEAR(s.ratio, 3.5, 1e-9);
  EXPECT_TRUE(s.alarm);
  PlausibilityAlarm other(3.0, 1);
  feed(&other, std::vector<double>(10, -0.05));
  s = other.update(-0.0525, true);
  EXPECT_NEAR(s.ratio, 2.5, 1e-9);
  EXPECT_FALSE(s.below);
  // The window keeps the last kBaselineUpdates quiet updates.
  PlausibilityAlarm window(3.0, 1);
  feed(&window, std::vector<double>(PlausibilityAlarm::kBaselineUpdates + 7, -0.1));
  EXPECT_EQ(window.baselineSize(), PlausibilityAlarm::kBaselineUpdates);
}

TEST(PlausibilityAlarm, NonFiniteValuesChangeNothing) {
  PlausibilityAlarm alarm(3.0, 2);
  feed(&alarm, kQuiet);
  EXPECT_TRUE(alarm.update(-0.30, true).below);
  const PlausibilityAlarmState s = alarm.update(std::nan(""), true);
  EXPECT_FALSE(s.below);
  EXPECT_EQ(alarm.baselineSize(), 10u);
  EXPECT_TRUE(alarm.update(-0.30, true).rising);  // the run of updates below went on
}

}  // namespace
}  // namespace evidential_slam
