// Tests of the exploration planner (exploration/planner.h) and the pure-pursuit controller
// (exploration/pure_pursuit.h) on hand-drawn grids and poses: inflation and wall cost by hand,
// the distance transform against brute force, A* around an obstacle and through (or not) unknown
// space, the robot's own disc, narrow gaps, shortcutting; the controller's outputs on simple cases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/exploration/planner.h"
#include "evidential_slam/core/exploration/pure_pursuit.h"
#include "exploration_support.h"

namespace evidential_slam {
namespace exploration {
namespace {

using testing_exploration::blankRaster;
using testing_exploration::fillBox;

CostGrid costGridOf(const LayerRaster& r, const PlannerConfig& config,
                    const Eigen::Vector2d* robot = nullptr) {
  return CostGrid(GridGeometry::of(r), classifyCells(r, CellClassConfig()), config, robot);
}

TEST(CostGrid, InflationAndWallCostByHand) {
  // One obstacle cell (10, 10) in free space, 0.1 m cells. Clearance = (centre distance - half a
  // cell); impassable below robot_radius 0.2; 1 + 4 exp(-10 (clearance - 0.2)) below 0.5.
  LayerRaster r = blankRaster(21, 21, 0.1);
  fillBox(&r, 0, 0, 20, 20, '.');
  fillBox(&r, 10, 10, 10, 10, '#');
  PlannerConfig c;
  c.robot_radius = 0.2;
  c.inflation_radius = 0.5;
  c.cost_scaling_factor = 10.0;
  c.wall_cost = 4.0;
  const CostGrid grid = costGridOf(r, c);
  const GridGeometry& g = grid.geometry();
  EXPECT_FALSE(grid.passable(g.index(10, 10)));
  EXPECT_NEAR(grid.clearance(g.index(12, 10)), 0.15, 1e-6);
  EXPECT_FALSE(grid.passable(g.index(12, 10)));
  EXPECT_NEAR(grid.clearance(g.index(13, 10)), 0.25, 1e-6);
  EXPECT_NEAR(grid.cost(g.index(13, 10)), 1.0 + 4.0 * std::exp(-0.5), 1e-5);
  EXPECT_NEAR(grid.clearance(g.index(12, 12)), (std::sqrt(8.0) - 0.5) * 0.1, 1e-6);
  const double diagonal = (std::sqrt(8.0) - 0.5) * 0.1;
  EXPECT_NEAR(grid.cost(g.index(12, 12)), 1.0 + 4.0 * std::exp(-10.0 * (diagonal - 0.2)), 1e-5);
  EXPECT_NEAR(grid.cost(g.index(15, 10)), 1.0 + 4.0 * std::exp(-2.5), 1e-5);  // clearance 0.45
  EXPECT_EQ(grid.cost(g.index(16, 10)), 1.0f);                                  // 0.55: none
  EXPECT_EQ(grid.cost(g.index(0, 0)), 1.0f);
}

TEST(CostGrid, ClearanceMatchesBruteForce) {
  std::mt19937 rng(7);
  LayerRaster r = blankRaster(37, 23, 0.05);
  fillBox(&r, 0, 0, 36, 22, '.');
  std::uniform_int_distribution<int> col(0, 36), row(0, 22);
  for (int k = 0; k < 12; ++k) {
    const int c = col(rng), w = row(rng);
    fillBox(&r, c, w, c, w, '#');
  }
  const CostGrid grid = costGridOf(r, PlannerConfig());
  const GridGeometry& g = grid.geometry();
  const auto classes = classifyCells(r, CellClassConfig());
  for (int i = 0; i < g.size(); ++i) {
    double nearest = 1e9;
    for (int j = 0; j < g.size(); ++j) {
      if (classes[j] == CellClass::kOccupied) {
        nearest = std::min(nearest, std::hypot(g.col(i) - g.col(j), g.row(i) - g.row(j)));
      }
    }
    ASSERT_NEAR(grid.clearance(i), std::max(0.0, (nearest - 0.5) * 0.05), 1e-5) << "cell " << i;
  }
}

// 4 m x 3 m of free space, 0.1 m cells, split by a wall at col 20 up to row 22: the way from
// the left half to the right half is the 0.7 m gap above it.
LayerRaster wallWithGapAtTheTop() {
  LayerRaster r = blankRaster(40, 30, 0.1);
  fillBox(&r, 0, 0, 39, 29, '.');
  fillBox(&r, 20, 0, 20, 22, '#');
  return r;
}

TEST(Planner, GoesAroundAnObstacle) {
  const LayerRaster r = wallWithGapAtTheTop();
  PlannerConfig c;
  const CostGrid grid = costGridOf(r, c);
  const Eigen::Vector2d start(0.55, 0.55), goal(3.55, 0.55);
  const PlanResult plan = planPath(grid, start, goal);
  ASSERT_TRUE(plan.found) << plan.why;
  ASSERT_GE(plan.path.size(), 3u);
  EXPECT_EQ(plan.path.front(), start);
  EXPECT_EQ(plan.path.back(), goal);
  double top = 0.0;
  for (size_t k = 1; k < plan.path.size(); ++k) {
    EXPECT_LT(segmentCost(grid, plan.path[k - 1], plan.path[k]), CostGrid::kImpassable)
        << "segment " << k << " crosses an impassable cell";
    top = std::max(top, plan.path[k].y());
  }
  // Over the wall's end (y = 2.3) with about the robot's radius to spare (cell centres from
  // y = 2.55 up are far enough), so at least twice the way from (0.55, 0.55) to (2.0, 2.5).
  EXPECT_GT(top, 2.5);
  EXPECT_GT(pathLength(plan.path), 2 * std::hypot(1.45, 1.95));
  // A* and Dijkstra agree on the cost.
  const std::vector<float> reach = costToReach(grid, start);
  EXPECT_NEAR(plan.cost, reach[grid.geometry().indexOf(goal)], 1e-4);
}

TEST(Planner, UnknownSpaceIsPassableOnlyWhenAllowed) {
  // Free halves separated by a band of never-observed cells.
  LayerRaster r = blankRaster(40, 20, 0.1);
  fillBox(&r, 0, 0, 17, 19, '.');
  fillBox(&r, 23, 0, 39, 19, '.');
  const Eigen::Vector2d start(0.55, 1.05), goal(3.55, 1.05);
  PlannerConfig c;
  c.unknown_passable = false;
  PlanResult plan = planPath(costGridOf(r, c), start, goal);
  EXPECT_FALSE(plan.found);
  EXPECT_NE(plan.why.find("unknown space"), std::string::npos) << plan.why;
  EXPECT_EQ(costToReach(costGridOf(r, c), start)[GridGeometry::of(r).indexOf(goal)],
            CostGrid::kImpassable);
  c.unknown_passable = true;
  plan = planPath(costGridOf(r, c), start, goal);
  ASSERT_TRUE(plan.found) << plan.why;
  EXPECT_NEAR(plan.cost, 3.0, 1e-6);  // straight along row 10, no obstacle anywhere
  EXPECT_EQ(plan.path.size(), 2u);    // and shortcut to one segment
}

TEST(Planner, TheRobotsOwnDiscStaysPassable) {
  // Nothing observed (the laser's blind spot): only the robot's disc may be crossed.
  const LayerRaster r = blankRaster(30, 30, 0.1);
  const Eigen::Vector2d robot(1.55, 1.55);
  const CostGrid grid = costGridOf(r, PlannerConfig(), &robot);  // radius 0.25
  const GridGeometry& g = grid.geometry();
  EXPECT_TRUE(grid.passable(g.index(15, 15)));
  EXPECT_TRUE(grid.passable(g.index(17, 15)));  // 0.2 m away
  EXPECT_FALSE(grid.passable(g.index(19, 15)));  // 0.4 m away
  EXPECT_TRUE(planPath(grid, robot, {1.75, 1.55}).found);
  EXPECT_FALSE(planPath(grid, robot, {1.95, 1.55}).found);
  EXPECT_FALSE(planPath(costGridOf(r, PlannerConfig()), robot, {1.75, 1.55}).found);
}

TEST(Planner, NarrowGapsStopWideRobots) {
  // A wall across the grid with a 0.4 m gap (cols 18..21).
  LayerRaster r = blankRaster(40, 30, 0.1);
  fillBox(&r, 0, 0, 39, 29, '.');
  fillBox(&r, 0, 15, 39, 15, '#');
  fillBox(&r, 18, 15, 21, 15, '.');
  const Eigen::Vector2d start(1.95, 0.55), goal(1.95, 2.55);
  PlannerConfig c;
  c.robot_radius = 0.25;
  c.inflation_radius = 0.25;
  EXPECT_FALSE(planPath(costGridOf(r, c), start, goal).found);
  c.robot_radius = 0.1;  // gap cells' clearance: 0.15 at cols 19, 20
  c.inflation_radius = 0.1;
  const PlanResult plan = planPath(costGridOf(r, c), start, goal);
  ASSERT_TRUE(plan.found) << plan.why;
  EXPECT_NEAR(plan.cost, 2.0, 1e-6);  // straight up col 19, through the gap
}

TEST(Planner, ShortcuttingStraightensTheGridPath) {
  LayerRaster r = blankRaster(40, 30, 0.1);
  fillBox(&r, 0, 0, 39, 29, '.');
  const Eigen::Vector2d start(0.55, 0.55), goal(2.55, 1.55);
  PlannerConfig c;
  c.smooth_path = false;
  PlanResult plan = planPath(costGridOf(r, c), start, goal);
  ASSERT_TRUE(plan.found);
  EXPECT_EQ(plan.path.size(), 21u);  // 20 steps: 10 diagonal, 10 straight
  EXPECT_NEAR(plan.cost, 1.0 + 10 * 0.1 * std::sqrt(2.0), 1e-6);
  c.smooth_path = true;
  plan = planPath(costGridOf(r, c), start, goal);
  ASSERT_TRUE(plan.found);
  ASSERT_EQ(plan.path.size(), 2u);
  EXPECT_NEAR(pathLength(plan.path), std::hypot(2.0, 1.0), 1e-12);
}

TEST(Planner, ShortcutsDoNotHugWalls) {
  // With a wall cost, the straight segment along the wall costs more than the path that keeps
  // off it: the shortcut is not taken.
  const LayerRaster r = wallWithGapAtTheTop();
  PlannerConfig c;
  const CostGrid grid = costGridOf(r, c);
  const PlanResult plan = planPath(grid, {0.55, 0.55}, {3.55, 0.55});
  ASSERT_TRUE(plan.found);
  double smoothed = 0.0;
  for (size_t k = 1; k < plan.path.size(); ++k) {
    smoothed += segmentCost(grid, plan.path[k - 1], plan.path[k]);
  }
  EXPECT_LE(smoothed, plan.cost + 1e-6);
}

TEST(Planner, BadInputIsRefusedWithAReason) {
  const LayerRaster r = wallWithGapAtTheTop();
  const CostGrid grid = costGridOf(r, PlannerConfig());
  PlanResult plan = planPath(grid, {-1.0, 0.5}, {1.0, 1.0});
  EXPECT_FALSE(plan.found);
  EXPECT_EQ(plan.why, "start is outside the map");
  plan = planPath(grid, {0.55, 0.55}, {2.05, 0.55});  // on the wall
  EXPECT_FALSE(plan.found);
  EXPECT_EQ(plan.why, "goal cell is impassable");
  std::string why;
  PlannerConfig c;
  c.inflation_radius = 0.1;  // below robot_radius
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_NE(why.find("inflation_radius"), std::string::npos);
}

// --- pure pursuit ---

TEST(PurePursuit, StraightAheadDrivesAtFullSpeed) {
  PursuitConfig c;
  const VelocityCommand cmd = purePursuit(Pose2(0, 0, 0), {{0, 0}, {5, 0}}, c);
  EXPECT_DOUBLE_EQ(cmd.linear, c.max_linear_speed);
  EXPECT_DOUBLE_EQ(cmd.angular, 0.0);
  EXPECT_FALSE(cmd.goal_reached);
}

TEST(PurePursuit, TurnsInPlaceWhenThePathIsBehindOrBeside) {
  PursuitConfig c;  // rotate in place beyond 0.6 rad, 2 rad/s per rad, at most 0.8 rad/s
  VelocityCommand cmd = purePursuit(Pose2(0, 0, 0), {{0, 0}, {0, 3}}, c);  // 90° left
  EXPECT_DOUBLE_EQ(cmd.linear, 0.0);
  EXPECT_DOUBLE_EQ(cmd.angular, 0.8);
  cmd = purePursuit(Pose2(0, 0, 0), {{0, 0}, {-3, -0.001}}, c);  // behind, slightly right
  EXPECT_DOUBLE_EQ(cmd.linear, 0.0);
  EXPECT_DOUBLE_EQ(cmd.angular, -0.8);
  // 0.7 rad off: 2 x 0.7 = 1.4, clamped.
  cmd = purePursuit(Pose2(0, 0, -0.7), {{0, 0}, {5, 0}}, c);
  EXPECT_DOUBLE_EQ(cmd.linear, 0.0);
  EXPECT_DOUBLE_EQ(cmd.angular, 0.8);
  c.max_angular_speed = 2.0;
  cmd = purePursuit(Pose2(0, 0, -0.7), {{0, 0}, {5, 0}}, c);
  EXPECT_NEAR(cmd.angular, 1.4, 1e-12);
}

TEST(PurePursuit, FollowsTheArcThroughTheLookaheadPoint) {
  // The robot at the origin heading 0.3 rad left of a path along x: the lookahead point is
  // (0.5, 0) on the path; in the robot's frame (0.5 cos 0.3, -0.5 sin 0.3), so the arc's
  // curvature is 2 y / d² = -2 sin(0.3) / 0.5.
  PursuitConfig c;
  c.max_angular_speed = 10.0;  // not saturated
  const VelocityCommand cmd = purePursuit(Pose2(0, 0, 0.3), {{0, 0}, {5, 0}}, c);
  EXPECT_DOUBLE_EQ(cmd.linear, 0.4);
  EXPECT_NEAR(cmd.angular, 0.4 * -2.0 * std::sin(0.3) / 0.5, 1e-12);
  // Saturated turn rate: the speed falls to keep the arc.
  c.max_angular_speed = 0.3;
  const VelocityCommand slow = purePursuit(Pose2(0, 0, 0.3), {{0, 0}, {5, 0}}, c);
  EXPECT_NEAR(slow.angular, -0.3, 1e-12);
  EXPECT_NEAR(slow.linear, 0.3 / (2.0 * std::sin(0.3) / 0.5), 1e-12);
}

TEST(PurePursuit, LookaheadPointIsMeasuredFromTheProjection) {
  const std::vector<Eigen::Vector2d> path{{0, 0}, {1, 0}, {1, 2}};
  EXPECT_TRUE(lookaheadPoint(path, {0.5, 0.3}, 0.2).isApprox(Eigen::Vector2d(0.7, 0)));
  EXPECT_TRUE(lookaheadPoint(path, {0.9, -0.1}, 0.6).isApprox(Eigen::Vector2d(1, 0.5)));
  EXPECT_TRUE(lookaheadPoint(path, {0.9, 1.0}, 5.0).isApprox(Eigen::Vector2d(1, 2)));
}

TEST(PurePursuit, SlowsDownNearTheGoalAndStopsWithinTolerance) {
  PursuitConfig c;  // slowdown within 0.6 m, tolerance 0.15 m: speed x (0.25 + 0.75 share)
  VelocityCommand cmd = purePursuit(Pose2(0, 0, 0), {{0, 0}, {0.375, 0}}, c);
  EXPECT_NEAR(cmd.linear, 0.4 * (0.25 + 0.75 * 0.5), 1e-12);
  EXPECT_FALSE(cmd.goal_reached);
  cmd = purePursuit(Pose2(0, 0, 0), {{0, 0}, {0.14, 0}}, c);
  EXPECT_TRUE(cmd.goal_reached);
  EXPECT_EQ(cmd.linear, 0.0);
  EXPECT_EQ(cmd.angular, 0.0);
  cmd = purePursuit(Pose2(0, 0, 0), {}, c);
  EXPECT_EQ(cmd.linear, 0.0);
  EXPECT_FALSE(cmd.goal_reached);
}

}  // namespace
}  // namespace exploration
}  // namespace evidential_slam
