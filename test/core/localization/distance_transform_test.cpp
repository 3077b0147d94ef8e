// The exact Euclidean distance transform (core/localization) against hand-computed distances.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace evidential_slam
