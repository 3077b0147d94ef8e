// The exact Euclidean distance transform (core/localization) against hand-computed distances.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "evidential_slam/core/localization/distance_transform.h"

namespace evidential_slam {
namespace {

// A 5 x 4 grid with seeds at (0, 0) and (4, 3): each cell's squared distance is the smaller of
// dx^2 + dy^2 to either, e.g. (2, 1): min(4 + 1, 4 + 4) = 5, (3, 2): min(9 + 4, 1 + 1) = 2.
TEST(DistanceTransform, SquaredDistancesByHand) {
  std::vector<uint8_t> seeds(20, 0);
  seeds[0] = 1;           // (0, 0)
  seeds[3 * 5 + 4] = 1;   // (4, 3)
  const std::vector<float> d = squaredDistanceTransform(seeds, 5, 4);
  const auto at = [&](int x, int y) { return d[static_cast<size_t>(y * 5 + x)]; };
  EXPECT_EQ(at(0, 0), 0.0f);
  EXPECT_EQ(at(4, 3), 0.0f);
  EXPECT_EQ(at(1, 0), 1.0f);
  EXPECT_EQ(at(1, 1), 2.0f);
  EXPECT_EQ(at(2, 1), 5.0f);
  EXPECT_EQ(at(3, 2), 2.0f);
  EXPECT_EQ(at(4, 0), 9.0f);   // min(16, 9)
  EXPECT_EQ(at(0, 3), 9.0f);   // min(9, 16)
  EXPECT_EQ(at(2, 2), 5.0f);   // min(4 + 4, 4 + 1)
  EXPECT_EQ(at(2, 0), 4.0f);   // min(4, 4 + 9)
}

// One seed: the distance grows along rows and columns alike (the second pass reads the first's
// result); no seed: infinity everywhere; a mismatched size is refused.
TEST(DistanceTransform, OneSeedNoSeedAndBadSizes) {
  std::vector<uint8_t> seeds(3 * 6, 0);
  seeds[5 * 3 + 1] = 1;  // (1, 5) of a 3 wide, 6 high grid
  const std::vector<float> d = squaredDistanceTransform(seeds, 3, 6);
  EXPECT_EQ(d[0], 26.0f);            // (0, 0): 1 + 25
  EXPECT_EQ(d[2 * 3 + 2], 10.0f);    // (2, 2): 1 + 9
  EXPECT_EQ(d[5 * 3 + 0], 1.0f);     // (0, 5)
  const std::vector<float> none = squaredDistanceTransform(std::vector<uint8_t>(6, 0), 2, 3);
  for (float v : none) EXPECT_EQ(v, std::numeric_limits<float>::infinity());
  EXPECT_TRUE(squaredDistanceTransform({}, 0, 0).empty());
  EXPECT_THROW(squaredDistanceTransform(std::vector<uint8_t>(5, 0), 2, 3), std::invalid_argument);
  EXPECT_THROW(squaredDistanceTransform({}, -1, 0), std::invalid_argument);
}

// The saturated whole-cell distance against the hand-computed squared ones: (0, 0) of the 3 x 6
// grid is sqrt(26) = 5.1 cells from the seed, (2, 2) sqrt(10) = 3.2; no seed: 255 everywhere.
TEST(DistanceTransform, SaturatedByHand) {
  std::vector<uint8_t> grid(3 * 6, 0);
  grid[5 * 3 + 1] = 1;
  std::vector<float> scratch;
  saturatedDistanceTransform(&grid, 3, 6, &scratch);
  EXPECT_EQ(grid[0], 5);
  EXPECT_EQ(grid[2 * 3 + 2], 3);
  EXPECT_EQ(grid[5 * 3 + 1], 0);
  EXPECT_EQ(grid[5 * 3 + 0], 1);
  std::vector<uint8_t> none(6, 0);
  saturatedDistanceTransform(&none, 2, 3, &scratch);
  for (uint8_t v : none) EXPECT_EQ(v, 255);
  EXPECT_THROW(saturatedDistanceTransform(&none, 4, 3, &scratch), std::invalid_argument);
}

// On grids whose distances reach past the saturation (700 cells long, one seed at an end), and on
// random seeds, the saturated transform equals floor(sqrt) of the squared one, capped.
TEST(DistanceTransform, SaturatedEqualsTheSquaredOnesFloorCapped) {
  uint64_t state = 12345;
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<uint32_t>(state >> 33);
  };
  std::vector<float> scratch;
  const int sizes[][2] = {{700, 40}, {40, 700}, {300, 300}, {1, 500}};
  for (const auto& size : sizes) {
    const int w = size[0], h = size[1];
    for (const uint32_t per_mille : {0u, 1u, 10u, 300u}) {
      std::vector<uint8_t> seeds(static_cast<size_t>(w) * h, 0);
      for (uint8_t& s : seeds) s = next() % 1000 < per_mille ? 1 : 0;
      if (per_mille == 0u) seeds[static_cast<size_t>(h / 2) * w] = 1;  // one, at x = 0
      const std::vector<float> squared = squaredDistanceTransform(seeds, w, h);
      std::vector<uint8_t> grid = seeds;
      saturatedDistanceTransform(&grid, w, h, &scratch);
      size_t differ = 0, saturated = 0;
      for (size_t i = 0; i < grid.size(); ++i) {
        const float expected = std::min(255.0f, std::floor(std::sqrt(squared[i])));
        differ += grid[i] != static_cast<uint8_t>(expected);
        saturated += grid[i] == 255;
      }
      EXPECT_EQ(differ, 0u) << w << " x " << h << ", " << per_mille << " per mille";
      if (per_mille == 0u && std::max(w, h) >= 700) {
        EXPECT_GT(saturated, 0u) << w << " x " << h;
      }
    }
  }
}

}  // namespace
}  // namespace evidential_slam
