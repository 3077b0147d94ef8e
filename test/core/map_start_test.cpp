// Starting the SLAM on a given map (SlamEngine::startFromMap, ParticleFilter::startOnMap): every
// particle on the map's shared tiles at the given pose, the first scan matched from there, reset()
// back onto the map, and the checks on what is given.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "evidential_slam/core/slam_engine.h"
#include "test_support.h"
#include "cell_support.h"

namespace evidential_slam {
namespace {

using testing_cells::sameCells;
using testing_cells::sharedTiles;
using testing_room::roomScan;

SlamConfig smallConfig() {
  SlamConfig c;
  c.particles = 8;
  c.threads = 1;
  return c;
}

// The room with its box (asymmetric: a pose in it is unambiguous), mapped from three poses taken
// as exact (no matcher, no motion noise), plus one tile far away that no scan of the room reaches.
EvidentialGridMap roomMap(const SlamConfig& config) {
  SlamConfig exact = config;
  exact.matcher.enabled = false;
  exact.motion = testing_room::noiselessMotion();
  SlamEngine engine(exact);
  const std::vector<Pose2> poses = {Pose2(0, 0, 0), Pose2(-0.6, -0.6, 0.0), Pose2(-0.6, 0.3, 0.0)};
  double stamp = 1.0;
  for (const Pose2& p : poses) engine.processScan(p, roomScan(p, stamp++, true));
  EvidentialGridMap map = engine.bestMap();
  updateCell(map.mutableCell(2000, 2000), ScanMass{0.6f, 0.0f});
  return map;
}

// Before any scan every particle holds the given map, sharing all its tiles, at the start pose.
TEST(MapStartTest, ParticlesShareTheMapAtThePose) {
  const SlamConfig config = smallConfig();
  const EvidentialGridMap map = roomMap(config);
  const EvidentialGridMap copy = map;  // shares the tiles: the map's own cells stay readable
  SlamEngine engine(config);
  const Pose2 start(0.3, -0.2, 0.4);
  std::string why;
  ASSERT_TRUE(engine.startFromMap(map, start, &why)) << why;
  EXPECT_TRUE(engine.hasStartMap());
  ASSERT_EQ(engine.filter().particles().size(), 8u);
  for (const Particle& p : engine.filter().particles()) {
    EXPECT_EQ(sharedTiles(p.map, map), map.allocatedTiles());
    EXPECT_EQ(p.pose.x, start.x);
    EXPECT_EQ(p.pose.y, start.y);
    EXPECT_EQ(p.pose.theta, start.theta);
  }
  EXPECT_TRUE(sameCells(engine.bestMap(), map));
  EXPECT_EQ(engine.bestPose().x, start.x);
  EXPECT_EQ(engine.bestPose().theta, start.theta);
  EXPECT_EQ(engine.stats().scans_processed, 0u);
  // Nothing was copied: the tiles are held by the map, its copy, the engine's start and 8
  // particles.
  EXPECT_EQ(sharedTiles(copy, map), map.allocatedTiles());
}

// The first scan after the start is taken at the start pose whatever its odometry says; the
// matcher refines from there, and the best pose lands on the true one (where the scan was taken)
// within the matcher's precision: the room's walls lie on cell boundaries, where matching to cell
// centres is half a cell (2.5 cm) ambiguous.
TEST(MapStartTest, FirstScanIsAtTheStartPose) {
  const SlamConfig config = smallConfig();
  const EvidentialGridMap map = roomMap(config);
  SlamEngine engine(config);
  const Pose2 start(0.3, -0.2, 0.4);
  ASSERT_TRUE(engine.startFromMap(map, start, nullptr));
  const ScanUpdate u = engine.processScan(Pose2(5.0, 7.0, -2.0), roomScan(start, 10.0, true));
  ASSERT_TRUE(u.processed) << u.why;
  EXPECT_NEAR(u.best_pose.x, start.x, 0.03);
  EXPECT_NEAR(u.best_pose.y, start.y, 0.03);
  EXPECT_NEAR(normalizeAngle(u.best_pose.theta - start.theta), 0.0, 0.01);
  // The trajectory's first pose is that pose; map -> odom maps the odometry onto it.
  const std::vector<StampedPose> path = engine.bestTrajectory();
  ASSERT_EQ(path.size(), 1u);
  EXPECT_NEAR(path[0].pose.x, u.best_pose.x, 1e-12);
  const Pose2 via_odom = engine.mapToOdom().compose(Pose2(5.0, 7.0, -2.0));
  EXPECT_NEAR(via_odom.x, u.best_pose.x, 1e-9);
  EXPECT_NEAR(via_odom.y, u.best_pose.y, 1e-9);
}

// Started 0.15 m and 0.1 rad off, the first scan's match pulls the pose onto the map: the start
// is a prior, not a certainty. (With the matcher off it stays within the motion model's floor.)
TEST(MapStartTest, FirstScanIsMatchedFromARoughStart) {
  SlamConfig config = smallConfig();
  const EvidentialGridMap map = roomMap(config);
  const Pose2 truth(0.3, -0.2, 0.4);
  const Pose2 rough(0.4, -0.1, 0.5);
  SlamEngine engine(config);
  ASSERT_TRUE(engine.startFromMap(map, rough, nullptr));
  const ScanUpdate u = engine.processScan(Pose2(), roomScan(truth, 10.0, true));
  EXPECT_NEAR(u.best_pose.x, truth.x, 0.03);
  EXPECT_NEAR(u.best_pose.y, truth.y, 0.03);
  EXPECT_NEAR(normalizeAngle(u.best_pose.theta - truth.theta), 0.0, 0.02);

  config.matcher.enabled = false;
  config.motion = testing_room::noiselessMotion();
  SlamEngine unmatched(config);
  ASSERT_TRUE(unmatched.startFromMap(map, rough, nullptr));
  const ScanUpdate v = unmatched.processScan(Pose2(), roomScan(truth, 10.0, true));
  EXPECT_EQ(v.best_pose.x, rough.x);
  EXPECT_EQ(v.best_pose.theta, rough.theta);
}

// With the odometry pose at the start pose given, the first scan is at start ⊕ (its odometry
// relative to that one).
TEST(MapStartTest, AnchoredOdometry) {
  SlamConfig config = smallConfig();
  config.matcher.enabled = false;
  config.motion = testing_room::noiselessMotion();
  const EvidentialGridMap map = roomMap(config);
  SlamEngine engine(config);
  const Pose2 start(0.3, -0.2, 0.4);
  const Pose2 odometry_at_start(10.0, 4.0, 1.0);
  const Pose2 moved(0.2, 0.1, 0.05);  // robot frame
  ASSERT_TRUE(engine.startFromMap(map, start, nullptr, &odometry_at_start));
  // Before any scan of its own, a scan's odometry already maps onto the map frame.
  EXPECT_NEAR(engine.bestPose().x, start.x, 1e-12);
  const Pose2 expected = start.compose(moved);
  const ScanUpdate u =
      engine.processScan(odometry_at_start.compose(moved), roomScan(expected, 10.0, true));
  ASSERT_TRUE(u.processed);
  EXPECT_EQ(engine.lastOdometry().x, odometry_at_start.compose(moved).x);
  EXPECT_NEAR(u.best_pose.x, expected.x, 1e-9);
  EXPECT_NEAR(u.best_pose.y, expected.y, 1e-9);
  EXPECT_NEAR(normalizeAngle(u.best_pose.theta - expected.theta), 0.0, 1e-9);
}

// The first scan writes the tiles it touches (copies of the shared ones); the far tile stays
// shared with the given map, and the given map's cells are never changed.
TEST(MapStartTest, TilesAreCopiedOnlyWhenWritten) {
  const SlamConfig config = smallConfig();
  const EvidentialGridMap map = roomMap(config);
  const EvidentialGridMap before = [&] {  // a deep copy of the cells, to compare with
    EvidentialGridMap deep(map.resolution());
    map.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
      EvidentialGridMap::Tile& t = deep.mutableTile(tx, ty);
      t.cells = tile.cells;
    });
    return deep;
  }();
  SlamEngine engine(config);
  const Pose2 start(0.3, -0.2, 0.4);
  ASSERT_TRUE(engine.startFromMap(map, start, nullptr));
  engine.processScan(Pose2(), roomScan(start, 10.0, true));
  const EvidentialGridMap& best = engine.bestMap();
  const int far = 2000 >> EvidentialGridMap::kTileBits;
  EXPECT_EQ(best.tile(far, far), map.tile(far, far));
  const size_t shared = sharedTiles(best, map);
  EXPECT_GE(shared, 1u);
  EXPECT_LT(shared, map.allocatedTiles());  // the room's tiles were written
  EXPECT_TRUE(sameCells(map, before));
  EXPECT_FALSE(sameCells(best, before));
}

