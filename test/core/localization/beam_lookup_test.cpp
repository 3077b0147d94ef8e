// The beam model at lookup cost (core/localization/beam_lookup.h): first-opaque ranges by hand on
// small grids (with the march's jumps), its plausibility against the ray-traced model's on a mapped
// room, and its two evidential readings (never-observed ends, short readings).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "../test_support.h"
#include "evidential_slam/core/localization/beam_lookup.h"
#include "evidential_slam/core/particle_filter.h"
#include "evidential_slam/core/slam_engine.h"

namespace evidential_slam {
namespace {

// A 20 x 10 strip (resolution 0.1 m) of empty cells (m(e) = 1: certain) with a wall at
// x = 15 (m(o) = 0.9), an opaque cell at (10, 8) (m(o) = 0.5), a faint one at (7, 5) (m(o) =
// 0.05 < kOpaque: transparent) and a hole never observed at (12, 2).
EvidentialGridMap strip() {
  EvidentialGridMap map(0.1);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) {
      if (x == 12 && y == 2) continue;
      map.mutableCell(x, y).setMasses(0.0f, 1.0f);
    }
    map.mutableCell(15, y).setMasses(0.9f, 0.0f);
  }
  map.mutableCell(10, 8).setMasses(0.5f, 0.0f);
  map.mutableCell(7, 5).setMasses(0.05f, 0.9f);
  return map;
}

// From (0.55, 0.55) along +x the beam passes the faint cell and enters the wall at x = 1.5:
// 0.95 m. Along +y it leaves the box at y = 1.0 with nothing opaque: the maximum range. From
// (0.52, 0.35) at 45°, it crosses y = 0.8 at x = 0.97 (cell (9, 8)) and enters (10, 8) at x = 1.0,
// y = 0.83: 0.48 sqrt(2) = 0.678823 m. From (-1.0, 0.55), off the box, along +x: 2.5 m. Towards
// -x nothing: the maximum range.
TEST(BeamLookup, FirstOpaqueRangesByHand) {
  const BeamLookup lookup(strip(), true);
  EXPECT_EQ(lookup.box().width(), 20);
  EXPECT_EQ(lookup.box().height(), 10);
  EXPECT_NEAR(lookup.firstOpaque({0.55, 0.55}, 0.0, 5.0), 0.95, 1e-9);
  EXPECT_EQ(lookup.firstOpaque({0.55, 0.55}, M_PI / 2, 5.0), 5.0);
  EXPECT_NEAR(lookup.firstOpaque({0.52, 0.35}, M_PI / 4, 5.0), 0.48 * std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(lookup.firstOpaque({-1.0, 0.55}, 0.0, 5.0), 2.5, 1e-9);
  EXPECT_EQ(lookup.firstOpaque({0.55, 0.55}, M_PI, 5.0), 5.0);
  EXPECT_EQ(lookup.firstOpaque({0.55, 0.55}, 0.0, 0.9), 0.9);  // the wall lies beyond the range
  EXPECT_GT(lookup.memoryBytes(), 0u);
  EXPECT_THROW(BeamLookup(EvidentialGridMap(0.1), true), std::invalid_argument);
}

// A long corridor, 400 x 9 cells of 0.05 m, free but for a wall across it at x = 360 and a post
// at (100, 8): from the centre of (0, 4) along +x the march jumps most of the 17.975 m to the
// wall, 17.975 / cos(a) along a small angle a, or the post.
TEST(BeamLookup, TheMarchJumpsWithoutMissingAnOpaqueCell) {
  EvidentialGridMap map(0.05);
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 400; ++x) map.mutableCell(x, y).setMasses(0.0f, 0.95f);
    map.mutableCell(360, y).setMasses(0.8f, 0.0f);
  }
  map.mutableCell(100, 8).setMasses(0.8f, 0.0f);
  const BeamLookup lookup(map, true);
  EXPECT_NEAR(lookup.firstOpaque({0.025, 0.225}, 0.0, 30.0), 17.975, 1e-9);
  // Along a = 0.01 rad the ray climbs 0.18 m over 17.975 m: it stays in the corridor (y < 0.45).
  EXPECT_NEAR(lookup.firstOpaque({0.025, 0.225}, 0.01, 30.0), 17.975 / std::cos(0.01), 1e-9);
  // Towards the middle of the post's bottom edge, (5.025, 0.4): at the post's left edge x = 5.0
  // the ray is at y = 0.3991, below it; it enters from below after hypot(5.0, 0.175) m.
  const double a = std::atan2(0.175, 5.0);
  EXPECT_NEAR(lookup.firstOpaque({0.025, 0.225}, a, 30.0), std::hypot(5.0, 0.175), 1e-9);
}

SlamConfig roomSlam() {
  SlamConfig c = testing_room::withoutRealRobotSettings(SlamConfig());
  c.threads = 1;
  c.particles = 1;
  c.matcher.enabled = false;
  c.motion = testing_room::noiselessMotion();
  return c;
}

