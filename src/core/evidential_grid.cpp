#include "evidential_slam/core/evidential_grid.h"

#include <algorithm>
#include <cmath>

#include "evidential_slam/core/profile.h"

namespace evidential_slam {

const Cell EvidentialGridMap::kVacuousCell{};

const EvidentialGridMap::Tile::Rows EvidentialGridMap::Tile::kNoRows{};

EvidentialGridMap::Tile::Tile(const Tile& other)
    : cells(other.cells), may_hold_occupied_(copyOf(other.may_hold_occupied_)) {
  // The source is shared and not written meanwhile; its rows may be being built by a reader, in
  // which case the clone builds its own when asked.
  if (other.rows_state_.load(std::memory_order_acquire) == kRowsReady) {
    rows_ = copyOf(other.rows_);
    rows_threshold_ = other.rows_threshold_;
    rows_state_.store(kRowsReady, std::memory_order_relaxed);
  }
}

const EvidentialGridMap::Tile::Rows& EvidentialGridMap::Tile::occupiedRows(float threshold,
                                                                           Rows* scratch) const {
  int state = rows_state_.load(std::memory_order_acquire);
  if (state == kRowsReady && rows_threshold_ == threshold) return rows_ ? *rows_ : kNoRows;
  if (state == kRowsNone &&
      rows_state_.compare_exchange_strong(state, kRowsBuilding, std::memory_order_acq_rel)) {
    if (buildOccupiedRows(threshold, scratch)) rows_ = std::make_unique<Rows>(*scratch);
    rows_threshold_ = threshold;
    rows_state_.store(kRowsReady, std::memory_order_release);
    return rows_ ? *rows_ : kNoRows;
  }
  buildOccupiedRows(threshold, scratch);
  return *scratch;
}

bool EvidentialGridMap::Tile::buildOccupiedRows(float threshold, Rows* rows) const {
  // With a positive threshold a target cell holds m̃(o) > 0, so rows without a may-hold-occupied
  // bit are skipped unread.
  const bool skip_empty_rows = threshold > 0.0f;
  uint32_t any = 0;
  for (int y = 0; y < kTileSize; ++y) {
    uint32_t bits = 0;
    if (!skip_empty_rows ||
        (may_hold_occupied_ && (*may_hold_occupied_)[static_cast<size_t>(y)] != 0)) {
      const Cell* row = &cells[static_cast<size_t>(y) * kTileSize];
      for (int x = 0; x < kTileSize; ++x) {
        bits |= static_cast<uint32_t>(isTarget(row[x], threshold)) << x;
      }
    }
    (*rows)[static_cast<size_t>(y)] = bits;
    any |= bits;
  }
  return any != 0;
}

void CellBox::extend(const CellBox& other) {
  if (other.empty()) return;
  if (empty()) {
    *this = other;
    return;
  }
  min_x = std::min(min_x, other.min_x);
  min_y = std::min(min_y, other.min_y);
  max_x = std::max(max_x, other.max_x);
  max_y = std::max(max_y, other.max_y);
}

EvidentialGridMap::EvidentialGridMap(double resolution) : resolution_(resolution) {}

Eigen::Vector2d EvidentialGridMap::cellCenter(const CellIndex& c) const {
  return {(c.x + 0.5) * resolution_, (c.y + 0.5) * resolution_};
}

void EvidentialGridMap::ensureTile(int tx, int ty) {
  if (tiles_w_ > 0 && tx >= tile_x0_ && ty >= tile_y0_ && tx < tile_x0_ + tiles_w_ &&
      ty < tile_y0_ + tiles_h_) {
    return;
  }
  // Grow with a margin so a robot exploring in one direction does not re-index every scan.
  constexpr int kMargin = 8;
  int x0 = tx - kMargin, y0 = ty - kMargin, x1 = tx + kMargin, y1 = ty + kMargin;  // inclusive
  if (tiles_w_ > 0) {
    x0 = std::min(x0, tile_x0_);
    y0 = std::min(y0, tile_y0_);
    x1 = std::max(x1, tile_x0_ + tiles_w_ - 1);
    y1 = std::max(y1, tile_y0_ + tiles_h_ - 1);
    // Only grow the side that needs it.
    if (tx >= tile_x0_) x0 = tile_x0_;
    if (ty >= tile_y0_) y0 = tile_y0_;
    if (tx < tile_x0_ + tiles_w_) x1 = tile_x0_ + tiles_w_ - 1;
    if (ty < tile_y0_ + tiles_h_) y1 = tile_y0_ + tiles_h_ - 1;
  }
  growIndex(x0, y0, x1, y1);
}

void EvidentialGridMap::reserveTiles(int tx0, int ty0, int tx1, int ty1) {
  if (tx1 < tx0 || ty1 < ty0) return;
  if (tiles_w_ > 0) {
    tx0 = std::min(tx0, tile_x0_);
    ty0 = std::min(ty0, tile_y0_);
    tx1 = std::max(tx1, tile_x0_ + tiles_w_ - 1);
    ty1 = std::max(ty1, tile_y0_ + tiles_h_ - 1);
    if (tx0 == tile_x0_ && ty0 == tile_y0_ && tx1 - tx0 + 1 == tiles_w_ &&
        ty1 - ty0 + 1 == tiles_h_)
      return;
  }
  growIndex(tx0, ty0, tx1, ty1);
}

void EvidentialGridMap::growIndex(int x0, int y0, int x1, int y1) {
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  std::vector<std::shared_ptr<Tile>> grown(static_cast<size_t>(w) * h);
  for (int j = 0; j < tiles_h_; ++j) {
    for (int i = 0; i < tiles_w_; ++i) {
      grown[static_cast<size_t>(j + tile_y0_ - y0) * w + (i + tile_x0_ - x0)] =
          std::move(tiles_[static_cast<size_t>(j) * tiles_w_ + i]);
    }
  }
  tiles_ = std::move(grown);
  tile_x0_ = x0;
  tile_y0_ = y0;
  tiles_w_ = w;
  tiles_h_ = h;
}

EvidentialGridMap::Tile& EvidentialGridMap::mutableTileSlow(int tx, int ty) {
  const ProfileTimer timer(ProfileSection::kTileClone);
  if (Profiler* profiler = Profiler::active()) profiler->count(ProfileCounter::kTileClones);
  ensureTile(tx, ty);
  std::shared_ptr<Tile>& slot =
      tiles_[static_cast<size_t>(ty - tile_y0_) * tiles_w_ + (tx - tile_x0_)];
  if (!slot) {
    slot = std::make_shared<Tile>();
  } else if (!isSoleOwner(slot)) {
    // Shared with another grid: clone before writing. (Another thread may release its copy
    // concurrently; then we clone needlessly, which is harmless.)
    slot = std::make_shared<Tile>(*slot);
  }
  return *slot;
}

CellBox EvidentialGridMap::allocatedBox() const {
  CellBox box;
  for (int j = 0; j < tiles_h_; ++j) {
    for (int i = 0; i < tiles_w_; ++i) {
      if (!tiles_[static_cast<size_t>(j) * tiles_w_ + i]) continue;
      const int x = (tile_x0_ + i) * kTileSize, y = (tile_y0_ + j) * kTileSize;
      box.extend(CellBox{x, y, x + kTileSize - 1, y + kTileSize - 1});
    }
  }
  return box;
}

CellBox EvidentialGridMap::observedBox() const {
  CellBox box;
  for (int j = 0; j < tiles_h_; ++j) {
    for (int i = 0; i < tiles_w_; ++i) {
      const Tile* t = tiles_[static_cast<size_t>(j) * tiles_w_ + i].get();
      if (t == nullptr) continue;
      // A tile within the box found so far cannot widen it.
      const int x0 = (tile_x0_ + i) * kTileSize, y0 = (tile_y0_ + j) * kTileSize;
      if (!box.empty() && x0 >= box.min_x && y0 >= box.min_y && x0 + kTileSize - 1 <= box.max_x &&
          y0 + kTileSize - 1 <= box.max_y) {
        continue;
      }
      for (int k = 0; k < kTileCells; ++k) {
        if (!t->cells[k].observed()) continue;
        const int x = (tile_x0_ + i) * kTileSize + (k & (kTileSize - 1));
        const int y = (tile_y0_ + j) * kTileSize + (k >> kTileBits);
        box.extend(CellBox{x, y, x, y});
      }
    }
  }
  return box;
}

size_t EvidentialGridMap::allocatedTiles() const {
  return static_cast<size_t>(std::count_if(
      tiles_.begin(), tiles_.end(), [](const std::shared_ptr<Tile>& t) { return t != nullptr; }));
}

size_t EvidentialGridMap::accumulateUniqueTileBytes(std::unordered_set<const Tile*>* seen) const {
  size_t bytes = 0;
  for (const auto& t : tiles_) {
    if (t && seen->insert(t.get()).second) bytes += sizeof(Tile) + t->bitmapBytes();
  }
  return bytes;
}

}  // namespace evidential_slam
