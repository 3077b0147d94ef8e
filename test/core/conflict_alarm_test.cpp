// Tests of the conflict alarm (conflict_alarm.h): the conflict mass a scan adds in the map's open
// space (ScanConflict::open_space_added, sensor_model.h, reported beside the alarm's input), on
// hand-built maps; and the alarm itself on hand-made sequences of its input.
#include <gtest/gtest.h>

#include <cmath>

#include "cell_support.h"
#include "evidential_slam/core/conflict_alarm.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/sensor_model.h"

namespace evidential_slam {
namespace {

using namespace testing_cells;

constexpr double kRes = 0.05;
// Cells store m̃ in steps of 2^-23 and λ as a half float: sums over them computed from the
// nominal values agree to ~1e-4.
constexpr double kStored = 1e-4;

// Per touched cell with m̃(e)s(o) >= 1/2 whose (2r+1)^2 neighbourhood is all m̃(e) > m̃(o), the
// m(∅) the update adds: e^{-λ} (m̃(o)s(e) + m̃(e)s(o)).
TEST(OpenSpaceConflict, HitsOnOpenFloorCountWhatTheyAdd) {
  EvidentialGridMap map = filledMap(storedCell(0.0f, 0.99f));
  map.mutableCell(3, 0) = storedCell(0.05f, 0.9f, static_cast<float>(std::log(2.0)));
  ScanAccumulator acc;
  acc.reset(CellIndex{0, 0}, 8);
  acc.add(0, 0, scanMass(0.8f, 0.0f));    // K = 0.99 * 0.8 = 0.792
  acc.add(3, 0, scanMass(0.7f, 0.1f));    // K = 0.05 * 0.1 + 0.9 * 0.7 = 0.635, e^{-λ} = 1/2
  acc.add(-3, 0, scanMass(0.5f, 0.0f));   // m̃(e)s(o) = 0.495 < 1/2: not counted
  acc.add(0, 3, scanMass(0.0f, 0.8f));    // clear: agrees, nothing
  acc.add(0, -3, scanMass(0.19f, 0.0f));  // the hit's side mass: below 1/2
  const double expected = 0.792 + 0.5 * 0.635;
  EXPECT_NEAR(acc.openSpaceConflict(map, 2), expected, kStored);

  // It is the m(∅) applyTo then adds on those two cells, and part of the total.
  const double before = -std::expm1(-static_cast<double>(map.cell(0, 0).lambda())) -
                        std::expm1(-static_cast<double>(map.cell(3, 0).lambda()));
  double total = 0.0;
  acc.applyTo(&map, &total);
  const double after = -std::expm1(-static_cast<double>(map.cell(0, 0).lambda())) -
                       std::expm1(-static_cast<double>(map.cell(3, 0).lambda()));
  EXPECT_NEAR(after - before, expected, kStored);
  EXPECT_GT(total, expected - 1e-6);
  EXPECT_NEAR(total, expected + 0.495 * 1.0 + 0.19 * 0.99, kStored);  // + the two weak hits
}

// A hit within `radius` cells of a cell the map does not hold free (occupied, or never observed)
// is next to a surface the map knows: not open space. Radius 2: a cell 2 away excludes it, 3 away
// does not.
TEST(OpenSpaceConflict, HitsNextToSurfacesOrTheUnknownDoNotCount) {
  const ScanMass hit = scanMass(0.8f, 0.0f);
  auto conflictWith = [&hit](int dx, int dy, const Cell& neighbour) {
    EvidentialGridMap map = filledMap(storedCell(0.0f, 0.99f));
    map.mutableCell(dx, dy) = neighbour;
    ScanAccumulator acc;
    acc.reset(CellIndex{0, 0}, 8);
    acc.add(0, 0, hit);
    return acc.openSpaceConflict(map, 2);
  };
  const Cell wall = storedCell(0.6f, 0.3f);
  const Cell unknown;  // vacuous: m̃(e) = m̃(o) = 0, not believed free
  const Cell balanced = storedCell(0.4f, 0.4f);
  EXPECT_NEAR(conflictWith(5, 5, wall), 0.792, kStored);
  EXPECT_EQ(conflictWith(1, 0, wall), 0.0);
  EXPECT_EQ(conflictWith(2, -2, wall), 0.0);
  EXPECT_NEAR(conflictWith(3, 0, wall), 0.792, kStored);
  EXPECT_NEAR(conflictWith(0, -3, wall), 0.792, kStored);
  EXPECT_EQ(conflictWith(-1, 1, unknown), 0.0);
  EXPECT_EQ(conflictWith(0, 2, balanced), 0.0);
  // The observed map ends at x = 10: a hit at x = 9 counts with radius 1, not with radius 2.
  EvidentialGridMap map = filledMap(storedCell(0.0f, 0.99f));
  ScanAccumulator acc;
  acc.reset(CellIndex{9, 0}, 8);
  acc.add(9, 0, hit);
  EXPECT_EQ(acc.openSpaceConflict(map, 2), 0.0);
  EXPECT_NEAR(acc.openSpaceConflict(map, 1), 0.792, kStored);
}

// The radius is the forward model's hit window in cells: ceil(k_f σ_f / Δ).
TEST(OpenSpaceConflict, RadiusIsTheForwardHitWindow) {
  SensorModelConfig c;
  c.forward_sigma = 0.025;
  c.forward_window = 3.0;
  EXPECT_EQ(BeamModel(c, 0.05).openSpaceRadius(), 2);   // 0.075 m / 0.05 m = 1.5
  EXPECT_EQ(BeamModel(c, 0.1).openSpaceRadius(), 1);    // 0.75
  EXPECT_EQ(BeamModel(c, 0.025).openSpaceRadius(), 3);  // exactly 3
  c.forward_sigma = 0.05;
  EXPECT_EQ(BeamModel(c, 0.05).openSpaceRadius(), 3);
}

// integrateScan: one beam of 1.0 m along +x from (0.025, 0.025) ends at the centre of cell
// (20, 0), where the inverse model puts o = 0.62554889 (sensor_model_test.cpp). On open floor
// (m̃(e) = 0.99) only that cell passes m̃(e)s(o) >= 1/2: open_space_added = 0.99 * 0.62554889;
// with a wall cell 2 cells beyond the hit, nothing is in open space, though as much m(∅) is added.
TEST(OpenSpaceConflict, IntegrateScanReportsIt) {
  SensorModelConfig config;
  config.hit_sigma = config.forward_sigma = 0.025;
  config.forward_window = config.free_gap = 3.0;
  config.random_weight = 0.2;
  config.prior_occupied = 0.4;
  const BeamModel model(config, kRes);
  LaserScan scan;
  scan.max_range = 30.0f;
  scan.ranges = {1.0f};
  scan.bearings = {0.0f};
  scan.valid = {1};
  TracedScan traced;
  model.traceScan(Pose2(0.025, 0.025, 0.0), scan, &traced);
  auto floorMap = [] {
    EvidentialGridMap map(kRes);
    for (int y = -5; y <= 5; ++y) {
      for (int x = -5; x <= 40; ++x) map.mutableCell(x, y) = storedCell(0.0f, 0.99f);
    }
    return map;
  };
  ScanAccumulator scratch;
  EvidentialGridMap open = floorMap();
  ScanConflict conflict;
  model.integrateScan(traced, &open, &scratch, &conflict);
  EXPECT_NEAR(conflict.open_space_added, 0.99 * 0.62554889, 1e-3);
  EXPECT_GT(conflict.mass_added, conflict.open_space_added);

  EvidentialGridMap walled = floorMap();
  walled.mutableCell(22, 0) = storedCell(0.9f, 0.0f);
  ScanConflict near_wall;
  model.integrateScan(traced, &walled, &scratch, &near_wall);
  EXPECT_EQ(near_wall.open_space_added, 0.0);
  EXPECT_NEAR(near_wall.mass_added, conflict.mass_added, 0.01);  // cell 22's o is ~0.002
}

ConflictAlarmConfig smallConfig() {
  ConflictAlarmConfig c;
  c.baseline_scans = 5;
  c.warmup_scans = 3;
  c.threshold_factor = 4.0;
  c.min_added = 1.0;
  c.confirm_scans = 1;
  return c;
}

TEST(ConflictAlarm, BaselineIsTheLargestOfRecentQuietScans) {
  ConflictAlarm alarm(smallConfig());
  EXPECT_DOUBLE_EQ(alarm.baseline(), 0.0);
  for (double v : {2.0, 10.0, 3.0}) alarm.update(v);  // warm-up: 10 > 4 x 2 does not alarm
  EXPECT_DOUBLE_EQ(alarm.baseline(), 10.0);           // the largest of {2, 10, 3}
  for (double v : {4.0, 5.0, 6.0}) alarm.update(v);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 10.0);  // the window keeps the last 5: {10, 3, 4, 5, 6}
  alarm.update(1.0);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 6.0);  // 10 has left it: {3, 4, 5, 6, 1}
}

