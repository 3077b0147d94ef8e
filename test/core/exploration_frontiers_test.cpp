// Tests of the exploration goals (exploration/cell_classes.h, exploration/frontiers.h) on
// hand-drawn rasters: cell classes at their thresholds, frontier clusters and their sizes,
// centroids and distances, the visible non-specificity against areas computed by hand, both
// strategies' scores, the two strategies choosing differently where they should, revisit goals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/exploration/frontiers.h"
#include "evidential_slam/core/exploration/planner.h"
#include "exploration_support.h"

namespace evidential_slam {
namespace exploration {
namespace {

using testing_exploration::blankRaster;
using testing_exploration::drawRaster;
using testing_exploration::fillBox;
using testing_exploration::hallWithPocketAndDoor;

TEST(CellClasses, ThresholdsDecideInOrderOccupiedUnknownFree) {
  const CellClassConfig c;  // occupied 0.65, free 0.35 with NS <= 0.5, unknown NS >= 0.9
  EXPECT_EQ(classifyCell(0.65, 0.1, c), CellClass::kOccupied);
  EXPECT_EQ(classifyCell(0.65, 0.95, c), CellClass::kOccupied);  // occupied wins
  EXPECT_EQ(classifyCell(0.5, 1.0, c), CellClass::kUnknown);     // never observed
  EXPECT_EQ(classifyCell(0.3, 0.9, c), CellClass::kUnknown);
  EXPECT_EQ(classifyCell(0.35, 0.5, c), CellClass::kFree);
  EXPECT_EQ(classifyCell(0.1, 0.2, c), CellClass::kFree);  // one free pass (r = 0.2)
  EXPECT_EQ(classifyCell(0.36, 0.2, c), CellClass::kUncertain);
  EXPECT_EQ(classifyCell(0.2, 0.6, c), CellClass::kUncertain);  // the Θ gap before a hit
  EXPECT_EQ(classifyCell(0.64, 0.0, c), CellClass::kUncertain);
}

TEST(CellClasses, BadThresholdsAreRejected) {
  std::string why;
  CellClassConfig c;
  EXPECT_TRUE(c.isValid(&why)) << why;
  c.unknown_ns = 0.4;  // below free_ns
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_NE(why.find("unknown_ns"), std::string::npos);
  c = CellClassConfig();
  c.occupied_betp = 0.5;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_NE(why.find("occupied_betp"), std::string::npos);
}

TEST(Frontiers, FreeCellsBesideUnknownClusteredEightConnected) {
  // 0.1 m cells. Frontier cells (F): free cells with a 4-neighbour never observed.
  //   row 5  ##########
  //   row 4  #........#
  //   row 3  #.......F?      cluster A: (8,3) (8,2) and (7,1) (diagonal to (8,2))
  //   row 2  #.......F?
  //   row 1  #.F....F.#      cluster B: (2,1) alone
  //   row 0  ##?####?##
  const LayerRaster r = drawRaster({"##########",  //
                                    "#........#",  //
                                    "#........?",  //
                                    "#........?",  //
                                    "#........#",  //
                                    "##?####?##"},
                                   0.1);
  const GridGeometry g = GridGeometry::of(r);
  const std::vector<CellClass> classes = classifyCells(r, CellClassConfig());
  FrontierConfig config;
  config.min_frontier_size = 0.0;
  const Eigen::Vector2d robot(0.15, 0.45);  // cell (1, 4)
  std::vector<Frontier> f = findFrontiers(g, classes, robot, config);
  ASSERT_EQ(f.size(), 2u);
  std::sort(f.begin(), f.end(),
            [](const Frontier& a, const Frontier& b) { return a.cells.size() < b.cells.size(); });
  EXPECT_EQ(f[0].cells, std::vector<int>{g.index(2, 1)});
  EXPECT_EQ(f[1].cells, (std::vector<int>{g.index(7, 1), g.index(8, 2), g.index(8, 3)}));
  EXPECT_NEAR(f[0].size, 0.1, 1e-12);
  EXPECT_NEAR(f[1].size, 0.3, 1e-12);
  // A: centres (0.75, 0.15), (0.85, 0.25), (0.85, 0.35).
  EXPECT_NEAR(f[1].centroid.x(), 2.45 / 3, 1e-12);
  EXPECT_NEAR(f[1].centroid.y(), 0.75 / 3, 1e-12);
  EXPECT_NEAR(f[0].min_distance, std::hypot(0.1, 0.3), 1e-12);  // (0.25, 0.15)
  EXPECT_NEAR(f[1].min_distance, std::hypot(0.6, 0.3), 1e-12);  // (0.75, 0.15)
  // min_frontier_size drops the single cell (0.1 m) but keeps the 0.3 m cluster.
  config.min_frontier_size = 0.2;
  f = findFrontiers(g, classes, robot, config);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].cells.size(), 3u);
}

TEST(Frontiers, UncertainCellsAndTheRasterBorder) {
  // Free cells beside '~' (NS 0.6 < τ) are no frontier; free cells on the raster's border are
  // (beyond it nothing was observed).
  const LayerRaster r = drawRaster({"#####",  //
                                    "#...~",  //
                                    "#...#",  //
                                    "#....",  //
                                    "#####"},
                                   0.1);
  const GridGeometry g = GridGeometry::of(r);
  FrontierConfig config;
  config.min_frontier_size = 0.0;
  const auto f = findFrontiers(g, classifyCells(r, CellClassConfig()), {0.15, 0.15}, config);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].cells, std::vector<int>{g.index(4, 1)});
}

