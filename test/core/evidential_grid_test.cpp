// Tests of the growing, tile-sharing evidential grid (evidential_grid.h): vacuous default,
// coordinates, growth in every direction, copy-on-write between copies, boxes and memory counting.
// Tiles are 32 x 32 cells (kTileBits = 5): tile t covers cells [32 t, 32 t + 31].
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>
#include <unordered_set>

#include "evidential_slam/core/evidential_grid.h"
#include "cell_support.h"

namespace evidential_slam {
namespace {

using namespace testing_cells;

// The values a cell stores for these (the storage is quantised).
void expectCell(const Cell& c, float occupied, float free, float lambda) {
  const Cell stored = storedCell(occupied, free, lambda);
  EXPECT_EQ(c.occupied(), stored.occupied());
  EXPECT_EQ(c.free(), stored.free());
  EXPECT_EQ(c.lambda(), stored.lambda());
}

// The stored value of a mass m.
float stored(float m) { return Cell::fromStored(m, 0.0f, 0.0f).occupied(); }

void setOccupied(Cell& c, float m) { c.setMasses(m, c.free()); }
void setFree(Cell& c, float m) { c.setMasses(c.occupied(), m); }

void expectVacuous(const Cell& c) {
  expectCell(c, 0.0f, 0.0f, 0.0f);
  EXPECT_FALSE(c.observed());
}

// Fresh grid: every cell, anywhere (including negative indices), reads vacuous; nothing allocated.
TEST(EvidentialGridTest, FreshGridIsVacuous) {
  const EvidentialGridMap g(0.05);
  EXPECT_DOUBLE_EQ(g.resolution(), 0.05);
  expectVacuous(g.cell(0, 0));
  expectVacuous(g.cell(-1, -1));
  expectVacuous(g.cell(123456, -98765));
  expectVacuous(g.cell(CellIndex{7, 3}));
  EXPECT_TRUE(g.allocatedBox().empty());
  EXPECT_TRUE(g.observedBox().empty());
  EXPECT_EQ(g.allocatedTiles(), 0u);
}

// Cell (i, j) covers [i res, (i+1) res): at res 0.05, x = 0.051 -> 1, 0.049 -> 0, -0.001 -> -1,
// -0.049 -> -1, -0.051 -> -2 (floor, not truncation). Centre of (-1, 1) = (-0.025, 0.075).
TEST(EvidentialGridTest, WorldToCellAndCellCenter) {
  const EvidentialGridMap g(0.05);
  EXPECT_EQ(g.worldToCell(0.051, 0.049), (CellIndex{1, 0}));
  EXPECT_EQ(g.worldToCell(-0.001, -0.049), (CellIndex{-1, -1}));
  EXPECT_EQ(g.worldToCell(-0.051, 0.0001), (CellIndex{-2, 0}));
  EXPECT_EQ(g.worldToCell(500.01, -500.01), (CellIndex{10000, -10001}));
  const Eigen::Vector2d c = g.cellCenter(CellIndex{-1, 1});
  EXPECT_NEAR(c.x(), -0.025, 1e-12);
  EXPECT_NEAR(c.y(), 0.075, 1e-12);
  const Eigen::Vector2d d = g.cellCenter(g.worldToCell(3.01, -2.01));  // cell (60, -41)
  EXPECT_NEAR(d.x(), 3.025, 1e-12);
  EXPECT_NEAR(d.y(), -2.025, 1e-12);
  // Another resolution: 0.1 m, x = 0.25 -> 2, y = -0.25 -> -3.
  const EvidentialGridMap h(0.1);
  EXPECT_EQ(h.worldToCell(0.25, -0.25), (CellIndex{2, -3}));
}

// Writes through mutableCell persist and do not touch neighbours.
TEST(EvidentialGridTest, MutableCellWritesPersist) {
  EvidentialGridMap g(0.05);
  g.mutableCell(3, 4) = storedCell(0.5f, 0.25f, 0.125f);
  g.mutableCell(-3, -4) = storedCell(0.75f, 0.0f, 1.0f);
  expectCell(g.cell(3, 4), 0.5f, 0.25f, 0.125f);
  expectCell(g.cell(CellIndex{3, 4}), 0.5f, 0.25f, 0.125f);
  expectCell(g.cell(-3, -4), 0.75f, 0.0f, 1.0f);
  expectVacuous(g.cell(4, 4));
  expectVacuous(g.cell(3, 5));
  expectVacuous(g.cell(-4, -4));
  // Modify in place through the returned reference.
  g.mutableCell(3, 4).setLambda(2.0f);
  expectCell(g.cell(3, 4), 0.5f, 0.25f, 2.0f);
}

// The grid grows towards negative and positive coordinates (±500 m = ±10000 cells at 0.05 m)
// without losing what was written before; cells in between stay vacuous.
TEST(EvidentialGridTest, GrowsInAllDirectionsKeepingCells) {
  EvidentialGridMap g(0.05);
  g.mutableCell(0, 0) = storedCell(0.1f, 0.2f, 0.0f);
  g.mutableCell(31, 31) = storedCell(0.3f, 0.0f, 0.0f);
  g.mutableCell(-10000, -10000) = storedCell(0.4f, 0.1f, 0.5f);
  expectCell(g.cell(0, 0), 0.1f, 0.2f, 0.0f);
  g.mutableCell(10000, 10000) = storedCell(0.6f, 0.2f, 1.5f);
  g.mutableCell(-10000, 10000) = storedCell(0.7f, 0.0f, 0.0f);
  g.mutableCell(10000, -10000) = storedCell(0.0f, 0.9f, 0.0f);
  const CellIndex far = g.worldToCell(-500.0 + 1e-6, 499.99);
  setFree(g.mutableCell(far.x, far.y), 0.5f);

  expectCell(g.cell(0, 0), 0.1f, 0.2f, 0.0f);
  expectCell(g.cell(31, 31), 0.3f, 0.0f, 0.0f);
  expectCell(g.cell(-10000, -10000), 0.4f, 0.1f, 0.5f);
  expectCell(g.cell(10000, 10000), 0.6f, 0.2f, 1.5f);
  expectCell(g.cell(-10000, 10000), 0.7f, 0.0f, 0.0f);
  expectCell(g.cell(10000, -10000), 0.0f, 0.9f, 0.0f);
  EXPECT_EQ(g.cell(far).free(), stored(0.5f));
  expectVacuous(g.cell(5000, -5000));
  expectVacuous(g.cell(-1, -1));
  expectVacuous(g.cell(10001, 10000));

  const CellBox box = g.observedBox();
  EXPECT_EQ(box.min_x, -10000);
  EXPECT_EQ(box.max_x, 10000);
  EXPECT_EQ(box.min_y, -10000);
  EXPECT_EQ(box.max_y, 10000);
}

// Growth one tile at a time in each direction (the resize paths), checking earlier cells each time.
TEST(EvidentialGridTest, StepwiseGrowthKeepsCells) {
  EvidentialGridMap g(0.05);
  for (int k = 0; k < 20; ++k) {
    const int d = 37 * k;
    g.mutableCell(d, -d) = storedCell(0.01f * k, 0.0f, 0.0f);
    g.mutableCell(-d - 1, d + 1) = storedCell(0.0f, 0.01f * k, 0.0f);
    for (int j = 0; j <= k; ++j) {
      const int e = 37 * j;
      EXPECT_EQ(g.cell(e, -e).occupied(), stored(0.01f * j)) << "k=" << k << " j=" << j;
      EXPECT_EQ(g.cell(-e - 1, e + 1).free(), stored(0.01f * j)) << "k=" << k << " j=" << j;
    }
  }
}

// allocatedBox is the box of whole tiles: a write to (0,0) allocates tile (0,0) = cells [0,31]^2;
// a further write to (-1, 40) adds tile (-1, 1) = x [-32,-1], y [32,63]; their bounding box is
// x [-32, 31], y [0, 63]. observedBox is tight around the two written cells: x [-1,0], y [0,40].
TEST(EvidentialGridTest, AllocatedAndObservedBoxes) {
  EvidentialGridMap g(0.05);
  g.mutableCell(0, 0) = storedCell(0.5f, 0.0f, 0.0f);
  CellBox a = g.allocatedBox();
  EXPECT_EQ(a.min_x, 0);
  EXPECT_EQ(a.max_x, 31);
  EXPECT_EQ(a.min_y, 0);
  EXPECT_EQ(a.max_y, 31);
  EXPECT_EQ(a.width(), 32);
  EXPECT_EQ(g.allocatedTiles(), 1u);

  g.mutableCell(-1, 40) = storedCell(0.0f, 0.5f, 0.0f);
  a = g.allocatedBox();
  EXPECT_EQ(a.min_x, -32);
  EXPECT_EQ(a.max_x, 31);
  EXPECT_EQ(a.min_y, 0);
  EXPECT_EQ(a.max_y, 63);
  EXPECT_EQ(g.allocatedTiles(), 2u);

  const CellBox o = g.observedBox();
  EXPECT_EQ(o.min_x, -1);
  EXPECT_EQ(o.max_x, 0);
  EXPECT_EQ(o.min_y, 0);
  EXPECT_EQ(o.max_y, 40);
  EXPECT_EQ(o.width(), 2);
  EXPECT_EQ(o.height(), 41);
}

// observedBox passes over tiles inside the box found so far: on scattered observed cells over
// many tiles (the box widening row after row, interior tiles among them) it equals the box of
// every observed cell.
TEST(EvidentialGridTest, ObservedBoxEqualsTheBoxOfEveryObservedCell) {
  EvidentialGridMap g(0.05);
  uint64_t state = 7;
  const auto next = [&](int range) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((state >> 33) % static_cast<uint64_t>(range));
  };
  CellBox expected;
  for (int i = 0; i < 400; ++i) {
    const int x = next(600) - 300, y = next(500) - 200;
    g.mutableCell(x, y) = storedCell(0.2f, 0.1f, 0.0f);
    expected.extend(CellBox{x, y, x, y});
    const CellBox o = g.observedBox();
    ASSERT_EQ(o.min_x, expected.min_x) << i;
    ASSERT_EQ(o.max_x, expected.max_x) << i;
    ASSERT_EQ(o.min_y, expected.min_y) << i;
    ASSERT_EQ(o.max_y, expected.max_y) << i;
  }
}

// mutableCell without writing allocates but does not observe: a cell that only got a lambda
// counts as observed (EC is evidence), a merely touched cell does not.
TEST(EvidentialGridTest, ObservedBoxIgnoresTouchedVacuousCells) {
  EvidentialGridMap g(0.05);
  g.mutableCell(5, 6) = storedCell(0.2f, 0.0f, 0.0f);
  g.mutableCell(200, 300);  // allocate only
  CellBox o = g.observedBox();
  EXPECT_EQ(o.min_x, 5);
  EXPECT_EQ(o.max_x, 5);
  EXPECT_EQ(o.min_y, 6);
  EXPECT_EQ(o.max_y, 6);
  g.mutableCell(-7, 2).setLambda(0.5f);
  o = g.observedBox();
  EXPECT_EQ(o.min_x, -7);
  EXPECT_EQ(o.max_x, 5);
  EXPECT_EQ(o.min_y, 2);
  EXPECT_EQ(o.max_y, 6);
}

// CellBox helpers: empty box has width/height 0; extend gives the union.
TEST(CellBoxTest, ExtendAndSize) {
  CellBox b;
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(b.width(), 0);
  CellBox c{2, 3, 4, 8};  // x [2,4], y [3,8]
  EXPECT_EQ(c.width(), 3);
  EXPECT_EQ(c.height(), 6);
  b.extend(c);  // extending an empty box gives the other box
  EXPECT_EQ(b.min_x, 2);
  EXPECT_EQ(b.min_y, 3);
  EXPECT_EQ(b.max_x, 4);
  EXPECT_EQ(b.max_y, 8);
  b.extend(CellBox{-1, 5, 0, 10});
  EXPECT_EQ(b.min_x, -1);
  EXPECT_EQ(b.min_y, 3);
  EXPECT_EQ(b.max_x, 4);
  EXPECT_EQ(b.max_y, 10);
  b.extend(CellBox{});  // extending by an empty box changes nothing
  EXPECT_EQ(b.min_x, -1);
  EXPECT_EQ(b.max_y, 10);
}

// Copy-on-write: after `b = a` (copy construction), a write to b leaves a unchanged, and a write
// to a leaves b unchanged; unwritten cells of the shared tile stay equal in both.
TEST(EvidentialGridTest, CopyOnWriteCopyConstruction) {
  EvidentialGridMap a(0.05);
  a.mutableCell(1, 1) = storedCell(0.5f, 0.0f, 0.0f);
  a.mutableCell(2, 1) = storedCell(0.0f, 0.5f, 0.0f);
  a.mutableCell(-40, 70) = storedCell(0.25f, 0.25f, 0.0f);

  EvidentialGridMap b = a;
  expectCell(b.cell(1, 1), 0.5f, 0.0f, 0.0f);
  expectCell(b.cell(-40, 70), 0.25f, 0.25f, 0.0f);

  b.mutableCell(1, 1) = storedCell(0.9f, 0.0f, 3.0f);  // same tile as (2,1), shared
  expectCell(a.cell(1, 1), 0.5f, 0.0f, 0.0f);        // a unchanged
  expectCell(b.cell(1, 1), 0.9f, 0.0f, 3.0f);
  expectCell(b.cell(2, 1), 0.0f, 0.5f, 0.0f);  // the clone kept the rest of the tile
  expectCell(a.cell(2, 1), 0.0f, 0.5f, 0.0f);

  a.mutableCell(-40, 70) = storedCell(0.0f, 1.0f, 0.0f);  // vice versa, on another shared tile
  expectCell(b.cell(-40, 70), 0.25f, 0.25f, 0.0f);      // b unchanged
  expectCell(a.cell(-40, 70), 0.0f, 1.0f, 0.0f);

  a.mutableCell(2, 1).setLambda(7.0f);  // a's first write to tile (0,0) after b cloned it
  EXPECT_EQ(b.cell(2, 1).lambda(), 0.0f);
  EXPECT_EQ(b.cell(1, 1).occupied(), stored(0.9f));
  EXPECT_EQ(a.cell(1, 1).occupied(), stored(0.5f));
}

// A grid writes a tile in place once the other grids that shared it are gone. Another thread's
// reads of the tile, made before it released its share, must be ordered before that write; the
// threads here share nothing else that orders them (the flag is relaxed), so under ThreadSanitizer
// a missing order is reported as a data race on the cell.
TEST(EvidentialGridTest, InPlaceWriteIsOrderedAfterAnotherThreadsRelease) {
  EvidentialGridMap a(0.05);
  a.mutableCell(1, 1) = storedCell(0.5f, 0.0f, 0.0f);
  auto sharer = std::make_unique<EvidentialGridMap>(a);
  std::atomic<bool> released{false};
  float read_by_sharer = -1.0f;
  std::thread other([&] {
    read_by_sharer = sharer->cell(1, 1).occupied();
    sharer.reset();
    released.store(true, std::memory_order_relaxed);
  });
  while (!released.load(std::memory_order_relaxed)) std::this_thread::yield();
  const EvidentialGridMap::Tile* before = a.tile(0, 0);
  a.mutableCell(1, 1) = storedCell(0.9f, 0.0f, 0.0f);
  EXPECT_EQ(a.tile(0, 0), before);  // a owned the tile alone: no clone
  other.join();
  EXPECT_EQ(read_by_sharer, stored(0.5f));
  EXPECT_EQ(a.cell(1, 1).occupied(), stored(0.9f));
}

// Copy-on-write with copy assignment into an existing grid, with growth after the copy, and among
// three "particles" sharing one map: a write by one never shows up in the others.
TEST(EvidentialGridTest, CopyOnWriteAssignmentGrowthAndThreeParticles) {
  EvidentialGridMap a(0.05);
  a.mutableCell(0, 0) = storedCell(0.5f, 0.0f, 0.0f);
  EvidentialGridMap b(0.05);
  b.mutableCell(100, 100) = storedCell(0.1f, 0.1f, 0.1f);
  b = a;
  expectCell(b.cell(0, 0), 0.5f, 0.0f, 0.0f);
  expectVacuous(b.cell(100, 100));  // b's old content is gone

  EvidentialGridMap c = b;
  // b grows far away (the tile array is re-laid out) and writes into the shared tile.
  b.mutableCell(-3000, 2500) = storedCell(0.3f, 0.3f, 0.3f);
  setOccupied(b.mutableCell(0, 0), 0.8f);
  expectCell(a.cell(0, 0), 0.5f, 0.0f, 0.0f);
  expectCell(c.cell(0, 0), 0.5f, 0.0f, 0.0f);
  expectVacuous(a.cell(-3000, 2500));
  expectVacuous(c.cell(-3000, 2500));
  EXPECT_EQ(b.cell(0, 0).occupied(), stored(0.8f));
  expectCell(b.cell(-3000, 2500), 0.3f, 0.3f, 0.3f);

  // c writes its copy; a and b keep theirs.
  setFree(c.mutableCell(0, 0), 0.4f);
  EXPECT_EQ(a.cell(0, 0).free(), 0.0f);
  EXPECT_EQ(b.cell(0, 0).free(), 0.0f);
  EXPECT_EQ(c.cell(0, 0).free(), stored(0.4f));
  EXPECT_EQ(c.cell(0, 0).occupied(), stored(0.5f));
}

// accumulateUniqueTileBytes counts each distinct tile once: with per-tile size P (measured on a
// one-tile grid, at least sizeof(Tile)), a 3-tile grid is 3P, an unmodified copy adds 0, and a
// copy that wrote one tile adds exactly one cloned tile, P.
TEST(EvidentialGridTest, AccumulateUniqueTileBytesCountsSharedTilesOnce) {
  EvidentialGridMap one(0.05);
  setOccupied(one.mutableCell(0, 0), 0.5f);
  std::unordered_set<const EvidentialGridMap::Tile*> seen_one;
  const size_t per_tile = one.accumulateUniqueTileBytes(&seen_one);
  EXPECT_GE(per_tile, sizeof(EvidentialGridMap::Tile));
  EXPECT_EQ(one.accumulateUniqueTileBytes(&seen_one), 0u);  // already seen

  EvidentialGridMap a(0.05);
  setOccupied(a.mutableCell(0, 0), 0.5f);    // tile (0,0)
  setOccupied(a.mutableCell(40, 0), 0.5f);   // tile (1,0)
  setOccupied(a.mutableCell(-5, -5), 0.5f);  // tile (-1,-1)
  EXPECT_EQ(a.allocatedTiles(), 3u);
  EvidentialGridMap b = a;
  EvidentialGridMap c = a;
  EXPECT_EQ(b.allocatedTiles(), 3u);

  std::unordered_set<const EvidentialGridMap::Tile*> seen;
  EXPECT_EQ(a.accumulateUniqueTileBytes(&seen), 3 * per_tile);
  EXPECT_EQ(b.accumulateUniqueTileBytes(&seen), 0u);
  EXPECT_EQ(c.accumulateUniqueTileBytes(&seen), 0u);

  setFree(b.mutableCell(41, 1), 0.25f);  // clones tile (1,0) only
  std::unordered_set<const EvidentialGridMap::Tile*> seen2;
  EXPECT_EQ(a.accumulateUniqueTileBytes(&seen2), 3 * per_tile);
  EXPECT_EQ(b.accumulateUniqueTileBytes(&seen2), per_tile);
  EXPECT_EQ(c.accumulateUniqueTileBytes(&seen2), 0u);
  EXPECT_EQ(seen2.size(), 4u);
}

// A tile's occupied rows: bit x of row y set exactly when the cell's m̃(o) ≥ the threshold; cached
// for the first threshold (another threshold is answered in the caller's scratch), dropped by a
// write, and not carried into the clone a shared tile gets on its first write.
TEST(EvidentialGridTest, OccupiedRowsFollowTheCells) {
  using Rows = EvidentialGridMap::Tile::Rows;
  const auto expectRows = [](const EvidentialGridMap& map, int tx, int ty, float threshold) {
    Rows scratch{};
    const Rows& rows = map.tile(tx, ty)->occupiedRows(threshold, &scratch);
    for (int y = 0; y < EvidentialGridMap::kTileSize; ++y) {
      for (int x = 0; x < EvidentialGridMap::kTileSize; ++x) {
        const Cell& c =
            map.cell(tx * EvidentialGridMap::kTileSize + x, ty * EvidentialGridMap::kTileSize + y);
        EXPECT_EQ((rows[static_cast<size_t>(y)] >> x) & 1u, c.occupied() >= threshold ? 1u : 0u)
            << tx << " " << ty << " " << x << " " << y << " " << threshold;
      }
    }
    return &rows == &scratch;
  };
  EvidentialGridMap a(0.05);
  setOccupied(a.mutableCell(-32, -1), 0.25f);  // tile (-1, -1): cell (0, 31)
  setOccupied(a.mutableCell(-1, -32), 0.9f);   // cell (31, 0)
  setOccupied(a.mutableCell(-10, -10), 0.2f);  // below 0.25
  setFree(a.mutableCell(-11, -10), 1.0f);
  EXPECT_FALSE(expectRows(a, -1, -1, 0.25f));  // built into the tile's cache
  EXPECT_FALSE(expectRows(a, -1, -1, 0.25f));  // read from it
  EXPECT_TRUE(expectRows(a, -1, -1, 0.1f));    // another threshold: the scratch

  EvidentialGridMap b = a;                     // shares the tile and its cache
  setOccupied(b.mutableCell(-10, -10), 0.5f);  // b's clone gets the cell ...
  EXPECT_FALSE(expectRows(b, -1, -1, 0.25f));  // ... and rows built afresh
  EXPECT_FALSE(expectRows(a, -1, -1, 0.25f));  // a's cache is still right: a did not change
  Rows scratch{};
  EXPECT_EQ(a.tile(-1, -1)->occupiedRows(0.25f, &scratch)[22], 0u);
  EXPECT_EQ(b.tile(-1, -1)->occupiedRows(0.25f, &scratch)[22], 1u << 22);

  setOccupied(a.mutableCell(-31, -31), 0.3f);  // a write in place drops a's cache
  EXPECT_FALSE(expectRows(a, -1, -1, 0.25f));
  EXPECT_EQ(a.tile(-1, -1)->occupiedRows(0.25f, &scratch)[1], 1u << 1);
}

// A tile's may-hold-occupied bits: clear on a new tile, following m̃(o) > 0 through cellWritten,
// copied into a clone, and set (conservatively) by mutableCell, whose caller writes afterwards.
TEST(EvidentialGridTest, MayHoldOccupiedBitsFollowWrittenCells) {
  EvidentialGridMap a(0.05);
  EvidentialGridMap::Tile& tile = a.mutableTile(0, 0);
  for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) EXPECT_FALSE(tile.mayHoldOccupied(k));
  tile.cells[5] = Cell::fromStored(0.3f, 0.2f, 0.0f);
  tile.cellWritten(5);
  tile.cells[40] = Cell::fromStored(1e-6f, 0.9f, 1.0f);
  tile.cellWritten(40);
  tile.cells[41] = Cell::fromStored(0.0f, 0.9f, 1.0f);  // conflict but no m̃(o)
  tile.cellWritten(41);
  EXPECT_TRUE(tile.mayHoldOccupied(5));
  EXPECT_TRUE(tile.mayHoldOccupied(40));
  EXPECT_FALSE(tile.mayHoldOccupied(41));
  tile.cells[5] = Cell::fromStored(0.0f, 0.9f, 0.0f);  // the occupied mass is gone
  tile.cellWritten(5);
  EXPECT_FALSE(tile.mayHoldOccupied(5));

