// Export of an evidential grid to three OctoMap files that others can open:
//   <prefix>.evidential.ot   EvidentialOcTree (evidential_octree.h), layout 2: every mass,
//                            lossless, and each voxel's anomaly (bits)
//   <prefix>.bt              standard OcTree, binary: occupied where BetP(o) >= 0.5, else free
//                            (octovis, octomap's tools and any OctoMap user read it)
//   <prefix>.color.ot        ColorOcTree, value = log-odds BetP(o) and RGB = 255 * (m(o), m(e),
//                            m(Θ)), the colours of layers/composite.png, for any ColorOcTree viewer
// The 2-D map becomes a slab of voxels at the grid's resolution: grid cell (i, j) is OctoMap key
// (i + 32768, j + 32768), so voxel and cell centres coincide; the slab repeats each cell on every
// voxel layer between two heights. Only observed cells are stored: unknown space stays unknown.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/evidential_grid.h"

namespace evidential_slam {
namespace io {

class AtomicFiles;

struct OctomapExportConfig {
  // The slab covers the voxel layers from the one containing z_min to the one containing z_max
  // (OctoMap's voxel k spans [k * res, (k + 1) * res)). Default: one layer, [0, res).
  double z_min = 0.0;    // m
  double z_max = 0.0;    // m
  int max_layers = 200;  // refuse slabs thicker than this (memory guard)

  bool isValid(std::string* why) const;
};

struct OctomapExportFile {
  std::string kind;  // "evidential", "binary", "color"
  std::string path;
  uint64_t bytes = 0;
  size_t nodes = 0;      // nodes of the tree written (after pruning, for the pruned trees)
  double seconds = 0.0;  // building and writing this tree
};

struct OctomapExportResult {
  std::vector<OctomapExportFile> files;  // evidential, binary, color, in that order
  size_t observed_cells = 0;
  int z_layers = 0;
  size_t voxels = 0;     // observed_cells * z_layers
  double seconds = 0.0;  // whole export
};

// Suffixes appended to the path prefix.
extern const char* const kEvidentialOtSuffix;  // ".evidential.ot"
extern const char* const kBinarySuffix;        // ".bt"
extern const char* const kColorOtSuffix;       // ".color.ot"

// Writes the three files (directory must exist); every voxel of the evidential tree carries its
// cell's anomaly from `anomaly` (0 for cells it does not hold; only observed cells are voxels).
// They replace the old ones together once all are written (atomic_files.h): staged into `files`
// when given (the caller commits), else committed here. False (and a one-line `error`) on a bad
// config, a map outside OctoMap's key range (±32768 cells from the origin), or a file that cannot
// be written (the old files are then left as they were). Trees are built one at a time to bound
// memory.
bool exportOctomap(const EvidentialGridMap& grid, const AnomalyGrid& anomaly,
                   const OctomapExportConfig& config, const std::string& path_prefix,
                   OctomapExportResult* result, std::string* error, AtomicFiles* files = nullptr);
// The same without an anomaly layer (every voxel's anomaly is 0).
bool exportOctomap(const EvidentialGridMap& grid, const OctomapExportConfig& config,
                   const std::string& path_prefix, OctomapExportResult* result, std::string* error,
                   AtomicFiles* files = nullptr);

}  // namespace io
}  // namespace evidential_slam