TEST(VisibleNonSpecificity, VacuousDiscIsPiRSquared) {
  // Nothing observed anywhere (an empty raster: all of it lies beyond).
  const LayerRaster empty = blankRaster(0, 0, 0.05);
  const std::vector<CellClass> none;
  EXPECT_NEAR(visibleNonSpecificity(empty, none, {0.3, -1.2}, 2.0, 360), M_PI * 4.0, 1e-9);
  EXPECT_NEAR(visibleNonSpecificity(empty, none, {0.0, 0.0}, 5.0, 64), M_PI * 25.0, 1e-9);
}

TEST(VisibleNonSpecificity, FreeSpaceCountsItsNonSpecificity) {
  // 6 m x 6 m of once-seen free cells (NS 0.2), range 2 m from the centre: 0.2 π 2².
  LayerRaster r = blankRaster(60, 60, 0.1);
  fillBox(&r, 0, 0, 59, 59, '.');
  const auto classes = classifyCells(r, CellClassConfig());
  EXPECT_NEAR(visibleNonSpecificity(r, classes, {3.0, 3.0}, 2.0, 360), 0.2 * M_PI * 4.0, 1e-4);
}

TEST(VisibleNonSpecificity, WallsStopTheRays) {
  // A closed box: walls one cell thick around a 2 m x 2 m free interior, vacuous outside. From
  // its centre only the interior is seen: 0.2 × 4 m² (the rays sample the square in polar
  // steps, so within 3 %), nothing of the vacuous space around it.
  LayerRaster r = blankRaster(60, 60, 0.1);
  fillBox(&r, 19, 19, 40, 40, '#');
  fillBox(&r, 20, 20, 39, 39, '.');
  const auto classes = classifyCells(r, CellClassConfig());
  const double seen = visibleNonSpecificity(r, classes, {3.0, 3.0}, 5.0, 720);
  EXPECT_NEAR(seen, 0.8, 0.03 * 0.8);
  // A door (1 m gap in the top wall) opens the view onto vacuous space.
  fillBox(&r, 25, 40, 34, 40, '.');
  EXPECT_GT(visibleNonSpecificity(r, classifyCells(r, CellClassConfig()), {3.0, 3.0}, 5.0, 720),
            seen + 1.0);
}