// The room of test_support.h (walls at ±2 m), mapped from exact poses.
EvidentialGridMap mappedRoom() {
  SlamEngine engine(roomSlam());
  const std::vector<Pose2> poses = {Pose2(0.0, 0.0, 0.0), Pose2(-0.8, 0.5, 1.0),
                                    Pose2(0.9, -0.7, 2.5), Pose2(0.6, 1.1, -2.0)};
  double stamp = 1.0;
  for (int lap = 0; lap < 3; ++lap) {
    for (const Pose2& p : poses) engine.processScan(p, testing_room::roomScan(p, stamp++));
  }
  return engine.bestMap();
}

// With never-observed cells read as the traced model reads them and no short readings, the
// lookup's plausibility of every hit beam is the traced model's, from poses on and off the truth:
// the jumps leave out only cells with m̃(o) < kOpaque far from opaque ones and certain cells.
TEST(BeamLookup, PlausibilityIsTheTracedModels) {
  const EvidentialGridMap map = mappedRoom();
  const SlamConfig slam = roomSlam();
  const BeamModel model(slam.sensor.forSensorNoise(0.0, map.resolution()), map.resolution());
  const BeamLookup lookup(map, model.config().forward_conflict_as_unknown);
  BeamLookup::Options traced;
  traced.unobserved_collects = true;
  int compared = 0;
  for (const Pose2& truth : {Pose2(0.3, -0.2, 0.4), Pose2(-1.1, 1.0, -2.0)}) {
    const LaserScan scan = testing_room::roomScan(truth);
    for (const Pose2& pose : {truth, Pose2(truth.x + 0.07, truth.y - 0.04, truth.theta + 0.03)}) {
      const LaserScan hits = ParticleFilter::hitBeamSubset(scan, model.config(), 1);
      const Pose2 sensor = pose.compose(hits.sensor_pose);
      for (size_t i = 0; i < hits.ranges.size(); ++i) {
        LaserScan one = hits;
        one.ranges = {hits.ranges[i]};
        one.bearings = {hits.bearings[i]};
        one.valid = {1};
        const double expected = std::exp(model.logPlausibility(map, sensor, one, 1));
        const LookupBeam got = lookup.beam(model, sensor.translation(),
                                           sensor.theta + hits.bearings[i], hits.ranges[i], traced);
        EXPECT_NEAR(got.plausibility, expected, 1e-3 * expected) << "beam " << i;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 500);
}

// On the strip (random weight r = 0.2): a beam ending in the never-observed hole (12, 2), from
// (0.55, 0.25) along +x with z = 0.7 (the hole's centre is 0.7 m ahead), weighs r alone; read as
// the traced model reads it, the hole's m(Θ) = 1 makes it plausible. A beam ending short in the
// confidently free cell (10, 5) (z = 0.5, no opaque cell before or around it) is a short reading:
// its plausibility rises from r to (1 - r) q + r with the short readings' rate q = 0.25. A beam
// ending on the wall is not short.
TEST(BeamLookup, NeverObservedEndsWeighOnlyTheRandomPartAndShortReadingsTheirRate) {
  const EvidentialGridMap map = strip();
  SensorModelConfig sensor = roomSlam().sensor;
  const BeamModel model(sensor, map.resolution());
  const double r = sensor.random_weight;
  const BeamLookup lookup(map, sensor.forward_conflict_as_unknown);
  BeamLookup::Options options;
  const LookupBeam hole = lookup.beam(model, {0.55, 0.25}, 0.0, 0.7, options);
  EXPECT_NEAR(hole.plausibility, r, 1e-6);
  EXPECT_FALSE(hole.short_reading);
  BeamLookup::Options traced;
  traced.unobserved_collects = true;
  EXPECT_GT(lookup.beam(model, {0.55, 0.25}, 0.0, 0.7, traced).plausibility, 0.5);

  const LookupBeam free_end = lookup.beam(model, {0.55, 0.55}, 0.0, 0.5, options);
  EXPECT_TRUE(free_end.short_reading);
  EXPECT_NEAR(free_end.plausibility, r, 1e-3);
  options.short_rate = 0.25;
  EXPECT_NEAR(lookup.beam(model, {0.55, 0.55}, 0.0, 0.5, options).plausibility,
              (1.0 - r) * 0.25 + r, 1e-3);
  const LookupBeam wall = lookup.beam(model, {0.55, 0.55}, 0.0, 0.975, options);
  EXPECT_FALSE(wall.short_reading);
  EXPECT_GT(wall.plausibility, 0.5);

  // A beam leaving the box 0.45 m out and ending 3 m out weighs r; read as traced, as the traced
  // model weighs it (the vacuous cells of its window make it plausible).
  EXPECT_NEAR(lookup.beam(model, {0.55, 0.55}, M_PI / 2, 3.0, BeamLookup::Options()).plausibility,
              r, 1e-9);
  LaserScan up;
  up.max_range = 30.0f;
  up.ranges = {3.0f};
  up.bearings = {0.0f};
  up.valid = {1};
  const double expected = std::exp(model.logPlausibility(map, Pose2(0.55, 0.55, M_PI / 2), up, 1));
  EXPECT_GT(expected, 0.5);
  EXPECT_NEAR(lookup.beam(model, {0.55, 0.55}, M_PI / 2, 3.0, traced).plausibility, expected,
              1e-3 * expected);
}

}  // namespace
}  // namespace evidential_slam
