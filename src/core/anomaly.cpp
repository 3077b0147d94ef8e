#include "evidential_slam/core/anomaly.h"

#include <algorithm>
#include <cmath>

#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/core/sole_owner.h"

namespace evidential_slam {
namespace {

// A hit contradicts a cell the map holds free with at least this normalised mass.
constexpr float kConfidentFree = 0.5f;
// The scan's side. A hit: the cell holds the endpoint. A hit's occupied mass, (1 - r) η [p_o pl +
// (1 - p_o) m] (algorithm.md §4), is 0.63 on the cell whose centre the endpoint falls on, 0.48 on
// each of two cells when it falls on their border, 0.19 on the neighbours of a centred one: 0.35
// takes the endpoint's cell wherever in it the endpoint lies (K >= 1/2 dropped those near a
// border, and floor seen free only once or twice).
constexpr float kHitMass = 0.35f;
// A pass: a clearing beam crossing a cell the map holds occupied, with conflict K = m̃(o) s(e) >=
// 1/2, i.e. m̃(o) >= 0.625 under a clearing beam's s(e) = 0.8. A wall's surface cells are partly
// wall, held occupied without that confidence while grazing beams clear them and others hit them
// (m̃(o) >= 1/2 alone flagged the faces of thin walls on clean generated runs).
constexpr float kMinPassConflict = 0.5f;
constexpr float kSurfaceMass = kScanSurfaceMass;

float bitsOf(float conflict) {
  return static_cast<float>(-std::log2(1.0 - std::min(conflict, kMaxUpdateConflict)));
}

bool believedFree(const Cell& c) { return c.free() > c.occupied(); }

}  // namespace

void scanAnomaly(const ScanAccumulator& scan, const EvidentialGridMap& map, int radius,
                 std::vector<AnomalyCell>* out) {
  scan.forEachCell([&](int x, int y, const ScanMass& s) {
    if (s.occupied >= kHitMass) {
      // A hit in open space.
      const Cell& c = map.cell(x, y);
      if (c.free() < kConfidentFree) return;
      const float k = c.free() * s.occupied;
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          if (!believedFree(map.cell(x + dx, y + dy))) return;
        }
      }
      out->push_back(AnomalyCell{x, y, bitsOf(k)});
    } else if (s.free >= kMinPassConflict) {
      // A pass through an obstacle. Most cleared cells hold no occupied mass at all (the tile's
      // may-hold-occupied bit), and are passed over without reading them.
      const EvidentialGridMap::Tile* tile =
          map.tile(x >> EvidentialGridMap::kTileBits, y >> EvidentialGridMap::kTileBits);
      const int k_cell = EvidentialGridMap::cellInTile(x, y);
      if (tile == nullptr || !tile->mayHoldOccupied(k_cell)) return;
      const float k = tile->cells[static_cast<size_t>(k_cell)].occupied() * s.free;
      if (k < kMinPassConflict) return;
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          const ScanMass* n = scan.find(x + dx, y + dy);
          if (n != nullptr && n->occupied >= kSurfaceMass) return;
        }
      }
      // Through the obstacle, not along its surface: every neighbour the map does not hold free
      // is cleared too. A beam grazing a wall clips its surface cells and leaves the wall's next
      // cells as they were, and at grazing incidence its own hit and its neighbours' lie far
      // along the wall, outside the window above.
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (believedFree(map.cell(x + dx, y + dy))) continue;
          const ScanMass* n = scan.find(x + dx, y + dy);
          if (n == nullptr || n->free < kMinPassConflict) return;
        }
      }
      out->push_back(AnomalyCell{x, y, bitsOf(k)});
    }
  });
}

BelievedFreeTiles::BelievedFreeTiles(const EvidentialGridMap& map) {
  int x1 = 0, y1 = 0;
  bool any = false;
  map.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile&) {
    x0_ = any ? std::min(x0_, tx) : tx;
    y0_ = any ? std::min(y0_, ty) : ty;
    x1 = any ? std::max(x1, tx) : tx;
    y1 = any ? std::max(y1, ty) : ty;
    any = true;
  });
  if (!any) return;
  width_ = x1 - x0_ + 1;
  height_ = y1 - y0_ + 1;
  free_.assign(static_cast<size_t>(width_) * static_cast<size_t>(height_), 0);
  map.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
    for (const Cell& c : tile.cells) {
      if (!believedFree(c)) return;
    }
    free_[static_cast<size_t>(ty - y0_) * static_cast<size_t>(width_) + (tx - x0_)] = 1;
  });
}

size_t BelievedFreeTiles::count() const {
  return static_cast<size_t>(std::count(free_.begin(), free_.end(), uint8_t{1}));
}

double contradictionOf(const std::vector<AnomalyCell>& cells) {
  double sum = 0.0;
  for (const AnomalyCell& c : cells) sum += 1.0 - std::exp2(-static_cast<double>(c.bits));
  return sum;
}

void AnomalyGrid::add(int x, int y, float bits) {
  if (bits > 0.0f) cells_[key(x, y)] += bits;
}

void AnomalyGrid::add(const std::vector<AnomalyCell>& cells) {
  for (const AnomalyCell& c : cells) add(c.x, c.y, c.bits);
}

float AnomalyGrid::at(int x, int y) const {
  const auto it = cells_.find(key(x, y));
  return it == cells_.end() ? 0.0f : it->second;
}

double AnomalyGrid::total() const {
  double sum = 0.0;
  for (const auto& entry : cells_) sum += entry.second;
  return sum;
}

AnomalyNode::~AnomalyNode() {
  std::shared_ptr<const AnomalyNode> next = std::move(parent);
  while (isSoleOwner(next)) {
    std::shared_ptr<const AnomalyNode> after = std::move(const_cast<AnomalyNode&>(*next).parent);
    next = std::move(after);
  }
}

AnomalyGrid accumulateAnomaly(const AnomalyNode* last) {
  AnomalyGrid grid;
  for (const AnomalyNode* n = last; n != nullptr; n = n->parent.get()) grid.add(n->cells);
  return grid;
}

}  // namespace evidential_slam