  EvidentialGridMap b = a;
  EvidentialGridMap::Tile& clone = b.mutableTile(0, 0);
  ASSERT_NE(&clone, &tile);
  EXPECT_TRUE(clone.mayHoldOccupied(40));
  EXPECT_FALSE(clone.mayHoldOccupied(5));

  a.mutableCell(7, 0);  // vacuous still, but its caller may write any mass
  EXPECT_TRUE(a.tile(0, 0)->mayHoldOccupied(7));
  EXPECT_FALSE(b.tile(0, 0)->mayHoldOccupied(7));
}

// A tile's two bitmaps take memory only once one of their bits is set: none on a tile of free
// cells, the may-hold-occupied bits at its first m̃(o) > 0, the occupied rows when built with a
// cell at the threshold or when a write later puts one there. A clone copies what is allocated.
TEST(EvidentialGridTest, TileBitmapsAreAllocatedAtTheirFirstSetBit) {
  using Rows = EvidentialGridMap::Tile::Rows;
  constexpr float kThreshold = 0.25f;
  EvidentialGridMap a(0.05);
  EvidentialGridMap::Tile& tile = a.mutableTile(0, 0);
  EXPECT_EQ(tile.bitmapBytes(), 0u);
  tile.cells[3] = Cell::fromStored(0.0f, 0.9f, 0.5f);  // free and conflicting: no m̃(o)
  tile.cellWritten(3);
  EXPECT_EQ(tile.bitmapBytes(), 0u);
  Rows scratch{};
  const Rows& none = tile.occupiedRows(kThreshold, &scratch);  // built: no cell at the threshold
  EXPECT_NE(&none, &scratch);
  for (const uint32_t word : none) EXPECT_EQ(word, 0u);
  EXPECT_EQ(tile.bitmapBytes(), 0u);

  tile.cells[70] = Cell::fromStored(0.1f, 0.5f, 0.0f);  // m̃(o) > 0, below the threshold
  tile.cellWritten(70);
  EXPECT_EQ(tile.bitmapBytes(), sizeof(Rows));
  EXPECT_TRUE(tile.mayHoldOccupied(70));
  EXPECT_EQ(tile.occupiedRows(kThreshold, &scratch)[2], 0u);

  tile.cells[71] = Cell::fromStored(0.6f, 0.1f, 0.0f);  // at the threshold: the rows appear
  tile.cellWritten(71);
  EXPECT_EQ(tile.bitmapBytes(), 2 * sizeof(Rows));
  const Rows& rows = tile.occupiedRows(kThreshold, &scratch);
  EXPECT_NE(&rows, &scratch);
  EXPECT_EQ(rows[2], 1u << 7);

  EvidentialGridMap b = a;
  const EvidentialGridMap::Tile& clone = b.mutableTile(0, 0);
  ASSERT_NE(&clone, &tile);
  EXPECT_EQ(clone.bitmapBytes(), 2 * sizeof(Rows));
  EXPECT_EQ(clone.occupiedRows(kThreshold, &scratch)[2], 1u << 7);

  // A tile built before any bit is set, cloned: nothing allocated in either.
  EvidentialGridMap c(0.05);
  c.mutableTile(5, 5).cellWritten(0);
  EvidentialGridMap d = c;
  EXPECT_EQ(d.mutableTile(5, 5).bitmapBytes(), 0u);
  EXPECT_EQ(c.tile(5, 5)->bitmapBytes(), 0u);
}

}  // namespace
}  // namespace evidential_slam
