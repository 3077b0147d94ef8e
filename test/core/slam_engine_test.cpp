// Tests of the SLAM entry point (slam_engine.h): the motion gate (0.5 m or 10°, algorithm.md §5),
// rejection of unusable scans, trajectory bookkeeping, reset, and a smoke test in a simulated room.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "evidential_slam/core/slam_engine.h"
#include "test_support.h"

namespace evidential_slam {
namespace {

using testing_room::roomScan;

SlamConfig smallConfig() {
  SlamConfig c = testing_room::withoutRealRobotSettings(SlamConfig());
  c.particles = 4;
  c.threads = 1;
  return c;
}

// Gate: the first scan is processed; then a scan is processed only once the odometry moved
// >= 0.5 m or turned >= 10° since the last processed one: x = 0.1, 0.3 (no), 0.55 (yes: 0.55 m),
// 0.6 with a 0.2 rad turn (yes: 0.2 > 0.1745 rad although only 0.05 m).
TEST(SlamEngineTest, MotionGate) {
  SlamEngine engine(smallConfig());
  const std::vector<Pose2> odom = {Pose2(0, 0, 0), Pose2(0.1, 0, 0), Pose2(0.3, 0, 0),
                                   Pose2(0.55, 0, 0), Pose2(0.6, 0, 0.2)};
  const std::vector<bool> expected = {true, false, false, true, true};
  for (size_t i = 0; i < odom.size(); ++i) {
    const ScanUpdate u = engine.processScan(odom[i], roomScan(odom[i], 1.0 + i));
    EXPECT_EQ(u.processed, expected[i]) << "scan " << i;
    EXPECT_FALSE(u.rejected) << "scan " << i << ": " << u.why;
  }
  EXPECT_EQ(engine.stats().scans_received, 5u);
  EXPECT_EQ(engine.stats().scans_processed, 3u);
  EXPECT_EQ(engine.stats().scans_rejected, 0u);

  // One trajectory pose per scan received, with its stamp.
  const auto traj = engine.bestTrajectory();
  ASSERT_EQ(traj.size(), 5u);
  for (size_t i = 0; i < traj.size(); ++i) EXPECT_DOUBLE_EQ(traj[i].stamp, 1.0 + i);

  // REP-105: map_T_odom ⊕ odom_T_base = map_T_base (the best pose at the latest scan).
  const Pose2 via_odom = engine.mapToOdom().compose(odom.back());
  const Pose2 best = engine.bestPose();
  EXPECT_NEAR(via_odom.x, best.x, 1e-9);
  EXPECT_NEAR(via_odom.y, best.y, 1e-9);
  EXPECT_NEAR(normalizeAngle(via_odom.theta - best.theta), 0.0, 1e-9);
}

// Unusable scans are rejected with a reason and counted; they do not initialise the filter.
TEST(SlamEngineTest, RejectsUnusableScans) {
  SlamEngine engine(smallConfig());
  LaserScan bad_sizes = roomScan(Pose2(), 1.0);
  bad_sizes.bearings.pop_back();
  ScanUpdate u = engine.processScan(Pose2(), bad_sizes);
  EXPECT_TRUE(u.rejected);
  EXPECT_FALSE(u.processed);
  EXPECT_FALSE(u.why.empty());

  LaserScan all_nan = roomScan(Pose2(), 2.0);
  for (float& r : all_nan.ranges) r = std::numeric_limits<float>::quiet_NaN();
  u = engine.processScan(Pose2(), all_nan);
  EXPECT_TRUE(u.rejected);
  EXPECT_FALSE(u.why.empty());
  EXPECT_EQ(engine.stats().scans_rejected, 2u);
  EXPECT_EQ(engine.stats().scans_processed, 0u);
  EXPECT_EQ(engine.stats().rays_bad, 360u);

  // A good scan afterwards is the first processed one.
  u = engine.processScan(Pose2(), roomScan(Pose2(), 3.0));
  EXPECT_TRUE(u.processed);
  EXPECT_FALSE(u.rejected);
}

// reset() forgets everything: counters, trajectory, and the next scan is processed as a first one.
TEST(SlamEngineTest, Reset) {
  SlamEngine engine(smallConfig());
  engine.processScan(Pose2(), roomScan(Pose2(), 1.0));
  engine.processScan(Pose2(0.6, 0, 0), roomScan(Pose2(0.6, 0, 0), 2.0));
  EXPECT_EQ(engine.stats().scans_processed, 2u);
  engine.reset();
  EXPECT_EQ(engine.stats().scans_received, 0u);
  EXPECT_EQ(engine.stats().scans_processed, 0u);
  EXPECT_TRUE(engine.bestTrajectory().empty());
  const ScanUpdate u = engine.processScan(Pose2(0.6, 0, 0), roomScan(Pose2(0.6, 0, 0), 3.0));
  EXPECT_TRUE(u.processed);
}

// Smoke test: exact odometry across the room in 0.5 m steps; the best pose stays on the truth
// (within 0.15 m / 0.05 rad), the map marks the wall cell ahead as occupied and the room centre
// as free.
// Poses between processed scans: the odometry over-reports travel by 20 % (true x = 0, 0.2, 0.4,
// 0.6, 0.8 at t = 1..5; odometry x = 1.2·x). Scans at 0 and 0.72 (odometry) pass the gate and the
// matcher puts the latter back near x = 0.6. Dead reckoning from x = 0 would put the scans in
// between at 0.24 and 0.48 (4 and 8 cm off); with the segment's drift (-0.12 m at t = 4) spread
// over it in proportion to time they land at 0.24 - 0.04 = 0.20 and 0.48 - 0.08 = 0.40.
TEST(SlamEngineTest, TrajectorySpreadsOdometryDriftBetweenProcessedScans) {
  SlamConfig c = smallConfig();
  c.particles = 1;
  c.motion = testing_room::noiselessMotion();
  SlamEngine engine(c);
  const std::vector<double> truth_x = {0.0, 0.2, 0.4, 0.6, 0.8};
  for (size_t i = 0; i < truth_x.size(); ++i) {
    const Pose2 truth(truth_x[i] - 0.3, 0.1, 0.0);  // off the room's centre and cell borders
    const Pose2 odometry(1.2 * truth_x[i] - 0.3, 0.1, 0.0);
    engine.processScan(odometry, roomScan(truth, 1.0 + i));
  }
  ASSERT_EQ(engine.stats().scans_processed, 2u);  // odometry x = 0 and 0.72 pass the gate
  const std::vector<StampedPose> path = engine.bestTrajectory();
  ASSERT_EQ(path.size(), truth_x.size());
  EXPECT_NEAR(path[3].pose.x, 0.6 - 0.3, 0.025);  // processed, corrected by the matcher
  EXPECT_NEAR(path[1].pose.x, 0.2 - 0.3, 0.025);  // dead reckoning alone: 0.04 off
  EXPECT_NEAR(path[2].pose.x, 0.4 - 0.3, 0.025);  // dead reckoning alone: 0.08 off
}

// reconfigure(): the motion gate changes for the next scan; particles and maps are kept; the
// start-up parameters keep their values; an invalid configuration changes nothing.
TEST(SlamEngineTest, ReconfigureWhileRunning) {
  SlamEngine engine(smallConfig());
  EXPECT_TRUE(engine.processScan(Pose2(), roomScan(Pose2(), 1.0)).processed);
  EXPECT_FALSE(engine.processScan(Pose2(0.3, 0, 0), roomScan(Pose2(0.3, 0, 0), 2.0)).processed);

  SlamConfig changed = engine.config();
  changed.update_min_distance = 0.2;
  changed.particles = 50;    // start-up only: ignored
  changed.resolution = 0.1;  // start-up only: ignored
  changed.sensor.random_weight = 0.3;
  std::string why;
  ASSERT_TRUE(engine.reconfigure(changed, &why)) << why;
  EXPECT_EQ(engine.config().particles, 4);
  EXPECT_DOUBLE_EQ(engine.config().resolution, 0.05);
  EXPECT_DOUBLE_EQ(engine.config().update_min_distance, 0.2);
  EXPECT_DOUBLE_EQ(engine.filter().config().sensor.random_weight, 0.3);
  EXPECT_EQ(engine.filter().particles().size(), 4u);
  EXPECT_TRUE(engine.processScan(Pose2(0.35, 0, 0), roomScan(Pose2(0.35, 0, 0), 3.0)).processed);
  EXPECT_EQ(engine.stats().scans_processed, 2u);  // the history was kept

  SlamConfig invalid = engine.config();
  invalid.sensor.random_weight = 1.5;
  why.clear();
  EXPECT_FALSE(engine.reconfigure(invalid, &why));
  EXPECT_FALSE(why.empty());
  EXPECT_DOUBLE_EQ(engine.config().sensor.random_weight, 0.3);
}

// Particle poses at the latest scan carry the odometry since the last processed scan; weights are
// normalised. Before any scan the estimate is the odometry with zero covariance. With exact
// odometry and the zero-noise motion model every particle sits on the truth: mean = truth.
TEST(SlamEngineTest, ParticlePosesAndEstimate) {
  SlamConfig config = smallConfig();
  config.motion = testing_room::noiselessMotion();
  SlamEngine engine(config);
  PoseEstimate e = engine.poseEstimate();
  EXPECT_DOUBLE_EQ(e.mean.x, 0.0);
  EXPECT_DOUBLE_EQ(e.covariance.norm(), 0.0);

  engine.processScan(Pose2(), roomScan(Pose2(), 1.0));
  engine.processScan(Pose2(0.2, 0.0, 0.0), roomScan(Pose2(0.2, 0.0, 0.0), 2.0));  // gated
  std::vector<Pose2> poses;
  std::vector<double> weights;
  engine.particlePoses(&poses, &weights);
  ASSERT_EQ(poses.size(), 4u);
  double total = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(poses[i].x, 0.2, 1e-6) << i;
    EXPECT_NEAR(poses[i].y, 0.0, 1e-6) << i;
    total += weights[i];
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
  e = engine.poseEstimate();
  EXPECT_NEAR(e.mean.x, 0.2, 1e-6);
  EXPECT_NEAR(e.covariance(0, 0), 0.0, 1e-9);
}

TEST(SlamEngineTest, RoomSmokeTest) {
  SlamEngine engine(smallConfig());
  for (int i = 0; i <= 6; ++i) {
    const Pose2 truth(-1.5 + 0.5 * i, 0.1, 0.0);
    const ScanUpdate u = engine.processScan(truth, roomScan(truth, 1.0 + i));
    EXPECT_TRUE(u.processed) << "scan " << i;
    EXPECT_NEAR(u.best_pose.x, truth.x, 0.15) << "scan " << i;
    EXPECT_NEAR(u.best_pose.y, truth.y, 0.15) << "scan " << i;
    EXPECT_NEAR(normalizeAngle(u.best_pose.theta - truth.theta), 0.0, 0.05) << "scan " << i;
  }
  const EvidentialGridMap& map = engine.bestMap();
  // Wall x = 2 at y = 0.1: the hit points lie on the boundary between cells 39 and 40.
  const CellIndex wall = map.worldToCell(1.99, 0.125);
  const CellIndex wall2 = map.worldToCell(2.01, 0.125);
  EXPECT_GT(std::max(map.cell(wall).occupied(), map.cell(wall2).occupied()), 0.5f);
  const CellIndex centre = map.worldToCell(0.0, 0.6);
  EXPECT_GT(map.cell(centre).free(), 0.9f);
  EXPECT_LT(map.cell(centre).occupied(), 0.05f);
}

}  // namespace
}  // namespace evidential_slam