TEST(Frontiers, HallPocketAndDoorClustersAndScoresByHand) {
  const LayerRaster r = hallWithPocketAndDoor();
  const GridGeometry g = GridGeometry::of(r);
  const auto classes = classifyCells(r, CellClassConfig());
  const Eigen::Vector2d robot(1.55, 2.05);
  FrontierConfig config;  // min_frontier_size 0.5 m
  std::vector<Frontier> f = findFrontiers(g, classes, robot, config);
  ASSERT_EQ(f.size(), 2u);
  std::sort(f.begin(), f.end(),
            [](const Frontier& a, const Frontier& b) { return a.cells.size() > b.cells.size(); });
  Frontier& pocket = f[0];
  Frontier& door = f[1];
  ASSERT_EQ(pocket.cells.size(), 31u);  // col 29, rows 5..35
  ASSERT_EQ(door.cells.size(), 11u);    // row 39, cols 10..20
  EXPECT_NEAR(pocket.size, 3.1, 1e-12);
  EXPECT_NEAR(door.size, 1.1, 1e-12);
  EXPECT_NEAR(pocket.centroid.x(), 2.95, 1e-12);
  EXPECT_NEAR(pocket.centroid.y(), 2.05, 1e-12);
  EXPECT_NEAR(door.centroid.x(), 1.55, 1e-12);
  EXPECT_NEAR(door.centroid.y(), 3.95, 1e-12);
  EXPECT_NEAR(pocket.min_distance, 1.4, 1e-12);  // to (2.95, 2.05)
  EXPECT_NEAR(door.min_distance, 1.9, 1e-12);    // to (1.55, 3.95)

  // Goals: the reachable cell nearest the centroid. No wall cost (inflation_radius =
  // robot_radius): a straight path costs its length.
  PlannerConfig planner;
  planner.inflation_radius = planner.robot_radius;
  const CostGrid grid(g, classes, planner, &robot);
  const std::vector<float> reach = costToReach(grid, robot);
  placeGoals(g, classes, reach, config, &f);
  ASSERT_TRUE(pocket.reachable);
  ASSERT_TRUE(door.reachable);
  EXPECT_EQ(pocket.goal_cell, g.index(29, 20));
  EXPECT_EQ(door.goal_cell, g.index(15, 39));
  EXPECT_NEAR(pocket.path_cost, 1.4, 1e-5);
  EXPECT_NEAR(door.path_cost, 1.9, 1e-5);

  // explore_lite's cost: potential_scale · min_distance · res − gain_scale · cells · res.
  config.strategy = "frontier";
  scoreFrontiers(r, classes, config, &f);
  EXPECT_NEAR(pocket.utility, -(1e-3 * 1.4 * 0.1 - 31 * 0.1), 1e-12);
  EXPECT_NEAR(door.utility, -(1e-3 * 1.9 * 0.1 - 11 * 0.1), 1e-12);
  EXPECT_GT(pocket.utility, door.utility);  // the baseline goes for the long frontier

  // Non-specificity within 2 m (from the pocket's goal the door lies 2.04 m away: unseen). From
  // (2.95, 2.05): the pocket's 4 x 31 vacuous cells (1.24 m²) and the hall's half disc at NS 0.2
  // (0.2 × (2π less 0.09 m² cut off by the top and bottom walls) = 1.24 m²): 2.48 m². From the
  // door (1.55, 3.95): the vacuous half disc above (2π m²) less the wedges its jambs hide
  // (rays within atan(0.05 / 0.55) = 5.2° of the wall row on either side: 2 × 5.2/180 × 2π),
  // 5.92 m², plus the hall's half disc below, less the same wedges and the 2 × 0.52 m² beyond
  // the side walls, at NS 0.2: 0.98 m²; 6.9 m².
  config.strategy = "ns";
  config.gain_range = 2.0;
  scoreFrontiers(r, classes, config, &f);
  EXPECT_NEAR(pocket.gain, 2.48, 0.1 * 2.48);
  EXPECT_NEAR(door.gain, 6.9, 0.1 * 6.9);
  EXPECT_NEAR(pocket.utility, pocket.gain * std::exp(-0.2 * 1.4), 1e-6 * pocket.utility);
  EXPECT_NEAR(door.utility, door.gain * std::exp(-0.2 * 1.9), 1e-6 * door.utility);
  EXPECT_GT(door.utility, pocket.utility);  // ours goes for the door
}

