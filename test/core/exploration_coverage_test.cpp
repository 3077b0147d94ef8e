// Tests of the coverage measures (exploration/coverage.h) on a hand-made ground truth: the free
// cells reachable from a start, the share of them a map knows (through the map frame's pose in
// the image), the distance to the nearest obstacle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "evidential_slam/core/exploration/coverage.h"
#include "exploration_support.h"

namespace evidential_slam {
namespace exploration {
namespace {

using testing_exploration::blankRaster;
using testing_exploration::fillBox;

// 10 x 6 cells of 0.1 m, origin (-0.5, -0.3): a wall on col 4 splits a 4 x 6 left part from
// a 5 x 6 right part.
OccupancyImage splitRoom() {
  OccupancyImage truth;
  truth.geometry.resolution = 0.1;
  truth.geometry.origin_x = -0.5;
  truth.geometry.origin_y = -0.3;
  truth.geometry.width = 10;
  truth.geometry.height = 6;
  truth.occupied.assign(60, 0);
  for (int r = 0; r < 6; ++r) truth.occupied[truth.geometry.index(4, r)] = 1;
  return truth;
}

TEST(Coverage, ReachableCellsStopAtWalls) {
  const OccupancyImage truth = splitRoom();
  std::vector<uint8_t> reachable = reachableFreeCells(truth, {-0.45, -0.25});  // cell (0, 0)
  EXPECT_EQ(std::count(reachable.begin(), reachable.end(), 1), 24);
  EXPECT_EQ(reachable[truth.geometry.index(3, 5)], 1);
  EXPECT_EQ(reachable[truth.geometry.index(5, 0)], 0);
  reachable = reachableFreeCells(truth, {0.45, 0.25});  // cell (9, 5)
  EXPECT_EQ(std::count(reachable.begin(), reachable.end(), 1), 30);
  reachable = reachableFreeCells(truth, {-0.05, 0.0});  // on the wall
  EXPECT_EQ(std::count(reachable.begin(), reachable.end(), 1), 0);
}

TEST(Coverage, KnownShareThroughTheMapsPose) {
  const OccupancyImage truth = splitRoom();
  const std::vector<uint8_t> reachable = reachableFreeCells(truth, {-0.45, -0.25});
  // The map's frame sits at (-0.5, -0.3) in the image, turned by 90°: image point (x, y) is map
  // point (y + 0.3, -(x + 0.5)). Its raster covers map x in [0, 0.6), y in [-1, 0): the left
  // part's cells (col c, row r) land on map cell (r, 9 - c) of a 6 x 10 raster with origin
  // (0, -1).
  LayerRaster map = blankRaster(6, 10, 0.1, 0.0, -1.0);
  const Pose2 map_in_truth(-0.5, -0.3, M_PI / 2);
  EXPECT_EQ(knownFraction(truth, reachable, map, map_in_truth), 0.0);
  // Known free: image cols 0..1 (12 of the 24 cells) = map rows 8..9.
  fillBox(&map, 0, 8, 5, 9, '.');
  EXPECT_NEAR(knownFraction(truth, reachable, map, map_in_truth), 0.5, 1e-12);
  // Occupied or uncertain is not known free space; NS below 0.5 and BetP below 0.5 both count.
  fillBox(&map, 0, 9, 5, 9, '#');
  fillBox(&map, 0, 7, 5, 7, '~');
  EXPECT_NEAR(knownFraction(truth, reachable, map, map_in_truth), 0.25, 1e-12);
  EXPECT_EQ(knownFraction(truth, std::vector<uint8_t>(60, 0), map, map_in_truth), 0.0);
}

TEST(Coverage, DistanceToTheNearestObstacle) {
  const OccupancyImage truth = splitRoom();  // the wall spans x in [-0.1, 0.0)
  EXPECT_NEAR(distanceToObstacle(truth, {0.25, 0.0}, 1.0), 0.25, 1e-12);
  EXPECT_NEAR(distanceToObstacle(truth, {-0.35, 0.1}, 1.0), 0.25, 1e-12);
  EXPECT_EQ(distanceToObstacle(truth, {-0.05, 0.1}, 1.0), 0.0);
  EXPECT_EQ(distanceToObstacle(truth, {0.25, 0.0}, 0.2), 0.2);  // capped
  // Beyond the image's end of the wall: to its corner (-0.1, 0.3) or (0, 0.3).
  EXPECT_NEAR(distanceToObstacle(truth, {0.3, 0.7}, 1.0), 0.5, 1e-12);
}

TEST(Coverage, ThetaGapBandLeavesOutTheCellsNextToWalls) {
  // The defaults: 3 sigma of 0.025 m in front of a hit, on 0.05 m cells: 0.075 + 0.05.
  EXPECT_NEAR(thetaGapBand(3.0, 0.025, 0.05), 0.125, 1e-12);
  const OccupancyImage truth = splitRoom();  // the wall spans x in [-0.1, 0.0)
  const std::vector<uint8_t> reachable = reachableFreeCells(truth, {0.45, 0.25});
  // The right part's cols 5..9 have centres 0.05, 0.15, ... m from the wall's face.
  std::vector<uint8_t> beyond = cellsBeyondBand(truth, reachable, 0.125);
  EXPECT_EQ(std::count(beyond.begin(), beyond.end(), 1), 24);  // col 5 left out
  EXPECT_EQ(beyond[truth.geometry.index(5, 2)], 0);
  EXPECT_EQ(beyond[truth.geometry.index(6, 2)], 1);
  beyond = cellsBeyondBand(truth, reachable, 0.2);
  EXPECT_EQ(std::count(beyond.begin(), beyond.end(), 1), 18);  // cols 5 and 6 left out
  beyond = cellsBeyondBand(truth, reachable, 0.0);
  EXPECT_EQ(beyond, reachable);
}

}  // namespace
}  // namespace exploration
}  // namespace evidential_slam
