// Tests of rebuilding a map from its layer rasters (core/fusion/layer_map.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "evidential_slam/core/fusion/layer_map.h"
#include "evidential_slam/core/layers.h"

namespace evidential_slam {
namespace fusion {
namespace {

// Cells of every kind: vacuous-free, occupied with a large conflict (m(∅) = 1 - 2^-60, which a
// float m(∅) cannot tell from 1), mixed, and an unobserved hole, at negative cell indices too.
EvidentialGridMap sample() {
  EvidentialGridMap map(0.05);
  map.mutableCell(-3, -2) = Cell::fromStored(0.0f, 0.8f, 0.0f);
  map.mutableCell(-2, -2) = Cell::fromStored(0.9f, 0.0f, 60.0f * 0.6931472f);
  map.mutableCell(4, 5) = Cell::fromStored(0.5f, 0.3f, 0.25f);
  map.mutableCell(40, 7) = Cell::fromStored(0.1f, 0.0f, 0.0f);
  return map;
}

void expectSameCells(const EvidentialGridMap& a, const EvidentialGridMap& b) {
  CellBox box = a.allocatedBox();
  box.extend(b.allocatedBox());
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& ca = a.cell(x, y);
      const Cell& cb = b.cell(x, y);
      ASSERT_EQ(ca.observed(), cb.observed()) << x << ", " << y;
      EXPECT_NEAR(ca.occupied(), cb.occupied(), 1e-6) << x << ", " << y;
      EXPECT_NEAR(ca.free(), cb.free(), 1e-6) << x << ", " << y;
      EXPECT_NEAR(ca.lambda(), cb.lambda(), 1e-3 * std::max(1.0f, ca.lambda())) << x << ", " << y;
    }
  }
}

TEST(LayerMapTest, RebuildsTheMapExtractLayersRasterised) {
  const EvidentialGridMap map = sample();
  const LayerRaster raster = extractLayers(map);
  EvidentialGridMap back;
  Pose2 offset(1, 1, 1);
  std::string why;
  ASSERT_TRUE(mapFromLayers(raster, &back, &offset, &why)) << why;
  EXPECT_DOUBLE_EQ(back.resolution(), 0.05);
  EXPECT_NEAR(offset.x, 0.0, 1e-12);
  EXPECT_NEAR(offset.y, 0.0, 1e-12);
  EXPECT_EQ(offset.theta, 0.0);
  expectSameCells(map, back);
  // λ = 60 ln 2 comes back from EC although m(∅) is 1 in float.
  EXPECT_NEAR(back.cell(-2, -2).lambda(), 60.0 * std::log(2.0), 0.05);
}

// An origin off the cell grid: cells land on the nearest whole cell and the rest is the offset.
TEST(LayerMapTest, AnOriginOffTheGridIsReturnedAsOffset) {
  LayerRaster raster = extractLayers(sample());
  raster.origin_x += 0.02;
  raster.origin_y -= 0.03;  // rounds to one cell lower, +0.02 left over
  EvidentialGridMap back;
  Pose2 offset;
  ASSERT_TRUE(mapFromLayers(raster, &back, &offset, nullptr));
  EXPECT_NEAR(offset.x, 0.02, 1e-9);
  EXPECT_NEAR(offset.y, 0.02, 1e-9);
  EXPECT_TRUE(back.cell(4, 4).observed());
  EXPECT_NEAR(back.cell(4, 4).occupied(), 0.5, 1e-6);
}

TEST(LayerMapTest, RefusesRastersThatHoldNoBelief) {
  const LayerRaster good = extractLayers(sample());
  EvidentialGridMap back;
  std::string why;

  LayerRaster r = good;
  r.resolution = 0.0;
  EXPECT_FALSE(mapFromLayers(r, &back, nullptr, &why));
  EXPECT_NE(why.find("resolution"), std::string::npos) << why;

  r = good;
  r.values[static_cast<int>(Layer::kFree)].pop_back();
  EXPECT_FALSE(mapFromLayers(r, &back, nullptr, &why));
  EXPECT_NE(why.find("free has"), std::string::npos) << why;

  r = good;
  r.observed.clear();
  EXPECT_FALSE(mapFromLayers(r, &back, nullptr, &why));
  EXPECT_NE(why.find("observed has"), std::string::npos) << why;

  r = good;
  for (size_t i = 0; i < r.observed.size(); ++i) {
    if (r.observed[i] == 0) continue;
    r.values[static_cast<int>(Layer::kOccupied)][i] = -0.5f;
    break;
  }
  EXPECT_FALSE(mapFromLayers(r, &back, nullptr, &why));
  EXPECT_NE(why.find("not a belief"), std::string::npos) << why;
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
