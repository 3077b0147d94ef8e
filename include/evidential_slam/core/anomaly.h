// The anomaly layer: per cell, the evidence of scans that contradicts what a map held with
// confidence before the scan (never the merged masses after it: the m(∅) a contradiction adds is
// e^{-λ} K, diluted on every cell that already conflicts), accumulated in bits like external
// conflict (EC) but only where the contradiction cannot come from an ordinary surface:
//   - a hit in open space: the map holds the cell free (m̃(e) >= 1/2), the scan's endpoint lies in
//     it (s(o) >= 0.35), and every cell within the forward model's hit window is believed free
//     too (m̃(e) > m̃(o)): something appeared, or the scan is placed where the map knew floor;
//   - a pass through an obstacle: the map holds the cell occupied and a clearing beam crosses it
//     with conflict K = m̃(o) s(e) >= 1/2, and the scan sees no surface within that window around
//     it: something was removed (an opened door, a moved shelf), or the scan is misplaced.
// After a kidnap the filter draws the true walls at its wrong pose: both at once, ghost walls in
// the map's free space and beams through the walls it held. A wall's surface cells are partly
// wall and partly free: beams grazing the wall clear them and others hit them, which grows their
// EC at every pass. The scan hits the wall next to such a cell, and the map holds the wall (or has
// never seen behind it) next to a hit on it, so neither rule flags them; range noise moves a hit
// along its beam by less than the window. The anomaly of one update of a cell is -log2(1 - K),
// K = m̃(e) s(o) or m̃(o) s(e), EC's increment there. It is read from the map before the scan,
// never fed back into it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "evidential_slam/core/evidential_grid.h"

namespace evidential_slam {

class ScanAccumulator;

// A scan's fused mass this occupied or more says the scan sees a surface in that cell (a pass
// through an obstacle next to such a cell is no anomaly: scanAnomaly).
constexpr float kScanSurfaceMass = 0.05f;

// One cell's anomaly from one scan.
struct AnomalyCell {
  int x = 0;
  int y = 0;
  float bits = 0.0f;
};

// Appends to `out` the anomaly of the scan held in `scan` (accumulated, not yet applied) against
// `map`, with neighbourhoods `radius` cells around each cell (BeamModel::openSpaceRadius()).
void scanAnomaly(const ScanAccumulator& scan, const EvidentialGridMap& map, int radius,
                 std::vector<AnomalyCell>* out);

// The tiles of a map all of whose cells the map believes free (m̃(e) > m̃(o)). scanAnomaly reads
// a scan's mass only on cells the map does not believe free and on cells the scan's hits put
// occupied mass on: BeamModel::accumulateForAnomaly leaves out the rest of these tiles.
class BelievedFreeTiles {
 public:
  BelievedFreeTiles() = default;
  explicit BelievedFreeTiles(const EvidentialGridMap& map);
  // False for a tile the map does not hold (never observed).
  bool contains(int tile_x, int tile_y) const {
    const int x = tile_x - x0_, y = tile_y - y0_;
    if (static_cast<unsigned>(x) >= static_cast<unsigned>(width_) ||
        static_cast<unsigned>(y) >= static_cast<unsigned>(height_)) {
      return false;
    }
    return free_[static_cast<size_t>(y) * static_cast<size_t>(width_) + x] != 0;
  }
  size_t count() const;

 private:
  int x0_ = 0, y0_ = 0, width_ = 0, height_ = 0;  // the allocated tiles' box
  std::vector<uint8_t> free_;
};

// Σ K over `cells` (K = 1 - 2^-bits): how many cells' confident evidence one scan contradicted,
// each weighted by how strongly (conflict.csv's contradiction_added).
double contradictionOf(const std::vector<AnomalyCell>& cells);

// Per-cell anomaly accumulated over scans (bits). Sparse: most cells never hold any.
class AnomalyGrid {
 public:
  void add(int x, int y, float bits);
  void add(const std::vector<AnomalyCell>& cells);
  // 0 for a cell without anomaly.
  float at(int x, int y) const;
  size_t size() const { return cells_.size(); }
  bool empty() const { return cells_.empty(); }
  void clear() { cells_.clear(); }
  double total() const;
  // fn(x, y, bits) for every cell holding anomaly, in no particular order.
  template <typename Fn>
  void forEach(Fn&& fn) const {
    for (const auto& [key, bits] : cells_) fn(keyX(key), keyY(key), bits);
  }

 private:
  static uint64_t key(int x, int y) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(x)) << 32) | static_cast<uint32_t>(y);
  }
  static int keyX(uint64_t key) { return static_cast<int>(static_cast<uint32_t>(key >> 32)); }
  static int keyY(uint64_t key) { return static_cast<int>(static_cast<uint32_t>(key)); }
  std::unordered_map<uint64_t, float> cells_;
};

// What one scan added to one particle's anomaly, on that particle's lineage (like its path:
// children share their ancestors' nodes, so resampling copies a pointer). Scans that add
// nothing add no node.
struct AnomalyNode {
  std::vector<AnomalyCell> cells;
  std::shared_ptr<const AnomalyNode> parent;
  ~AnomalyNode();  // releases long chains iteratively (no deep recursion)
};

// The anomaly of a lineage: every node's cells summed.
AnomalyGrid accumulateAnomaly(const AnomalyNode* last);

}  // namespace evidential_slam
