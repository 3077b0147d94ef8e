// An evidential occupancy grid that grows with the explored area and shares its tiles between
// particles: copying a grid copies tile pointers only, and a tile is cloned the first time a grid
// that shares it writes to it (copy-on-write, in the spirit of GMapping's harray2d patches).
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/mass.h"
#include "evidential_slam/core/sole_owner.h"

namespace evidential_slam {

// Integer cell coordinates; cell (i, j) covers [i*res, (i+1)*res) x [j*res, (j+1)*res) in the map
// frame.
struct CellIndex {
  int x = 0;
  int y = 0;
  bool operator==(const CellIndex& o) const { return x == o.x && y == o.y; }
};

// Inclusive cell-index box; empty when max < min.
struct CellBox {
  int min_x = 0, min_y = 0, max_x = -1, max_y = -1;
  bool empty() const { return max_x < min_x || max_y < min_y; }
  int width() const { return empty() ? 0 : max_x - min_x + 1; }
  int height() const { return empty() ? 0 : max_y - min_y + 1; }
  void extend(const CellBox& other);
};

class EvidentialGridMap {
 public:
  static constexpr int kTileBits = 5;
  static constexpr int kTileSize = 1 << kTileBits;  // cells per tile side
  static constexpr int kTileCells = kTileSize * kTileSize;
  class Tile {
   public:
    Tile() = default;
    // A clone copies the cells, their may-hold-occupied bits and, when built, the occupied rows.
    Tile(const Tile& other);
    Tile& operator=(const Tile&) = delete;

    std::array<Cell, kTileCells> cells{};

    // Two bitmaps per tile, a 32-bit word per row (bit x of word y is the cell at (x, y) in the
    // tile), each allocated only once a bit of it is set: most tiles hold no occupied mass at
    // all (open space), and a bitmap is 1.5 % of a tile.
    using Rows = std::array<uint32_t, kTileSize>;
    // The occupied rows: one bit per cell whose m̃(o) ≥ threshold. The scan matcher's
    // correspondence search scans rows of it instead of reading cells one by one. Built in the
    // tile on the first call (for the first threshold asked), so the particles sharing a tile
    // build it once, and kept through clones and map updates (cellWritten). Readers may call it
    // concurrently (a tile is never written while others read it: copy on write); a reader that
    // finds the rows being built, or built for another threshold, gets them built in `scratch`.
    const Rows& occupiedRows(float threshold, Rows* scratch) const;
    // One bit per cell whose m̃(o) may be above 0, always kept (a clear bit: the cell holds no
    // occupied mass). Far from a beam's measured range the forward model needs only a cell's
    // m̃(o), so it reads these bits instead of the cells where that is 0: most of the free space,
    // never hit.
    bool mayHoldOccupied(int k) const {
      const Rows* may = may_hold_occupied_.get();
      return may != nullptr &&
             (((*may)[static_cast<size_t>(k >> kTileBits)] >> (k & (kTileSize - 1))) & 1u) != 0;
    }
    // Whoever writes cells of a tile it owns (mutableTile) keeps the rows and bits true:
    // cellWritten(k) after writing cells[k]; after writing cells otherwise, dropOccupiedRows() and
    // markMayHoldOccupied(k) for each.
    void markMayHoldOccupied(int k) {
      setBit(&may_hold_occupied_, static_cast<size_t>(k >> kTileBits), k & (kTileSize - 1), true);
    }
    void cellWritten(int k) {
      const int x = k & (kTileSize - 1);
      const size_t y = static_cast<size_t>(k >> kTileBits);
      const Cell& cell = cells[static_cast<size_t>(k)];
      setBit(&may_hold_occupied_, y, x, cell.occupied() > 0.0f);
      if (rows_state_.load(std::memory_order_relaxed) != kRowsReady) return;
      setBit(&rows_, y, x, isTarget(cell, rows_threshold_));
    }
    // The rows' bit of a cell: m̃(o) at or above the threshold.
    static bool isTarget(const Cell& c, float threshold) { return c.occupied() >= threshold; }
    void dropOccupiedRows() {
      rows_state_.store(kRowsNone, std::memory_order_release);
      rows_.reset();
    }
    // Bytes of the bitmaps allocated (beside sizeof(Tile)).
    size_t bitmapBytes() const {
      return (may_hold_occupied_ ? sizeof(Rows) : 0) + (rows_ ? sizeof(Rows) : 0);
    }

   private:
    // Sets bit x of word y of *rows to `value`, allocating the (zeroed) bitmap for its first set
    // bit. (A word is stored only when its bit changes, which is rare: consecutive cells of a row
    // then do not wait for each other's store.)
    static void setBit(std::unique_ptr<Rows>* rows, size_t y, int x, bool value) {
      if (!*rows) {
        if (!value) return;
        *rows = std::make_unique<Rows>();
      }
      uint32_t& word = (**rows)[y];
      if ((((word >> x) & 1u) != 0) != value) word ^= 1u << x;
    }
    static std::unique_ptr<Rows> copyOf(const std::unique_ptr<Rows>& rows) {
      return rows ? std::make_unique<Rows>(*rows) : nullptr;
    }
    enum : int { kRowsNone = 0, kRowsBuilding = 1, kRowsReady = 2 };
    // Fills *rows; false when no bit is set.
    bool buildOccupiedRows(float threshold, Rows* rows) const;

