// Tests of scoring a map against a ground-truth raster (core/fusion/map_score.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "evidential_slam/core/fusion/map_score.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr CellClass U = CellClass::kUnknown, F = CellClass::kFree, O = CellClass::kOccupied;

Cell cell(float occupied, float free, float lambda = 0.0f) {
  return Cell::fromStored(occupied, free, lambda);
}

// BetP(o) = m̃(o) + m̃(Θ)/2, NS = e^{-λ} m̃(Θ):
//   (0.9, 0):    BetP 0.95, NS 0.1  → occupied
//   (0, 0.8):    BetP 0.1,  NS 0.2  → free
//   (0.3, 0.3):  BetP 0.5          → unknown
//   (0.35, 0):   BetP 0.675, NS 0.65 > 0.5 → unknown (too little evidence)
//   (0.4, 0) with λ = ln 2: NS = 0.6 / 2 = 0.3, BetP 0.7 → occupied (conflict lowers NS)
TEST(MapScoreTest, ClassifiesByPignisticProbabilityAndNonSpecificity) {
  const ClassifyConfig config;
  EXPECT_EQ(classify(EvidentialGridMap::vacuousCell(), config), U);
  EXPECT_EQ(classify(cell(0.9f, 0.0f), config), O);
  EXPECT_EQ(classify(cell(0.0f, 0.8f), config), F);
  EXPECT_EQ(classify(cell(0.3f, 0.3f), config), U);
  EXPECT_EQ(classify(cell(0.35f, 0.0f), config), U);
  EXPECT_EQ(classify(cell(0.4f, 0.0f, static_cast<float>(std::log(2.0))), config), O);
}

OccupancyRaster raster(double resolution, int width, int height, std::vector<CellClass> rows) {
  OccupancyRaster r;
  r.resolution = resolution;
  r.width = width;
  r.height = height;
  r.cells = std::move(rows);
  return r;
}

void set(EvidentialGridMap* map, int x, int y, const Cell& c) { map->mutableCell(x, y) = c; }

// Truth at 0.1 m (rows from y = 0):  row 0: O F F U,  row 1: O F O F,  row 2: F F F F.
// The map at 0.05 m: four map cells per truth cell.
//   (0,0) O: one occupied map cell, three free → occupied (correct)
//   (1,0) F: all free → free (correct)
//   (2,0) F: one occupied → occupied (wrong)
//   (3,0) U: free (not scored)
//   (0,1) O: unobserved → unknown
//   (1,1) F: mixed cells (0.3, 0.3) → unknown
//   (2,1) O: occupied (correct)
//   (3,1) and row 2: unobserved.
// Known 11, classified 4, correct 3.
TEST(MapScoreTest, ScoresAgainstACoarserTruth) {
  const OccupancyRaster truth = raster(0.1, 4, 3, {O, F, F, U, O, F, O, F, F, F, F, F});
  EvidentialGridMap map(0.05);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 8; ++x) set(&map, x, y, cell(0.0f, 0.8f));
  }
  set(&map, 1, 0, cell(0.9f, 0.0f));
  set(&map, 5, 1, cell(0.9f, 0.0f));
  for (int y = 2; y < 4; ++y) {
    for (int x = 2; x < 4; ++x) set(&map, x, y, cell(0.3f, 0.3f));
    for (int x = 4; x < 6; ++x) set(&map, x, y, cell(0.9f, 0.0f));
  }
  MapScore score;
  std::string why;
  ASSERT_TRUE(scoreMap(map, Pose2(), truth, ClassifyConfig{}, &score, &why)) << why;
  EXPECT_EQ(score.known, 11u);
  EXPECT_EQ(score.classified, 4u);
  EXPECT_EQ(score.correct, 3u);
  EXPECT_DOUBLE_EQ(score.accuracy(), 0.75);
  EXPECT_DOUBLE_EQ(score.coverage(), 4.0 / 11.0);
  const auto o = static_cast<size_t>(O), f = static_cast<size_t>(F), u = static_cast<size_t>(U);
  EXPECT_EQ(score.confusion[o][o], 2u);
  EXPECT_EQ(score.confusion[f][f], 1u);
  EXPECT_EQ(score.confusion[f][o], 1u);
  EXPECT_EQ(score.confusion[u][f], 1u);
  EXPECT_EQ(score.confusion[o][u], 1u);
  EXPECT_EQ(score.confusion[f][u], 6u);
}

// The map placed at (0.2, 0.1) in the truth's frame: its cell (0, 0), centre (0.025, 0.025), lands
// at (0.225, 0.125), in truth cell (2, 1).
TEST(MapScoreTest, PlacesTheMapByItsPose) {
  const OccupancyRaster truth = raster(0.1, 4, 3, std::vector<CellClass>(12, O));
  EvidentialGridMap map(0.05);
  set(&map, 0, 0, cell(0.9f, 0.0f));
  MapScore score;
  ASSERT_TRUE(scoreMap(map, Pose2(0.2, 0.1, 0.0), truth, ClassifyConfig{}, &score, nullptr));
  EXPECT_EQ(score.classified, 1u);
  EXPECT_EQ(score.correct, 1u);
  EXPECT_EQ(score.known, 12u);
  ASSERT_TRUE(scoreMap(map, Pose2(), truth, ClassifyConfig{}, &score, nullptr));
  EXPECT_EQ(score.classified, 1u);
}

// Truth at 0.05 m, map at 0.1 m: the map cell's centre (0.05, 0.05) falls in truth cell (1, 1);
// the three others hold no map cell centre and read the map cell under their centres.
TEST(MapScoreTest, ScoresAgainstAFinerTruth) {
  const OccupancyRaster truth = raster(0.05, 2, 2, {O, O, O, F});
  EvidentialGridMap map(0.1);
  set(&map, 0, 0, cell(0.9f, 0.0f));
  MapScore score;
  ASSERT_TRUE(scoreMap(map, Pose2(), truth, ClassifyConfig{}, &score, nullptr));
  EXPECT_EQ(score.classified, 4u);
  EXPECT_EQ(score.correct, 3u);
}

TEST(MapScoreTest, RefusesBadInput) {
  const EvidentialGridMap map(0.05);
  MapScore score;
  std::string why;
  EXPECT_FALSE(
      scoreMap(map, Pose2(), raster(0.1, 2, 2, {O, O, O}), ClassifyConfig{}, &score, &why));
  EXPECT_EQ(why, "ground truth: 3 cells for 2 x 2");
  EXPECT_FALSE(scoreMap(map, Pose2(), raster(0.0, 1, 1, {O}), ClassifyConfig{}, &score, &why));
  EXPECT_EQ(why, "ground truth: resolution must be > 0");
  ClassifyConfig config;
  config.free_betp = 0.5;
  EXPECT_FALSE(scoreMap(map, Pose2(), raster(0.1, 1, 1, {O}), config, &score, &why));
  EXPECT_EQ(why, "invalid classification config: free_betp must be in [0, 0.5)");
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
