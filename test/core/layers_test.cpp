// Tests of the layer rasters (layers.h): layout (row 0 = lowest y, col 0 = lowest x, origin = lower
// left corner of the box's first cell), values equal to the measures of each cell, observed flags.
// Cell values are the hand-computed ones of measures_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cell_support.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/measures.h"

namespace evidential_slam {
namespace {

using namespace testing_cells;

// The cells store m̃ in steps of 2^-23 and λ as a half float (2^-11 relative): values agree with
// the nominal masses to ~3e-4 (EC of λ = ln 2 is off by up to 2.4e-4 / ln 2).
constexpr double kTol = 5e-4;

// Layer values, in layer order (occupied free unknown conflict pignistic nonspecificity
// internal_conflict external_conflict entropy anomaly; the anomaly is 0 without an AnomalyGrid):
// vacuous: m(Θ) = 1, BetP 0.5, NS 1, H 1.
const std::vector<double> kVacuous = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.0, 0.0, 1.0, 0.0};
// certain occupied: m(o) = 1, BetP 1, everything else 0.
const std::vector<double> kOccupied = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0};
// (∅0.5, o0.3, e0.1, Θ0.1): BetP 0.35/0.5 = 0.7, IC 0.22877124, EC 1, H(0.7) = 0.88129090.
const std::vector<double> kConflicting = {
    0.3, 0.1, 0.1, 0.5, 0.7, 0.1, 0.22877123795494, 1.0, 0.88129089923069, 0.0};
// (∅0, o0.6, e0.1, Θ0.3): BetP 0.75, IC 0.22339467, H(0.75) = 0.81127812.
const std::vector<double> kAsymmetric = {
    0.6, 0.1, 0.3, 0.0, 0.75, 0.3, 0.22339466555577, 0.0, 0.81127812445913, 0.0};

// Grid with (2,3) certain occupied, (4,3) conflicting, (5,2) asymmetric; resolution 0.05.
EvidentialGridMap makeGrid() {
  EvidentialGridMap g(0.05);
  g.mutableCell(2, 3) = cellWithConflict(1.0, 0.0, 0.0);
  g.mutableCell(4, 3) = cellWithConflict(0.6, 0.2, 0.5);
  g.mutableCell(5, 2) = cellWithConflict(0.6, 0.1, 0.0);
  return g;
}

void expectLayers(const LayerRaster& r, int index, const std::vector<double>& expected) {
  ASSERT_EQ(expected.size(), static_cast<size_t>(kLayerCount)) << "one expected value per layer";
  for (int l = 0; l < kLayerCount; ++l) {
    ASSERT_LT(static_cast<size_t>(index), r.values[l].size());
    EXPECT_NEAR(r.values[l][index], expected[l], kTol)
        << "layer " << layerNames()[l] << " index " << index;
  }
}

void expectSizes(const LayerRaster& r, int width, int height) {
  EXPECT_EQ(r.width, width);
  EXPECT_EQ(r.height, height);
  for (int l = 0; l < kLayerCount; ++l) {
    EXPECT_EQ(r.values[l].size(), static_cast<size_t>(width * height)) << layerNames()[l];
  }
  EXPECT_EQ(r.observed.size(), static_cast<size_t>(width * height));
}

// Explicit box x [1,5], y [2,4]: width 5, height 3, origin = corner of cell (1,2) = (0.05, 0.10).
// index(cx, cy) = (cy - 2) * 5 + (cx - 1): (2,3) -> 6, (4,3) -> 8, (5,2) -> 4; all others vacuous.
TEST(LayersTest, ExplicitBoxLayoutAndValues) {
  const EvidentialGridMap g = makeGrid();
  const LayerRaster r = extractLayers(g, CellBox{1, 2, 5, 4});
  expectSizes(r, 5, 3);
  EXPECT_DOUBLE_EQ(r.resolution, 0.05);
  EXPECT_NEAR(r.origin_x, 0.05, 1e-12);
  EXPECT_NEAR(r.origin_y, 0.10, 1e-12);
  for (int i = 0; i < 15; ++i) {
    SCOPED_TRACE(testing::Message() << "index " << i);
    if (i == 6) {
      expectLayers(r, i, kOccupied);
    } else if (i == 8) {
      expectLayers(r, i, kConflicting);
    } else if (i == 4) {
      expectLayers(r, i, kAsymmetric);
    } else {
      expectLayers(r, i, kVacuous);
    }
    const bool observed = (i == 4 || i == 6 || i == 8);
    EXPECT_EQ(r.observed[i], observed ? 1 : 0);
  }
  // Named accessor is the same vector.
  EXPECT_NEAR(r.layer(Layer::kExternalConflict)[8], 1.0, kTol);
  EXPECT_NEAR(r.layer(Layer::kOccupied)[6], 1.0, kTol);
}

