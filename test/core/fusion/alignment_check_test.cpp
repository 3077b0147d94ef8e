// Tests of the disagreement beyond registration error (core/fusion/alignment_check.h).
#include <gtest/gtest.h>

#include "evidential_slam/core/fusion/alignment_check.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kRes = 0.05;

// A 20 x 20 patch of cells, all free with m̃(e) = 0.9.
EvidentialGridMap freePatch() {
  EvidentialGridMap map(kRes);
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) map.mutableCell(x, y).setMasses(0.0f, 0.9f);
  }
  return map;
}

// `map` with a wall of m̃(o) = 0.8 from cell (x, y0) to (x, y1).
void addWall(EvidentialGridMap* map, int x, int y0, int y1) {
  for (int y = y0; y <= y1; ++y) map->mutableCell(x, y).setMasses(0.8f, 0.0f);
}

// B's wall of 3 cells in A's open space. Structure: the end cells have one occupied neighbour
// (0.8 · 0.8), the middle one two (0.8 · 1); each meets A's free 0.9. A has no occupied evidence,
// and B's free cells near its wall are not free away from walls (ẽ = 0 there).
TEST(DisagreementTest, AWallInTheOtherMapsOpenSpace) {
  const EvidentialGridMap a = freePatch();
  EvidentialGridMap b = freePatch();
  addWall(&b, 10, 9, 11);
  const Disagreement d = disagreement(a, b, Pose2(), 0.1);
  const double structure = 2 * 0.8 * 0.8 + 0.8;
  EXPECT_NEAR(d.contradicted, structure * 0.9, 1e-6);
  EXPECT_NEAR(d.occupied, structure, 1e-6);
  EXPECT_NEAR(d.share(), 0.9, 1e-6);
  EXPECT_EQ(d.overlap, 400u);
}

// A lone hit is no structure: it contradicts nothing.
TEST(DisagreementTest, ALoneHitIsNoStructure) {
  const EvidentialGridMap a = freePatch();
  EvidentialGridMap b = freePatch();
  b.mutableCell(10, 10).setMasses(0.8f, 0.0f);
  const Disagreement d = disagreement(a, b, Pose2(), 0.1);
  EXPECT_EQ(d.contradicted, 0.0);
  EXPECT_EQ(d.occupied, 0.0);
}

// A's wall two cells away: within the 0.1 m tolerance neither map's free evidence counts there.
TEST(DisagreementTest, AWallWithinTheToleranceIsNoDisagreement) {
  EvidentialGridMap a = freePatch(), b = freePatch();
  addWall(&a, 12, 9, 11);
  addWall(&b, 10, 9, 11);
  EXPECT_NEAR(disagreement(a, b, Pose2(), 0.1).contradicted, 0.0, 1e-9);
  // Three cells away it is beyond a 0.1 m tolerance: both walls stand in the other's open space.
  EvidentialGridMap c = freePatch();
  addWall(&c, 13, 9, 11);
  EXPECT_NEAR(disagreement(c, b, Pose2(), 0.1).contradicted, 2 * (2 * 0.8 * 0.8 + 0.8) * 0.9,
              1e-6);
}

// The pose places B: B shifted by 5 cells onto A's wall agrees with it.
TEST(DisagreementTest, ThePosePlacesTheMovingMap) {
  EvidentialGridMap a = freePatch(), b = freePatch();
  addWall(&a, 15, 9, 11);
  addWall(&b, 10, 9, 11);
  EXPECT_GT(disagreement(a, b, Pose2(), 0.1).contradicted, 1.0);
  EXPECT_NEAR(disagreement(a, b, Pose2(5 * kRes, 0.0, 0.0), 0.1).contradicted, 0.0, 1e-9);
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
