// The raw access a lossless map file needs (mass.h, evidential_grid.h): a cell's stored bits and
// Cell::fromBits, which takes back exactly the bits a cell can hold; forEachTile's order; and
// reserveTiles, which re-indexes without losing or allocating tiles.
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/mass.h"

namespace evidential_slam {
namespace {

// Bits of hand-computed cells: m̃(o) = 0.5 is 2^22 steps, m̃(e) = 0.25 is 2^21, λ = 1 is half
// 0x3C00; the vacuous cell is all zeros.
TEST(CellBitsTest, StoredBits) {
  const Cell c = Cell::fromStored(0.5f, 0.25f, 1.0f);
  EXPECT_EQ(c.occupiedSteps(), 1u << 22);
  EXPECT_EQ(c.freeSteps(), 1u << 21);
  EXPECT_EQ(c.lambdaBits(), 0x3C00);
  const Cell v;
  EXPECT_EQ(v.occupiedSteps(), 0u);
  EXPECT_EQ(v.freeSteps(), 0u);
  EXPECT_EQ(v.lambdaBits(), 0);
  EXPECT_EQ(Cell::fromStored(0.0f, 0.0f, 1e9f).lambdaBits(), Cell::kMaxLambdaBits);  // capped
}

// Every cell a run of updates makes comes back from its bits as the same cell.
TEST(CellBitsTest, FromBitsRoundTrips) {
  Cell c;
  const std::vector<ScanMass> scans = {{0.63f, 0.0f}, {0.0f, 0.8f}, {0.3f, 0.3f}, {0.0f, 0.2f}};
  for (int i = 0; i < 400; ++i) {
    updateCell(c, scans[static_cast<size_t>(i) % scans.size()]);
    Cell back = Cell::fromStored(0.1f, 0.1f, 0.1f);
    ASSERT_TRUE(Cell::fromBits(c.occupiedSteps(), c.freeSteps(), c.lambdaBits(), &back)) << i;
    EXPECT_TRUE(back == c) << i;
    EXPECT_EQ(back.lambda(), c.lambda());
    EXPECT_EQ(back.oneMinusConflict(), c.oneMinusConflict());
  }
  EXPECT_TRUE(c.conflicted());
}

// Bits no cell holds are refused and leave the output as it was; the extremes are taken.
TEST(CellBitsTest, FromBitsRefusesWhatNoCellHolds) {
  const Cell before = Cell::fromStored(0.2f, 0.3f, 0.5f);
  const struct {
    uint32_t o, e;
    uint16_t l;
  } bad[] = {{Cell::kMassSteps + 1, 0, 0},
             {0, Cell::kMassSteps + 1, 0},
             {Cell::kMassSteps / 2, Cell::kMassSteps / 2 + 1, 0},
             {0, 0, 0x7C00},  // +inf
             {0, 0, 0x7E00},  // NaN
             {0, 0, 0x8000},  // -0
             {0, 0, 0xBC00},  // -1
             {0xFFFFFFFFu, 1, 0}};
  for (const auto& b : bad) {
    Cell out = before;
    EXPECT_FALSE(Cell::fromBits(b.o, b.e, b.l, &out)) << b.o << " " << b.e << " " << b.l;
    EXPECT_TRUE(out == before);
  }
  Cell out;
  ASSERT_TRUE(Cell::fromBits(Cell::kMassSteps, 0, Cell::kMaxLambdaBits, &out));
  EXPECT_EQ(out.occupied(), 1.0f);
  EXPECT_EQ(out.lambda(), 65504.0f);
  ASSERT_TRUE(Cell::fromBits(Cell::kMassSteps / 4, Cell::kMassSteps * 3 / 4, 1, &out));
  EXPECT_EQ(out.unknown(), 0.0f);
  EXPECT_GT(out.lambda(), 0.0f);  // the smallest subnormal half
}

std::vector<std::pair<int, int>> tilesOf(const EvidentialGridMap& map) {
  std::vector<std::pair<int, int>> tiles;
  map.forEachTile(
      [&](int tx, int ty, const EvidentialGridMap::Tile&) { tiles.emplace_back(tx, ty); });
  return tiles;
}

// forEachTile visits the allocated tiles by rows from the lowest y, each from the lowest x.
TEST(CellBitsTest, ForEachTileOrder) {
  EvidentialGridMap map(0.05);
  EXPECT_TRUE(tilesOf(map).empty());
  map.mutableCell(100, 5);   // tile (3, 0)
  map.mutableCell(-1, -1);   // tile (-1, -1)
  map.mutableCell(-64, 40);  // tile (-2, 1)
  map.mutableCell(0, 0);     // tile (0, 0)
  const std::vector<std::pair<int, int>> expected = {{-1, -1}, {0, 0}, {3, 0}, {-2, 1}};
  EXPECT_EQ(tilesOf(map), expected);
}

// reserveTiles re-indexes the map: the tiles and their cells stay, none is allocated, and tiles
// inside or outside the reserved box are written as before.
TEST(CellBitsTest, ReserveTilesKeepsTheMap) {
  EvidentialGridMap map(0.05);
  updateCell(map.mutableCell(5, 5), ScanMass{0.63f, 0.0f});
  const EvidentialGridMap::Tile* tile = map.tile(0, 0);
  map.reserveTiles(-100, -3, 50, 200);
  EXPECT_EQ(map.allocatedTiles(), 1u);
  EXPECT_EQ(map.tile(0, 0), tile);
  EXPECT_NEAR(map.cell(5, 5).occupied(), 0.63f, 1e-6f);
  map.reserveTiles(3, 3, 2, 2);  // an empty box: nothing to do
  EXPECT_EQ(map.tile(0, 0), tile);
  updateCell(map.mutableCell(-100 * 32, 200 * 32), ScanMass{0.0f, 0.8f});
  updateCell(map.mutableCell(60 * 32, 0), ScanMass{0.0f, 0.8f});
  EXPECT_EQ(map.allocatedTiles(), 3u);
  const std::vector<std::pair<int, int>> expected = {{0, 0}, {60, 0}, {-100, 200}};
  EXPECT_EQ(tilesOf(map), expected);

  EvidentialGridMap fresh(0.05);
  fresh.reserveTiles(-2, -2, 2, 2);
  EXPECT_EQ(fresh.allocatedTiles(), 0u);
  EXPECT_TRUE(fresh.allocatedBox().empty());
}

}  // namespace
}  // namespace evidential_slam