// The raster values equal layerValue() of the grid's cells everywhere in the box.
TEST(LayersTest, ValuesEqualLayerValueOfCells) {
  const EvidentialGridMap g = makeGrid();
  const CellBox box{0, 1, 6, 5};
  const LayerRaster r = extractLayers(g, box);
  expectSizes(r, 7, 5);
  for (int cy = box.min_y; cy <= box.max_y; ++cy) {
    for (int cx = box.min_x; cx <= box.max_x; ++cx) {
      const int index = (cy - box.min_y) * 7 + (cx - box.min_x);
      for (int l = 0; l < kLayerCount; ++l) {
        EXPECT_NEAR(r.values[l][index], layerValue(g.cell(cx, cy), static_cast<Layer>(l)), kTol);
      }
      EXPECT_EQ(r.observed[index], g.cell(cx, cy).observed() ? 1 : 0);
    }
  }
}

// A subset of the layers: those asked for hold the full extraction's values, the others are empty.
TEST(LayersTest, SubsetComputesOnlyTheLayersAskedFor) {
  const EvidentialGridMap g = makeGrid();
  const CellBox box{0, 1, 6, 5};
  AnomalyGrid anomaly;
  anomaly.add(4, 3, 2.5f);
  const LayerRaster all = extractLayers(g, box, &anomaly);
  const LayerRaster some =
      extractLayers(g, box, &anomaly, layerBit(Layer::kPignistic) | layerBit(Layer::kAnomaly));
  EXPECT_EQ(some.width, 7);
  EXPECT_EQ(some.height, 5);
  EXPECT_EQ(some.observed, all.observed);
  for (int l = 0; l < kLayerCount; ++l) {
    const Layer layer = static_cast<Layer>(l);
    if (layer == Layer::kPignistic || layer == Layer::kAnomaly) {
      EXPECT_EQ(some.values[l], all.values[l]) << layerName(layer);
    } else {
      EXPECT_TRUE(some.values[l].empty()) << layerName(layer);
    }
  }
  EXPECT_FLOAT_EQ(some.layer(Layer::kAnomaly)[(3 - 1) * 7 + 4], 2.5f);
}

// Margin form: observed box x [2,5], y [2,3]; margin 1 -> x [1,6], y [1,4]: width 6, height 4,
// origin (0.05, 0.05); index = (cy - 1) * 6 + (cx - 1): (2,3) -> 13, (4,3) -> 15, (5,2) -> 10.
TEST(LayersTest, MarginAroundObservedBox) {
  const EvidentialGridMap g = makeGrid();
  const LayerRaster r = extractLayers(g, 1);
  expectSizes(r, 6, 4);
  EXPECT_NEAR(r.origin_x, 0.05, 1e-12);
  EXPECT_NEAR(r.origin_y, 0.05, 1e-12);
  expectLayers(r, 13, kOccupied);
  expectLayers(r, 15, kConflicting);
  expectLayers(r, 10, kAsymmetric);
  expectLayers(r, 0, kVacuous);
  expectLayers(r, 23, kVacuous);
  int observed = 0;
  for (uint8_t o : r.observed) observed += o;
  EXPECT_EQ(observed, 3);
  EXPECT_EQ(r.observed[13], 1);
  EXPECT_EQ(r.observed[15], 1);
  EXPECT_EQ(r.observed[10], 1);
}

// Margin 0: exactly the observed box x [2,5], y [2,3]: width 4, height 2, origin (0.10, 0.10);
// (2,3) -> row 1 col 0 = 4, (4,3) -> 6, (5,2) -> row 0 col 3 = 3.
TEST(LayersTest, ZeroMargin) {
  const EvidentialGridMap g = makeGrid();
  const LayerRaster r = extractLayers(g, 0);
  expectSizes(r, 4, 2);
  EXPECT_NEAR(r.origin_x, 0.10, 1e-12);
  EXPECT_NEAR(r.origin_y, 0.10, 1e-12);
  expectLayers(r, 4, kOccupied);
  expectLayers(r, 6, kConflicting);
  expectLayers(r, 3, kAsymmetric);
}

// Negative cell indices: box x [-4,-2], y [-3,-1] at 0.05 m -> origin (-0.20, -0.15), 3 x 3;
// cell (-3,-2) is row 1 col 1 = index 4; cell (-2,-3) is row 0 col 2 = index 2.
TEST(LayersTest, NegativeCoordinates) {
  EvidentialGridMap g(0.05);
  g.mutableCell(-3, -2) = cellWithConflict(1.0, 0.0, 0.0);
  g.mutableCell(-2, -3) = cellWithConflict(0.6, 0.2, 0.5);
  const LayerRaster r = extractLayers(g, CellBox{-4, -3, -2, -1});
  expectSizes(r, 3, 3);
  EXPECT_NEAR(r.origin_x, -0.20, 1e-12);
  EXPECT_NEAR(r.origin_y, -0.15, 1e-12);
  expectLayers(r, 4, kOccupied);
  expectLayers(r, 2, kConflicting);
  expectLayers(r, 0, kVacuous);
  expectLayers(r, 8, kVacuous);
  EXPECT_EQ(r.observed[4], 1);
  EXPECT_EQ(r.observed[2], 1);
  EXPECT_EQ(r.observed[0], 0);
}

}  // namespace
}  // namespace evidential_slam