// reset() starts over on the given map: the same scan then gives the same result, bit for bit;
// after clearStartMap() it starts on an empty map.
TEST(MapStartTest, ResetReturnsToTheMap) {
  const SlamConfig config = smallConfig();
  const EvidentialGridMap map = roomMap(config);
  SlamEngine engine(config);
  const Pose2 start(0.3, -0.2, 0.4);
  ASSERT_TRUE(engine.startFromMap(map, start, nullptr));
  const ScanUpdate first = engine.processScan(Pose2(), roomScan(start, 10.0, true));
  const Pose2 next = start.compose(Pose2(0.6, 0.0, 0.0));
  engine.processScan(Pose2(0.6, 0.0, 0.0), roomScan(next, 11.0, true));
  EXPECT_EQ(engine.stats().scans_processed, 2u);

  engine.reset();
  EXPECT_EQ(engine.stats().scans_received, 0u);
  EXPECT_TRUE(sameCells(engine.bestMap(), map));
  EXPECT_EQ(sharedTiles(engine.bestMap(), map), map.allocatedTiles());
  EXPECT_EQ(engine.bestPose().x, start.x);
  const ScanUpdate again = engine.processScan(Pose2(), roomScan(start, 10.0, true));
  EXPECT_EQ(again.best_pose.x, first.best_pose.x);
  EXPECT_EQ(again.best_pose.y, first.best_pose.y);
  EXPECT_EQ(again.best_pose.theta, first.best_pose.theta);

  engine.clearStartMap();
  EXPECT_FALSE(engine.hasStartMap());
  engine.reset();
  EXPECT_EQ(engine.bestMap().allocatedTiles(), 0u);
  const ScanUpdate fresh = engine.processScan(Pose2(5.0, 7.0, -2.0), roomScan(start, 12.0, true));
  EXPECT_EQ(fresh.best_pose.x, 5.0);  // a first scan on an empty map: at its odometry
}

// A map of another resolution, or a pose that is not finite, is refused and changes nothing.
TEST(MapStartTest, RefusesWhatItCannotUse) {
  const SlamConfig config = smallConfig();
  SlamEngine engine(config);
  engine.processScan(Pose2(), roomScan(Pose2(), 1.0));
  std::string why;
  EXPECT_FALSE(engine.startFromMap(EvidentialGridMap(0.1), Pose2(), &why));
  EXPECT_NE(why.find("resolution"), std::string::npos) << why;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(engine.startFromMap(EvidentialGridMap(config.resolution), Pose2(nan, 0, 0), &why));
  EXPECT_NE(why.find("finite"), std::string::npos) << why;
  const Pose2 bad_odometry(0, std::numeric_limits<double>::infinity(), 0);
  EXPECT_FALSE(
      engine.startFromMap(EvidentialGridMap(config.resolution), Pose2(), &why, &bad_odometry));
  EXPECT_FALSE(engine.hasStartMap());
  EXPECT_EQ(engine.stats().scans_processed, 1u);  // the run goes on
}

}  // namespace
}  // namespace evidential_slam