// Baseline 2: 7.9 stays quiet (< 4 x 2) and becomes the baseline; 31.5 (< 4 x 7.9 = 31.6) too;
// 126.5 (> 4 x 31.5 = 126) alarms and rises once, the next alarming scan does not rise again, and
// alarming scans do not enter the baseline.
TEST(ConflictAlarm, FiresAboveFactorTimesBaseline) {
  ConflictAlarm alarm(smallConfig());
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(alarm.update(2.0).alarm);
  ConflictAlarmState s = alarm.update(7.9);
  EXPECT_FALSE(s.alarm);
  EXPECT_DOUBLE_EQ(s.baseline, 2.0);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 7.9);  // a quiet scan enters the window
  s = alarm.update(31.5);                   // 4 x 7.9 = 31.6
  EXPECT_FALSE(s.alarm);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 31.5);
  s = alarm.update(126.5);  // > 4 x 31.5 = 126
  EXPECT_TRUE(s.alarm);
  EXPECT_TRUE(s.rising);
  EXPECT_NEAR(s.ratio, 126.5 / 31.5, 1e-12);
  s = alarm.update(500.0);
  EXPECT_TRUE(s.alarm);
  EXPECT_FALSE(s.rising);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 31.5);  // {2, 2, 2, 7.9, 31.5}: the alarms stayed out
  EXPECT_FALSE(alarm.update(2.0).alarm);
  EXPECT_TRUE(alarm.update(127.0).rising);  // a new episode
}

