// Tests of the exploration loop (exploration/explorer.h) on hand-drawn rasters: termination when
// no frontier is left, driving to the frontier, the two strategies' choices, goals blacklisted
// when reached and after no progress, unreachable frontiers reported, revisit goals, bad config.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "evidential_slam/core/exploration/explorer.h"
#include "exploration_support.h"

namespace evidential_slam {
namespace exploration {
namespace {

using testing_exploration::blankRaster;
using testing_exploration::fillBox;
using testing_exploration::hallWithPocketAndDoor;

std::shared_ptr<const LayerRaster> share(LayerRaster r) {
  return std::make_shared<const LayerRaster>(std::move(r));
}

// A closed 3 m x 2 m room, all of it seen free.
LayerRaster closedRoom() {
  LayerRaster r = blankRaster(32, 22, 0.1);
  fillBox(&r, 0, 0, 31, 21, '#');
  fillBox(&r, 1, 1, 30, 20, '.');
  return r;
}

// A corridor along x (walls on rows 0 and 20, free cols 10..50 between), never observed at
// both ends: frontiers on cols 10 and 50, goals at their middle cells (1.05, 1.05) and
// (5.05, 1.05).
LayerRaster corridorOpenAtBothEnds() {
  LayerRaster r = blankRaster(61, 21, 0.1);
  fillBox(&r, 0, 0, 60, 0, '#');
  fillBox(&r, 0, 20, 60, 20, '#');
  fillBox(&r, 10, 1, 50, 19, '.');
  return r;
}

TEST(Explorer, StopsWhenNoFrontierIsLeft) {
  Explorer explorer{ExplorerConfig()};
  const VelocityCommand cmd = explorer.update(0.0, Pose2(1.5, 1.0, 0.0), share(closedRoom()));
  EXPECT_TRUE(explorer.done());
  EXPECT_EQ(explorer.stopReason(), StopReason::kNoFrontier);
  EXPECT_EQ(explorer.stopMessage(), "done: no frontier left");
  EXPECT_EQ(cmd.linear, 0.0);
  EXPECT_EQ(cmd.angular, 0.0);
  EXPECT_FALSE(explorer.hasGoal());
  EXPECT_FALSE(explorer.wantsMap(10.0));
}

TEST(Explorer, WaitsForAMap) {
  Explorer explorer{ExplorerConfig()};
  VelocityCommand cmd = explorer.update(0.0, Pose2());
  EXPECT_EQ(cmd.linear, 0.0);
  EXPECT_FALSE(explorer.done());
  EXPECT_TRUE(explorer.wantsMap(0.0));
  // Nothing observed yet (an empty grid's raster, or one of vacuous cells): still waiting, not
  // "no frontier left".
  cmd = explorer.update(0.1, Pose2(), share(blankRaster(0, 0, 0.05)));
  EXPECT_FALSE(explorer.done());
  cmd = explorer.update(0.2, Pose2(), share(blankRaster(20, 20, 0.05)));
  EXPECT_FALSE(explorer.done());
  EXPECT_EQ(cmd.linear, 0.0);
  EXPECT_TRUE(explorer.wantsMap(0.3));
  EXPECT_EQ(explorer.stats().replans, 0u);
}

TEST(Explorer, AMapWithANonFiniteValueStopsTheRobotUntilAGoodMapComes) {
  Explorer explorer{ExplorerConfig()};
  const auto good = share(corridorOpenAtBothEnds());
  const Pose2 pose(2.05, 1.05, M_PI);
  VelocityCommand cmd = explorer.update(0.0, pose, good);
  EXPECT_GT(cmd.linear, 0.0);
  EXPECT_TRUE(explorer.fault().empty());
  for (const Layer layer : {Layer::kPignistic, Layer::kNonspecificity, Layer::kEntropy}) {
    LayerRaster bad = corridorOpenAtBothEnds();
    bad.values[static_cast<int>(layer)][5 * 61 + 20] = std::nanf("");
    cmd = explorer.update(0.1, pose, share(bad));
    EXPECT_EQ(cmd.linear, 0.0);
    EXPECT_EQ(cmd.angular, 0.0);
    EXPECT_FALSE(explorer.done());
    EXPECT_FALSE(explorer.hasGoal());
    EXPECT_NE(explorer.fault().find("map refused"), std::string::npos) << explorer.fault();
    EXPECT_NE(explorer.fault().find("cell 325"), std::string::npos) << explorer.fault();
    // The last good map is not driven on either, until a good one comes.
    cmd = explorer.update(2.0, pose);
    EXPECT_EQ(cmd.linear, 0.0);
    EXPECT_FALSE(explorer.fault().empty());
    cmd = explorer.update(2.1, pose, good);
    EXPECT_GT(cmd.linear, 0.0);
    EXPECT_TRUE(explorer.fault().empty());
  }
  // An infinite EC is a long-contradicted cell, not a broken map.
  LayerRaster conflict = corridorOpenAtBothEnds();
  conflict.values[static_cast<int>(Layer::kExternalConflict)][325] = INFINITY;
  cmd = explorer.update(3.0, pose, share(conflict));
  EXPECT_TRUE(explorer.fault().empty()) << explorer.fault();
  EXPECT_GT(cmd.linear, 0.0);
}

TEST(Explorer, ANonFinitePoseStopsTheRobot) {
  Explorer explorer{ExplorerConfig()};
  const auto map = share(corridorOpenAtBothEnds());
  EXPECT_GT(explorer.update(0.0, Pose2(2.05, 1.05, M_PI), map).linear, 0.0);
  const VelocityCommand cmd = explorer.update(0.1, Pose2(NAN, 1.05, M_PI));
  EXPECT_EQ(cmd.linear, 0.0);
  EXPECT_EQ(cmd.angular, 0.0);
  EXPECT_EQ(explorer.fault(), "the pose or the time is not finite");
  EXPECT_EQ(explorer.update(NAN, Pose2(2.0, 1.05, M_PI)).linear, 0.0);
  EXPECT_GT(explorer.update(0.3, Pose2(2.0, 1.05, M_PI)).linear, 0.0);
  EXPECT_TRUE(explorer.fault().empty());
  EXPECT_FALSE(explorer.done());
}

TEST(Explorer, DrivesToTheNearerFrontierAndReplansAtItsRate) {
  Explorer explorer{ExplorerConfig()};  // strategy ns, 1 Hz
  const auto map = share(corridorOpenAtBothEnds());
  const VelocityCommand cmd = explorer.update(0.0, Pose2(2.05, 1.05, M_PI), map);
  ASSERT_TRUE(explorer.hasGoal());
  EXPECT_TRUE(explorer.goal().goal.isApprox(Eigen::Vector2d(1.05, 1.05)));
  EXPECT_EQ(explorer.frontiers().size(), 2u);
  // Facing the goal down a straight, obstacle-free path: full speed, no turn.
  EXPECT_DOUBLE_EQ(cmd.linear, explorer.config().pursuit.max_linear_speed);
  EXPECT_NEAR(cmd.angular, 0.0, 1e-9);
  EXPECT_EQ(explorer.stats().replans, 1u);
  EXPECT_FALSE(explorer.wantsMap(0.5));
  explorer.update(0.5, Pose2(2.0, 1.05, M_PI));
  EXPECT_EQ(explorer.stats().replans, 1u);
  EXPECT_TRUE(explorer.wantsMap(1.0));
  explorer.update(1.0, Pose2(1.8, 1.05, M_PI));
  EXPECT_EQ(explorer.stats().replans, 2u);
  EXPECT_EQ(explorer.stats().goals_chosen, 1u);  // the same goal kept
}

TEST(Explorer, TheStrategiesChooseDifferentFrontiers) {
  // Frontiers.HallPocketAndDoorClustersAndScoresByHand: explore_lite's cost prefers the long
  // frontier onto the closed pocket, ours the door onto the unknown room.
  const auto map = share(hallWithPocketAndDoor());
  const Pose2 robot(1.55, 2.05, 0.0);
  ExplorerConfig config;
  Explorer ns(config);
  ns.update(0.0, robot, map);
  ASSERT_TRUE(ns.hasGoal());
  EXPECT_TRUE(ns.goal().goal.isApprox(Eigen::Vector2d(1.55, 3.95))) << ns.goal().goal.transpose();
  config.frontiers.strategy = "frontier";
  Explorer baseline(config);
  baseline.update(0.0, robot, map);
  ASSERT_TRUE(baseline.hasGoal());
  EXPECT_TRUE(baseline.goal().goal.isApprox(Eigen::Vector2d(2.95, 2.05)))
      << baseline.goal().goal.transpose();
}

TEST(Explorer, ReachedGoalsAreBlacklistedAndTheNextOneTaken) {
  Explorer explorer{ExplorerConfig()};
  const auto map = share(corridorOpenAtBothEnds());
  explorer.update(0.0, Pose2(2.05, 1.05, 0.0), map);
  ASSERT_TRUE(explorer.goal().goal.isApprox(Eigen::Vector2d(1.05, 1.05)));
  // At the goal, but the frontier did not clear (the map did not change).
  const VelocityCommand cmd = explorer.update(0.1, Pose2(1.1, 1.05, 0.0));
  EXPECT_EQ(explorer.stats().goals_reached, 1u);
  ASSERT_EQ(explorer.blacklist().size(), 1u);
  EXPECT_EQ(explorer.blacklist()[0].why, "reached");
  EXPECT_TRUE(explorer.isBlacklisted({1.05, 1.05}));
  ASSERT_TRUE(explorer.hasGoal());
  EXPECT_TRUE(explorer.goal().goal.isApprox(Eigen::Vector2d(5.05, 1.05)));
  EXPECT_GT(cmd.linear, 0.0);  // facing it already
  EXPECT_FALSE(cmd.goal_reached);
  // There too: then nothing is left to go to.
  explorer.update(0.2, Pose2(5.0, 1.05, 0.0));
  EXPECT_TRUE(explorer.done());
  EXPECT_EQ(explorer.stopReason(), StopReason::kNoReachableGoal);
  EXPECT_EQ(explorer.stopMessage(),
            "done: 2 frontier(s) and 0 revisit cluster(s) left, none to go to (0 unreachable, 2 "
            "blacklisted)");
}

TEST(Explorer, GoalsWithoutProgressAreBlacklistedAfterTheTimeout) {
  ExplorerConfig config;
  config.progress_timeout = 5.0;
  Explorer explorer(config);
  const auto map = share(corridorOpenAtBothEnds());
  const Pose2 stuck(2.05, 1.05, 0.0);  // never moves; the map never changes
  double t = 0.0;  // steps of 1/8 s: exact replanning times
  explorer.update(t, stuck, map);
  ASSERT_TRUE(explorer.goal().goal.isApprox(Eigen::Vector2d(1.05, 1.05)));
  for (int k = 1; k <= 47; ++k) explorer.update(t = k / 8.0, stuck);
  EXPECT_TRUE(explorer.blacklist().empty());  // the replanning at 5 s: 5 s without progress
  for (int k = 48; k <= 49; ++k) explorer.update(t = k / 8.0, stuck);
  ASSERT_EQ(explorer.blacklist().size(), 1u);
  EXPECT_EQ(explorer.blacklist()[0].why, "no progress for 6 s");
  EXPECT_EQ(explorer.blacklist()[0].time, 6.0);
  EXPECT_EQ(explorer.stats().goals_no_progress, 1u);
  ASSERT_TRUE(explorer.hasGoal());
  EXPECT_TRUE(explorer.goal().goal.isApprox(Eigen::Vector2d(5.05, 1.05)));
  for (int k = 50; k <= 100 && !explorer.done(); ++k) explorer.update(t = k / 8.0, stuck);
  EXPECT_TRUE(explorer.done());
  EXPECT_EQ(t, 12.0);
  EXPECT_EQ(explorer.stats().goals_no_progress, 2u);
}

TEST(Explorer, ARecedingFrontierCountsAsProgress) {
  // The robot does not get closer, but each map shows the frontier further away (the corridor
  // being revealed): the goal is not given up.
  ExplorerConfig config;
  config.progress_timeout = 2.0;
  Explorer explorer(config);
  const Pose2 robot(3.05, 1.05, 0.0);
  for (int k = 0; k <= 8; ++k) {
    LayerRaster r = blankRaster(81, 21, 0.1);
    fillBox(&r, 0, 0, 80, 0, '#');
    fillBox(&r, 0, 20, 80, 20, '#');
    fillBox(&r, 0, 1, 0, 19, '#');
    fillBox(&r, 1, 1, 40 + 3 * k, 19, '.');  // the frontier recedes by 0.3 m a second
    explorer.update(k * 1.0, robot, share(std::move(r)));
  }
  EXPECT_TRUE(explorer.blacklist().empty());
  EXPECT_TRUE(explorer.hasGoal());
  EXPECT_EQ(explorer.stats().goals_chosen, 1u);
  EXPECT_TRUE(explorer.goal().goal.isApprox(Eigen::Vector2d(6.45, 1.05)));
}

TEST(Explorer, UnreachableFrontiersAreReportedWhenNothingElseIsLeft) {
  // The only frontier lies beyond a 0.2 m gap in the room's top wall: a strip of free space
  // seen through it, never observed beyond.
  LayerRaster r = blankRaster(32, 30, 0.1);
  fillBox(&r, 0, 0, 31, 21, '#');
  fillBox(&r, 1, 1, 30, 20, '.');
  fillBox(&r, 15, 21, 16, 21, '.');
  fillBox(&r, 10, 22, 21, 23, '.');
  Explorer explorer{ExplorerConfig()};
  explorer.update(0.0, Pose2(1.5, 1.0, 0.0), share(std::move(r)));
  EXPECT_TRUE(explorer.done());
  EXPECT_EQ(explorer.stopReason(), StopReason::kNoReachableGoal);
  EXPECT_EQ(explorer.stopMessage(),
            "done: 1 frontier(s) and 0 revisit cluster(s) left, none to go to (1 unreachable, 0 "
            "blacklisted)");
}

TEST(Explorer, RevisitsConflictWhenAskedTo) {
  LayerRaster r = closedRoom();
  fillBox(&r, 20, 10, 22, 12, 'x');  // 9 cells of 2 bits of external conflict
  const auto map = share(std::move(r));
  Explorer off{ExplorerConfig()};
  off.update(0.0, Pose2(0.55, 1.05, 0.0), map);
  EXPECT_TRUE(off.done());
  ExplorerConfig config;
  config.frontiers.revisit_conflict = true;
  Explorer on(config);
  on.update(0.0, Pose2(0.55, 1.05, 0.0), map);
  ASSERT_FALSE(on.done());
  ASSERT_TRUE(on.hasGoal());
  EXPECT_TRUE(on.goal().revisit);
  EXPECT_NEAR((on.goal().goal - Eigen::Vector2d(2.15, 1.15)).norm(), 1.0, 0.05);
  // Visited once: done.
  const Eigen::Vector2d there = on.goal().goal;
  on.update(0.1, Pose2(there.x(), there.y(), 0.0));
  EXPECT_TRUE(on.done());
  EXPECT_EQ(on.stopReason(), StopReason::kNoReachableGoal);
}

TEST(Explorer, BadConfigIsRejectedWithAReason) {
  std::string why;
  ExplorerConfig c;
  EXPECT_TRUE(c.isValid(&why)) << why;
  c.planner_frequency = 0.0;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "planner_frequency must be in [0.01, 100] Hz");
  c = ExplorerConfig();
  c.pursuit.lookahead = -1.0;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "lookahead must be in [0.01, 10] m");
  c = ExplorerConfig();
  c.planner.robot_radius = std::nan("");
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "robot_radius must be in [0, 10] m");
}

}  // namespace
}  // namespace exploration
}  // namespace evidential_slam
