// The files a map is saved as, written by one code path for the offline runner's --out and the
// node's ~save_map:
//   trajectory.tum   the best particle's path, one pose per scan (TUM: t x y z qx qy qz qw)
//   conflict.csv     per processed scan, the conflict it added and the alarm's verdict
//   layers/          every layer as <name>.png + <name>.npy (writeLayers) and as a map_server pair
//                    <name>.pgm + <name>.yaml (writeMapServerLayers), with composite.png,
//                    observed.npy and map.yaml (map_server metadata of pignistic.png)
//   octomap/         map.evidential.ot, map.bt, map.color.ot, when export_octomap is set
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/session/session.h"

namespace evidential_slam {
namespace io {
class AtomicFiles;
}  // namespace io

// What the OctoMap export wrote.
struct OctomapFilesReport {
  std::vector<std::string> files;  // full paths
  std::vector<uint64_t> bytes;
  double seconds = 0.0;
  int z_layers = 0;
  uint64_t voxels = 0;
};

struct MapFilesReport {
  std::vector<std::string> files;  // every file written, full paths
  int map_width = 0;               // cells of the layer rasters
  int map_height = 0;
  double external_conflict_scale = 0.0;  // EC drawn black in layers/external_conflict.png
  std::optional<OctomapFilesReport> octomap;
};

// Writes the files above into `dir` (created if missing). They replace the previous files together
// once all are written (io/atomic_files.h): staged into `staged` when given (the caller commits it
// with files of its own), else committed here. False with a one-line `error` on the first file
// that cannot be written; the previous files are then left as they were.
bool writeMapFiles(const std::string& dir, const EvidentialGridMap& map,
                   const std::vector<StampedPose>& trajectory,
                   const std::vector<ConflictRecord>& conflicts, const SessionConfig& config,
                   MapFilesReport* report, std::string* error,
                   io::AtomicFiles* staged = nullptr);

}  // namespace evidential_slam
