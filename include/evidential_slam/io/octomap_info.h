// What evidential_octomap_info reports about an EvidentialOcTree: extent, node counts, occupancy
// and per-layer statistics of the masses and (layout 2) the anomaly, and a voxel-by-voxel
// comparison with the layers/ that the offline runner wrote for the same map. Kept in the library
// so the tool is thin and testable.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>

#include "evidential_slam/core/measures.h"
#include "evidential_slam/io/evidential_octree.h"

namespace evidential_slam {
namespace io {

struct LayerStats {
  double min = 0.0;
  double mean = 0.0;
  double max = 0.0;
};

struct OctreeStats {
  double resolution = 0.0;
  std::array<double, 3> min{};  // metric bounds of the stored voxels (lower corners)
  std::array<double, 3> max{};  // (upper corners)
  size_t nodes = 0;             // all nodes, inner ones included (OctoMap's size())
  size_t leaves = 0;
  uint64_t voxels = 0;  // finest-level voxels the leaves cover (a pruned leaf covers several)
  uint64_t occupied_voxels = 0;              // OctoMap's isNodeOccupied: BetP(o) >= 0.5
  std::map<int, uint64_t> voxels_per_z_key;  // OctoMap z key -> voxels in that height layer
  // Over voxels, in Layer order (measures.h); the anomaly's only when the layout holds it.
  std::array<LayerStats, kLayerCount> layers{};
  EvidentialLayout layout = kLatestEvidentialLayout;
  bool has_anomaly = false;         // layout 2
  uint64_t anomaly_voxels = 0;      // voxels with an anomaly > 0
  double anomaly_voxel_bits = 0.0;  // Σ over voxels (a cell's bits times its height layers)
};

// Walks the leaves once. An empty tree gives zero counts.
OctreeStats computeOctreeStats(const EvidentialOcTree& tree);

struct LayerComparison {
  uint64_t cells = 0;           // observed cells in the layers
  uint64_t voxels_checked = 0;  // cells * height layers of the tree
  uint64_t missing_voxels = 0;  // observed cell without a voxel in a layer
  uint64_t extra_voxels = 0;    // tree voxels not matched by an observed cell
  // Largest |difference| of m(o), m(e), m(Θ), m(∅) (float32, as in the .npy files).
  std::array<double, 4> max_abs_diff{};
  // The same for the anomaly (anomaly.npy), compared when the tree's layout holds it.
  bool anomaly_compared = false;
  double anomaly_max_abs_diff = 0.0;
  bool identical(double tolerance) const;
};

// Compares every observed cell of a run's layers/ directory (occupied, free, unknown and conflict
// .npy, observed.npy, map.yaml, and anomaly.npy for a layout-2 tree) with the tree's voxel at
// that cell on every height layer in `stats`.
bool compareWithLayers(const EvidentialOcTree& tree, const OctreeStats& stats,
                       const std::string& layers_dir, LayerComparison* comparison,
                       std::string* error);

}  // namespace io
}  // namespace evidential_slam