TEST(VisibleGain, EntropyCountsBalancedEvidenceThatNonSpecificityDoesNot) {
  // 6 m x 6 m of cells measured often with balanced evidence (BetP 0.5, NS 0.1), range 2 m from
  // the centre: H(0.5) = 1 bit everywhere, so π 2² bit·m², against 0.1 π 2² m² of NS.
  LayerRaster r = blankRaster(60, 60, 0.1);
  fillBox(&r, 0, 0, 59, 59, 'b');
  const auto classes = classifyCells(r, CellClassConfig());
  EXPECT_NEAR(visibleGain(r, classes, Layer::kEntropy, {3.0, 3.0}, 2.0, 360), M_PI * 4.0, 1e-4);
  EXPECT_NEAR(visibleGain(r, classes, Layer::kNonspecificity, {3.0, 3.0}, 2.0, 360),
              0.1 * M_PI * 4.0, 1e-4);
  // Never observed space: 1 of either per m², the footprint at most.
  const LayerRaster empty = blankRaster(0, 0, 0.05);
  EXPECT_NEAR(visibleGain(empty, {}, Layer::kEntropy, {0.0, 0.0}, 2.0, 360), M_PI * 4.0, 1e-9);
}

TEST(Frontiers, EntropyGoesForBalancedEvidenceAndNonSpecificityForTheUnmeasured) {
  // A walled hall (rows 0 and 19, cols 0 and 50 occupied), 0.1 m cells: 1.9 m of balanced cells
  // (cols 1-19), a never-observed strip (col 20), the free hall (cols 21-39), 1 m never observed
  // (cols 40-49).
  // Frontiers at cols 21 and 39, 0.9 m either side of the robot. Within 2 m, the left goal sees
  // the strip and ~3.3 m² of balanced cells (H 1, NS 0.1), the right one ~1.8 m² never observed;
  // both ~3.3 m² of hall (H 0.47, NS 0.2).
  LayerRaster r = blankRaster(51, 20, 0.1);
  fillBox(&r, 0, 0, 19, 19, 'b');
  fillBox(&r, 21, 0, 39, 19, '.');
  fillBox(&r, 0, 0, 50, 0, '#');
  fillBox(&r, 0, 19, 50, 19, '#');
  fillBox(&r, 0, 0, 0, 19, '#');
  fillBox(&r, 50, 0, 50, 19, '#');
  const GridGeometry g = GridGeometry::of(r);
  const auto classes = classifyCells(r, CellClassConfig());
  const Eigen::Vector2d robot(3.05, 1.05);
  FrontierConfig config;
  config.min_frontier_size = 0.0;
  config.gain_range = 2.0;
  std::vector<Frontier> f = findFrontiers(g, classes, robot, config);
  ASSERT_EQ(f.size(), 2u);
  PlannerConfig planner;
  planner.inflation_radius = planner.robot_radius;
  const CostGrid grid(g, classes, planner, &robot);
  placeGoals(g, classes, costToReach(grid, robot), config, &f);
  const bool first_is_left = f[0].centroid.x() < f[1].centroid.x();
  const Frontier& left = first_is_left ? f[0] : f[1];
  const Frontier& right = first_is_left ? f[1] : f[0];
  ASSERT_TRUE(left.reachable && right.reachable);
  EXPECT_NEAR(left.path_cost, right.path_cost, 1e-5);
  config.strategy = "ns";
  scoreFrontiers(r, classes, config, &f);
  EXPECT_GT(right.utility, 1.5 * left.utility);
  config.strategy = "entropy";
  scoreFrontiers(r, classes, config, &f);
  EXPECT_GT(left.utility, 1.2 * right.utility);
}

