// Shared helpers of the core tests that build cells, maps and scan masses by hand.
#pragma once

#include <cmath>
#include <cstddef>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/mass.h"

namespace evidential_slam {
namespace testing_cells {

// A cell holding normalised masses m̃(o), m̃(e) and the conflict exponent λ as stored.
inline Cell storedCell(float occupied, float free, float lambda = 0.0f) {
  return Cell::fromStored(occupied, free, lambda);
}

// A cell with normalised masses m̃(o), m̃(e) and raw conflict m(∅) (λ = -ln(1 - m(∅))).
inline Cell cellWithConflict(double occupied_n, double free_n, double conflict) {
  return Cell::fromStored(static_cast<float>(occupied_n), static_cast<float>(free_n),
                          static_cast<float>(-std::log(1.0 - conflict)));
}

// A map of 0.05 m cells whose cells (x, y) for x, y in [-10, 10] hold `c`.
inline EvidentialGridMap filledMap(const Cell& c) {
  EvidentialGridMap map(0.05);
  for (int y = -10; y <= 10; ++y) {
    for (int x = -10; x <= 10; ++x) map.mutableCell(x, y) = c;
  }
  return map;
}

// A scan's simple-support masses s(o), s(e) of one cell.
inline ScanMass scanMass(float occupied, float free) {
  ScanMass m;
  m.occupied = occupied;
  m.free = free;
  return m;
}

// True when `a` and `b` hold the same tiles with the same cells.
inline bool sameCells(const EvidentialGridMap& a, const EvidentialGridMap& b) {
  if (a.allocatedTiles() != b.allocatedTiles()) return false;
  bool same = true;
  a.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
    const EvidentialGridMap::Tile* other = b.tile(tx, ty);
    if (other == nullptr || !(other->cells == tile.cells)) same = false;
  });
  return same;
}

// The number of `a`'s tiles that `b` shares (the same copy-on-write tile, not a copy).
inline size_t sharedTiles(const EvidentialGridMap& a, const EvidentialGridMap& b) {
  size_t shared = 0;
  a.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
    if (b.tile(tx, ty) == &tile) ++shared;
  });
  return shared;
}

}  // namespace testing_cells
}  // namespace evidential_slam
