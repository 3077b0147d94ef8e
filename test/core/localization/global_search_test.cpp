// The correlative global search (core/localization/global_search.h): cell scores, a pose's score
// and the best hypotheses of a two-point scan by hand on a tiny map.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "evidential_slam/core/localization/global_search.h"

namespace evidential_slam {
namespace {

// 12 x 8 cells of 0.1 m, confidently empty (m(e) = 0.9) but for two occupied cells, A = (10, 2)
// and B = (2, 6); the free cells are all the empty ones.
constexpr double kRes = 0.1;
EvidentialGridMap tinyMap() {
  EvidentialGridMap map(kRes);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 12; ++x) map.mutableCell(x, y).setMasses(0.0f, 0.9f);
  }
  map.mutableCell(10, 2).setMasses(0.9f, 0.0f);
  map.mutableCell(2, 6).setMasses(0.9f, 0.0f);
  return map;
}

std::vector<CellIndex> freeCells() {
  std::vector<CellIndex> cells;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 12; ++x) {
      if (!((x == 10 && y == 2) || (x == 2 && y == 6))) cells.push_back(CellIndex{x, y});
    }
  }
  return cells;
}

// σ = 0.1 m: s = round(255 exp(-d² / 2σ²)) / 255 with d the distance to A or B, 0 from 3σ on:
// d = 0: 1; d = 0.1: 255 e^-0.5 = 154.66 -> 155/255; d = √2 0.1: 255 e^-1 = 93.81 -> 94/255;
// d = 0.2: 255 e^-2 = 34.51 -> 35/255; d = √5 0.1: 255 e^-2.5 = 20.93 -> 21/255; d = 0.3: 0.
TEST(GlobalSearch, CellScoresByHand) {
  const GlobalSearch search(tinyMap(), 0.1, freeCells());
  EXPECT_DOUBLE_EQ(search.cellScore(10, 2), 1.0);
  EXPECT_DOUBLE_EQ(search.cellScore(9, 2), 155.0 / 255);
  EXPECT_DOUBLE_EQ(search.cellScore(3, 5), 94.0 / 255);
  EXPECT_DOUBLE_EQ(search.cellScore(10, 4), 35.0 / 255);
  EXPECT_DOUBLE_EQ(search.cellScore(1, 4), 21.0 / 255);
  EXPECT_DOUBLE_EQ(search.cellScore(7, 2), 0.0);
  EXPECT_DOUBLE_EQ(search.cellScore(5, 4), 0.0);
  EXPECT_DOUBLE_EQ(search.cellScore(-3, 2), 0.0);  // off the map
  EXPECT_THROW(GlobalSearch(tinyMap(), 0.0, freeCells()), std::invalid_argument);
  EXPECT_THROW(GlobalSearch(EvidentialGridMap(kRes), 0.1, freeCells()), std::invalid_argument);
}

// One cell at 10 m: acos(1 - 0.05² / (2 10²)) = 0.0050000 rad; the step never exceeds π/4.
TEST(GlobalSearch, HeadingStepMovesTheFarthestEndpointByACell) {
  EXPECT_NEAR(GlobalSearch::headingStep(0.05, 10.0), 0.005, 1e-6);
  EXPECT_NEAR(GlobalSearch::headingStep(0.1, 0.5), std::acos(1.0 - 0.01 / 0.5), 1e-12);
  EXPECT_DOUBLE_EQ(GlobalSearch::headingStep(0.1, 0.05), M_PI / 4);
}

