// Tests of the conflict alarm (conflict_alarm.h) on hand-made EC sequences.
#include <gtest/gtest.h>

#include "evidential_slam/core/conflict_alarm.h"

namespace evidential_slam {
namespace {

ConflictAlarmConfig smallConfig() {
  ConflictAlarmConfig c;
  c.baseline_scans = 5;
  c.warmup_scans = 3;
  c.threshold_factor = 4.0;
  c.min_added = 1.0;
  return c;
}

TEST(ConflictAlarm, BaselineIsTheMedianOfRecentScans) {
  ConflictAlarm alarm(smallConfig());
  EXPECT_DOUBLE_EQ(alarm.baseline(), 0.0);
  for (double v : {2.0, 10.0, 3.0}) alarm.update(v);  // 10 > 4 * 2.5? warm-up: no alarm yet
  EXPECT_DOUBLE_EQ(alarm.baseline(), 3.0);            // median of {2, 10, 3}
  alarm.update(4.0);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 3.5);  // median of {2, 10, 3, 4}
  for (double v : {5.0, 6.0}) alarm.update(v);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 5.0);  // the window keeps the last 5: {10, 3, 4, 5, 6}
}

// Baseline 2: 7.9 stays quiet (< 4 x 2), 8.5 alarms and rises once, the next alarming scan
// does not rise again, and alarming scans do not enter the baseline.
TEST(ConflictAlarm, FiresAboveFactorTimesBaseline) {
  ConflictAlarm alarm(smallConfig());
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(alarm.update(2.0).alarm);
  ConflictAlarmState s = alarm.update(7.9);
  EXPECT_FALSE(s.alarm);
  EXPECT_DOUBLE_EQ(s.baseline, 2.0);
  s = alarm.update(8.5);
  EXPECT_TRUE(s.alarm);
  EXPECT_TRUE(s.rising);
  EXPECT_NEAR(s.ratio, 8.5 / 2.0, 1e-12);
  s = alarm.update(50.0);
  EXPECT_TRUE(s.alarm);
  EXPECT_FALSE(s.rising);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 2.0);  // {2, 2, 2, 2, 7.9} -> 2
  EXPECT_FALSE(alarm.update(2.0).alarm);
  EXPECT_TRUE(alarm.update(9.0).rising);  // a new episode
}

TEST(ConflictAlarm, QuietDuringWarmupBelowFloorAndWhenDisabled) {
  ConflictAlarm alarm(smallConfig());
  EXPECT_FALSE(alarm.update(0.0).alarm);
  EXPECT_FALSE(alarm.update(100.0).alarm);  // warm-up: only 1 scan in the baseline
  ConflictAlarm tiny(smallConfig());
  for (int i = 0; i < 5; ++i) tiny.update(0.01);
  EXPECT_FALSE(tiny.update(0.9).alarm);  // 90 x the baseline, but below min_added
  EXPECT_TRUE(tiny.update(1.5).alarm);
  ConflictAlarmConfig off = smallConfig();
  off.enabled = false;
  ConflictAlarm disabled(off);
  for (int i = 0; i < 5; ++i) disabled.update(1.0);
  EXPECT_FALSE(disabled.update(1000.0).alarm);
}

TEST(ConflictAlarm, ResetAndValidation) {
  ConflictAlarm alarm(smallConfig());
  for (int i = 0; i < 5; ++i) alarm.update(3.0);
  alarm.reset();
  EXPECT_DOUBLE_EQ(alarm.baseline(), 0.0);
  std::string why;
  EXPECT_TRUE(ConflictAlarmConfig().isValid(&why)) << why;
  ConflictAlarmConfig bad = smallConfig();
  bad.threshold_factor = 1.0;
  EXPECT_FALSE(bad.isValid(&why));
  EXPECT_NE(why.find("threshold_factor"), std::string::npos);
  bad = smallConfig();
  bad.warmup_scans = -1;
  EXPECT_FALSE(bad.isValid(&why));
}

}  // namespace
}  // namespace evidential_slam