TEST(Frontiers, UnreachableFrontierHasNoGoal) {
  // The hall's door narrowed to a 0.2 m gap the 0.25 m robot cannot pass: no goal there.
  LayerRaster r = hallWithPocketAndDoor();
  fillBox(&r, 10, 39, 20, 39, '#');
  fillBox(&r, 14, 39, 15, 39, '.');
  const GridGeometry g = GridGeometry::of(r);
  const auto classes = classifyCells(r, CellClassConfig());
  const Eigen::Vector2d robot(1.55, 2.05);
  FrontierConfig config;
  config.min_frontier_size = 0.0;
  std::vector<Frontier> f = findFrontiers(g, classes, robot, config);
  ASSERT_EQ(f.size(), 2u);
  const CostGrid grid(g, classes, PlannerConfig(), &robot);
  placeGoals(g, classes, costToReach(grid, robot), config, &f);
  for (const Frontier& x : f) {
    EXPECT_EQ(x.reachable, x.cells.size() == 31u) << x.cells.size() << " cells";
  }
  scoreFrontiers(r, classes, config, &f);
  for (const Frontier& x : f) {
    if (!x.reachable) {
      EXPECT_EQ(x.utility, -std::numeric_limits<double>::infinity());
    }
  }
}

TEST(Frontiers, RevisitClustersOfHighExternalConflict) {
  // A 3 x 3 block of cells in conflict (EC 2 bits) in known free space, and a lone one.
  LayerRaster r = blankRaster(40, 40, 0.1);
  fillBox(&r, 0, 0, 39, 39, '.');
  fillBox(&r, 20, 20, 22, 22, 'x');
  fillBox(&r, 5, 5, 5, 5, 'x');
  const GridGeometry g = GridGeometry::of(r);
  const auto classes = classifyCells(r, CellClassConfig());
  const Eigen::Vector2d robot(0.55, 3.05);
  FrontierConfig config;
  config.revisit_conflict = true;
  std::vector<Frontier> f = findConflictClusters(r, robot, config);  // at least 5 cells
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(f[0].revisit);
  EXPECT_EQ(f[0].cells.size(), 9u);
  EXPECT_NEAR(f[0].gain, 9 * 2.0 * 0.01, 1e-6);  // Σ EC · cell area (bit·m²)
  EXPECT_NEAR(f[0].centroid.x(), 2.15, 1e-12);
  // The goal: a reachable free cell as near as can be to 1 m from the cluster's centre.
  const CostGrid grid(g, classes, PlannerConfig(), &robot);
  placeGoals(g, classes, costToReach(grid, robot), config, &f);
  ASSERT_TRUE(f[0].reachable);
  EXPECT_NEAR((f[0].goal - f[0].centroid).norm(), 1.0, 0.05);
  scoreFrontiers(r, classes, config, &f);
  EXPECT_NEAR(f[0].utility, 0.18 * std::exp(-0.2 * f[0].path_cost), 1e-9);
}

TEST(Frontiers, StrategyNamesAndBadConfig) {
  Strategy s = Strategy::kFrontier;
  EXPECT_TRUE(parseStrategy("ns", &s));
  EXPECT_EQ(s, Strategy::kNonSpecificity);
  EXPECT_TRUE(parseStrategy("frontier", &s));
  EXPECT_EQ(s, Strategy::kFrontier);
  EXPECT_TRUE(parseStrategy("entropy", &s));
  EXPECT_EQ(s, Strategy::kEntropy);
  EXPECT_STREQ(strategyName(Strategy::kEntropy), "entropy");
  EXPECT_FALSE(parseStrategy("nearest", &s));
  EXPECT_STREQ(strategyName(Strategy::kNonSpecificity), "ns");
  std::string why;
  FrontierConfig c;
  EXPECT_TRUE(c.isValid(&why)) << why;
  c.gain_rays = 2;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_NE(why.find("gain_rays"), std::string::npos);
  c = FrontierConfig();
  c.gain_range = std::nan("");
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_NE(why.find("gain_range"), std::string::npos);
  c = FrontierConfig();
  EXPECT_EQ(c.kind(), Strategy::kNonSpecificity);
  c.strategy = "frontier";
  EXPECT_EQ(c.kind(), Strategy::kFrontier);
  c.strategy = "nearest";
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "strategy must be ns, entropy or frontier, not 'nearest'");
}

}  // namespace
}  // namespace exploration
}  // namespace evidential_slam