// From the robot at (0.55, 0.45) (cell (5, 4)) heading 0, a scan of two points: A's centre
// (1.05, 0.25) at (0.5, -0.2) and B's (0.25, 0.65) at (-0.3, 0.2). Turned by π about (0.75, 0.45)
// (cell (7, 4)) the scan puts the first point on B and the second on A: two poses explain it
// fully (score 1), in different regions. The headings: the farthest point is 0.5385 m away, a
// step of acos(1 - 0.01 / (2 0.29)) = 0.1859 rad, 34 headings of 2π/34, π the 17th. Shifted by a
// cell in x, the first pose scores (155 + 155) / 510.
TEST(GlobalSearch, TwoPointScanByHand) {
  const GlobalSearch search(tinyMap(), 0.1, freeCells());
  const std::vector<Eigen::Vector2d> points = {Eigen::Vector2d(0.5, -0.2),
                                               Eigen::Vector2d(-0.3, 0.2)};
  EXPECT_DOUBLE_EQ(search.score(Pose2(0.55, 0.45, 0.0), points), 1.0);
  EXPECT_DOUBLE_EQ(search.score(Pose2(0.75, 0.45, M_PI), points), 1.0);
  EXPECT_DOUBLE_EQ(search.score(Pose2(0.65, 0.45, 0.0), points), 155.0 / 255);
  GlobalSearch::Options options;
  options.count = 3;
  options.region_xy = 0.5;
  options.region_angle = M_PI / 18;
  GlobalSearch::Stats stats;
  const std::vector<PoseHypothesis> best = search.search(points, options, &stats);
  EXPECT_EQ(stats.headings, 34u);
  ASSERT_EQ(best.size(), 3u);
  EXPECT_DOUBLE_EQ(best[0].score, 1.0);
  EXPECT_DOUBLE_EQ(best[1].score, 1.0);
  EXPECT_LT(best[2].score, 1.0);
  // The two exact poses, in either order.
  const bool first_unturned = std::abs(best[0].pose.theta) < 1e-9;
  const Pose2& unturned = first_unturned ? best[0].pose : best[1].pose;
  const Pose2& turned = first_unturned ? best[1].pose : best[0].pose;
  EXPECT_NEAR(unturned.x, 0.55, 1e-9);
  EXPECT_NEAR(unturned.y, 0.45, 1e-9);
  EXPECT_NEAR(unturned.theta, 0.0, 1e-9);
  EXPECT_NEAR(turned.x, 0.75, 1e-9);
  EXPECT_NEAR(turned.y, 0.45, 1e-9);
  EXPECT_NEAR(std::abs(turned.theta), M_PI, 1e-9);
  // Every region's best is no better than these, and the search pruned: fewer squares and leaves
  // scored than the 94 free cells times 34 headings.
  for (const PoseHypothesis& h : best) EXPECT_LE(h.score, 1.0);
  EXPECT_LT(stats.evaluations, 94u * 34u);
  // No points, no hypotheses.
  EXPECT_TRUE(search.search({}, options).empty());
}

// The search's best equals the best of a brute-force scoring of every free cell and heading (the
// bounds of the coarse levels never prune the optimum), for a scan of five points.
TEST(GlobalSearch, BranchAndBoundFindsTheBruteForceOptimum) {
  const GlobalSearch search(tinyMap(), 0.1, freeCells());
  const std::vector<Eigen::Vector2d> points = {
      Eigen::Vector2d(0.42, -0.13), Eigen::Vector2d(-0.31, 0.27), Eigen::Vector2d(0.2, 0.33),
      Eigen::Vector2d(-0.05, -0.4), Eigen::Vector2d(0.37, 0.08)};
  GlobalSearch::Options options;
  options.count = 1;
  GlobalSearch::Stats stats;
  const std::vector<PoseHypothesis> best = search.search(points, options, &stats);
  ASSERT_EQ(best.size(), 1u);
  const double step = 2.0 * M_PI / static_cast<double>(stats.headings);
  double brute = 0.0;
  for (const CellIndex& c : freeCells()) {
    for (size_t a = 0; a < stats.headings; ++a) {
      brute = std::max(brute, search.score(Pose2((c.x + 0.5) * kRes, (c.y + 0.5) * kRes,
                                                 static_cast<double>(a) * step),
                                           points));
    }
  }
  EXPECT_GT(brute, 0.0);
  EXPECT_NEAR(best[0].score, brute, 1e-12);
  EXPECT_NEAR(search.score(best[0].pose, points), brute, 1e-12);
}

}  // namespace
}  // namespace evidential_slam