TEST(ConflictAlarm, QuietDuringWarmupBelowFloorAndWhenDisabled) {
  ConflictAlarm alarm(smallConfig());
  EXPECT_FALSE(alarm.update(0.0).alarm);
  EXPECT_FALSE(alarm.update(100.0).alarm);  // warm-up: only 1 scan in the baseline
  ConflictAlarm tiny(smallConfig());
  for (int i = 0; i < 5; ++i) tiny.update(0.01);
  EXPECT_FALSE(tiny.update(0.9).alarm);  // 90 x the baseline, but below min_added
  ConflictAlarm tiny2(smallConfig());
  for (int i = 0; i < 5; ++i) tiny2.update(0.01);
  EXPECT_TRUE(tiny2.update(1.5).alarm);
  ConflictAlarmConfig off = smallConfig();
  off.enabled = false;
  ConflictAlarm disabled(off);
  for (int i = 0; i < 5; ++i) disabled.update(1.0);
  EXPECT_FALSE(disabled.update(1000.0).alarm);
}

// With the defaults (floor 5, factor 4, 2 scans to confirm, no alarm before the window holds 50
// scans). A simulated run's input is ~0 before a fault, so the floor decides: 4.9 stays quiet, one
// scan at 22 (a scan the best particle placed wrong) does not alarm, two in a row do, and a fault
// that persists keeps alarming: its scans never enter the baseline.
TEST(ConflictAlarm, ZeroBaselineLeavesItToTheFloor) {
  const ConflictAlarmConfig defaults;
  EXPECT_EQ(defaults.min_added, 5.0);
  EXPECT_EQ(defaults.threshold_factor, 4.0);
  EXPECT_EQ(defaults.baseline_scans, 50);
  EXPECT_EQ(defaults.warmup_scans, 50);
  EXPECT_EQ(defaults.confirm_scans, 2);
  ConflictAlarm alarm(defaults);
  for (int i = 0; i < 49; ++i) EXPECT_FALSE(alarm.update(0.0).alarm);
  EXPECT_FALSE(alarm.update(30.0).above);  // 50th scan: 49 in the window, still warming up
  EXPECT_DOUBLE_EQ(alarm.baseline(), 30.0);
  ConflictAlarm fresh(defaults);
  for (int i = 0; i < 50; ++i) fresh.update(0.0);
  EXPECT_FALSE(fresh.update(4.9).above);  // under the floor (and now the baseline)
  ConflictAlarmState s = fresh.update(22.0);
  EXPECT_TRUE(s.above);
  EXPECT_FALSE(s.alarm);
  EXPECT_FALSE(fresh.update(0.0).alarm);  // a transient: quiet again
  EXPECT_FALSE(fresh.update(22.0).alarm);
  s = fresh.update(22.0);
  EXPECT_TRUE(s.alarm);
  EXPECT_TRUE(s.rising);
  EXPECT_DOUBLE_EQ(s.baseline, 4.9);
  EXPECT_NEAR(s.ratio, 22.0 / 4.9, 1e-12);
  for (int i = 0; i < 60; ++i) EXPECT_TRUE(fresh.update(20.0).alarm) << i;
  EXPECT_DOUBLE_EQ(fresh.baseline(), 4.9);
}