    std::unique_ptr<Rows> may_hold_occupied_;  // null: no bit set
    mutable std::atomic<int> rows_state_{kRowsNone};
    mutable float rows_threshold_ = 0.0f;
    mutable std::unique_ptr<Rows> rows_;  // when ready, null: no cell at the threshold
    static const Rows kNoRows;
  };

  EvidentialGridMap() : EvidentialGridMap(0.05) {}
  explicit EvidentialGridMap(double resolution);

  double resolution() const { return resolution_; }
  CellIndex worldToCell(double x, double y) const {
    return {static_cast<int>(std::floor(x / resolution_)),
            static_cast<int>(std::floor(y / resolution_))};
  }
  Eigen::Vector2d cellCenter(const CellIndex& c) const;

  // The cell every unallocated position reads as (all masses on Θ).
  static const Cell& vacuousCell() { return kVacuousCell; }
  // Read access; cells outside the allocated area are vacuous.
  const Cell& cell(int cx, int cy) const {
    const int tx = (cx >> kTileBits) - tile_x0_;
    const int ty = (cy >> kTileBits) - tile_y0_;
    if (tx < 0 || ty < 0 || tx >= tiles_w_ || ty >= tiles_h_) return kVacuousCell;
    const Tile* t = tiles_[static_cast<size_t>(ty) * tiles_w_ + tx].get();
    if (t == nullptr) return kVacuousCell;
    return t->cells[cellInTile(cx, cy)];
  }
  const Cell& cell(const CellIndex& c) const { return cell(c.x, c.y); }

  // Read access to a whole tile (tile coordinates: cell >> kTileBits); nullptr if not allocated.
  const Tile* tile(int tx, int ty) const {
    tx -= tile_x0_;
    ty -= tile_y0_;
    if (tx < 0 || ty < 0 || tx >= tiles_w_ || ty >= tiles_h_) return nullptr;
    return tiles_[static_cast<size_t>(ty) * tiles_w_ + tx].get();
  }
  static int cellInTile(int cx, int cy) {
    return ((cy & (kTileSize - 1)) << kTileBits) | (cx & (kTileSize - 1));
  }

  // Write access: grows the grid and clones a shared tile before returning it. The caller tells
  // the tile which cells it wrote (Tile::cellWritten).
  Tile& mutableTile(int tx, int ty) {
    const int ix = tx - tile_x0_, iy = ty - tile_y0_;
    if (ix >= 0 && iy >= 0 && ix < tiles_w_ && iy < tiles_h_) {
      std::shared_ptr<Tile>& slot = tiles_[static_cast<size_t>(iy) * tiles_w_ + ix];
      if (isSoleOwner(slot)) return *slot;  // owned: write in place
    }
    return mutableTileSlow(tx, ty);
  }
  // For writing one cell (drops the tile's occupied rows and sets the cell's may-hold-occupied
  // bit: see Tile::cellWritten).
  Cell& mutableCell(int cx, int cy) {
    Tile& tile = mutableTile(cx >> kTileBits, cy >> kTileBits);
    tile.dropOccupiedRows();
    tile.markMayHoldOccupied(cellInTile(cx, cy));
    return tile.cells[cellInTile(cx, cy)];
  }

  // Calls fn(tx, ty, tile) for every allocated tile (tile coordinates), row by row from the
  // lowest y, each row from the lowest x.
  template <typename Fn>
  void forEachTile(Fn&& fn) const {
    for (int j = 0; j < tiles_h_; ++j) {
      for (int i = 0; i < tiles_w_; ++i) {
        const Tile* t = tiles_[static_cast<size_t>(j) * tiles_w_ + i].get();
        if (t != nullptr) fn(tile_x0_ + i, tile_y0_ + j, *t);
      }
    }
  }
  // Makes room for the tiles tx0..tx1 x ty0..ty1 (inclusive) at once, without allocating any: a
  // map filled from a file then grows its tile index once instead of tile by tile.
  void reserveTiles(int tx0, int ty0, int tx1, int ty1);

  // Box of allocated tiles (in cells); empty for a fresh grid.
  CellBox allocatedBox() const;
  // Tight box of the observed (non-vacuous) cells.
  CellBox observedBox() const;

  size_t allocatedTiles() const;
  // Adds this grid's tiles to `seen`; returns the bytes of the tiles not yet in it (for memory
  // accounting of grids that share tiles).
  size_t accumulateUniqueTileBytes(std::unordered_set<const Tile*>* seen) const;

 private:
  void ensureTile(int tx, int ty);
  // Re-indexes the tiles onto the box x0..x1 x y0..y1 (inclusive), which holds the current one.
  void growIndex(int x0, int y0, int x1, int y1);
  Tile& mutableTileSlow(int tx, int ty);

  static const Cell kVacuousCell;
  double resolution_;
  int tile_x0_ = 0, tile_y0_ = 0, tiles_w_ = 0, tiles_h_ = 0;
  std::vector<std::shared_ptr<Tile>> tiles_;
};

}  // namespace evidential_slam
