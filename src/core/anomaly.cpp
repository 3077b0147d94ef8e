#include "evidential_slam/core/anomaly.h"

#include <algorithm>
#include <cmath>

#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/core/sole_owner.h"

namespace evidential_slam {
namespace {

// Each rule's conflict must reach this (a cell believed one way with confidence, a scan mass the
// other way with confidence: 1/2 needs both at least 1/2).
constexpr float kMinConflict = 0.5f;
// A scan mass this occupied or more says the scan sees a surface in that cell.
constexpr float kSurfaceMass = 0.05f;

float bitsOf(float conflict) {
  return static_cast<float>(-std::log2(1.0 - std::min(conflict, kMaxUpdateConflict)));
}

bool believedFree(const Cell& c) { return c.free() > c.occupied(); }

}  // namespace

void scanAnomaly(const ScanAccumulator& scan, const EvidentialGridMap& map, int radius,
                 std::vector<AnomalyCell>* out) {
  scan.forEachCell([&](int x, int y, const ScanMass& s) {
    if (s.occupied >= kMinConflict) {
      // A hit in open space.
      const Cell& c = map.cell(x, y);
      const float k = c.free() * s.occupied;
      if (k < kMinConflict) return;
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          if (!believedFree(map.cell(x + dx, y + dy))) return;
        }
      }
      out->push_back(AnomalyCell{x, y, bitsOf(k)});
    } else if (s.free >= kMinConflict) {
      // A pass through an obstacle. Most cleared cells hold no occupied mass at all (the tile's
      // may-hold-occupied bit), and are passed over without reading them.
      const EvidentialGridMap::Tile* tile =
          map.tile(x >> EvidentialGridMap::kTileBits, y >> EvidentialGridMap::kTileBits);
      const int k_cell = EvidentialGridMap::cellInTile(x, y);
      if (tile == nullptr || !tile->mayHoldOccupied(k_cell)) return;
      const float k = tile->cells[static_cast<size_t>(k_cell)].occupied() * s.free;
      if (k < kMinConflict) return;
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          const ScanMass* n = scan.find(x + dx, y + dy);
          if (n != nullptr && n->occupied >= kSurfaceMass) return;
        }
      }
      out->push_back(AnomalyCell{x, y, bitsOf(k)});
    }
  });
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