// A real robot driving into clutter: each scan contradicts the map more than the one before
// (5, 12, 30, 70, 150 cells: chair legs, people), but never more than 4 x the largest of the
// quiet scans before it, so the envelope grows with it and the defaults never alarm, although
// 12 to 150 are over the floor (a median baseline, 1 here, alarmed at 30). A kidnap 50 quiet
// scans later, when the envelope holds only their largest, 20: 90 and 85 are over 4 x 20 = 80
// and alarm on the second. Right after the ramp the same two scans do not.
TEST(ConflictAlarm, ARampRaisesTheEnvelopeAStepAlarms) {
  const ConflictAlarmConfig defaults;
  ConflictAlarm alarm(defaults);
  for (int i = 0; i < 50; ++i) EXPECT_FALSE(alarm.update(1.0).alarm);
  for (double v : {5.0, 12.0, 30.0, 70.0, 150.0}) {
    const ConflictAlarmState s = alarm.update(v);
    EXPECT_FALSE(s.above) << v;
  }
  EXPECT_DOUBLE_EQ(alarm.baseline(), 150.0);
  for (int i = 0; i < 50; ++i) EXPECT_FALSE(alarm.update(i % 10 == 0 ? 20.0 : 2.0).alarm);
  EXPECT_DOUBLE_EQ(alarm.baseline(), 20.0);  // the ramp has left the window
  ConflictAlarmState s = alarm.update(90.0);
  EXPECT_TRUE(s.above);
  EXPECT_FALSE(s.alarm);
  s = alarm.update(85.0);
  EXPECT_TRUE(s.alarm);
  EXPECT_TRUE(s.rising);
  EXPECT_NEAR(s.ratio, 85.0 / 20.0, 1e-12);
  ConflictAlarm after_ramp(defaults);
  for (int i = 0; i < 50; ++i) after_ramp.update(1.0);
  for (double v : {5.0, 12.0, 30.0, 70.0, 150.0}) after_ramp.update(v);
  EXPECT_FALSE(after_ramp.update(90.0).above);  // 4 x 150 = 600
  EXPECT_FALSE(after_ramp.update(85.0).alarm);
}

// rearm (a localizer acted on the alarm): the alarm and its count of scans above the threshold
// are forgotten, the baseline is kept; a fault that goes on rises again once confirmed.
TEST(ConflictAlarm, RearmKeepsTheBaseline) {
  ConflictAlarmConfig c = smallConfig();
  c.confirm_scans = 2;
  ConflictAlarm alarm(c);
  for (int i = 0; i < 5; ++i) alarm.update(3.0);
  EXPECT_FALSE(alarm.update(50.0).alarm);  // > 4 x 3, the first of two
  EXPECT_TRUE(alarm.update(50.0).rising);
  alarm.rearm();
  EXPECT_DOUBLE_EQ(alarm.baseline(), 3.0);
  EXPECT_FALSE(alarm.update(50.0).alarm);  // counted again from the first
  const ConflictAlarmState s = alarm.update(50.0);
  EXPECT_TRUE(s.alarm);
  EXPECT_TRUE(s.rising);
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
  EXPECT_NE(why.find("conflict_alarm_factor"), std::string::npos) << why;
  bad = smallConfig();
  bad.warmup_scans = -1;
  EXPECT_FALSE(bad.isValid(&why));
}

}  // namespace
}  // namespace evidential_slam
