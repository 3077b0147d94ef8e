// The files a map is saved as, written by one code path for the offline runner's --out and the
// node's ~save_map:
//   map.evmap        the lossless map file (io/map_file.h, docs/map_format.md): the best
//                    particle's map, its pose and odometry pose at save time, the build and every
//                    parameter's value; what --load-map, map_file and ~load_map read back
//   trajectory.tum   the best particle's path, one pose per scan (TUM: t x y z qx qy qz qw)
//   trajectory.png   (with layers/) that path over the pignistic map, with the reference path and
//                    caption of MapSave when set (io/trajectory_image.h)
//   conflict.csv     per processed scan, the conflict it added and the alarm's verdict
//   layers/          (when the observed box fits max_layer_cells) every layer as <name>.png +
//   <name>.npy (writeLayers) and as a map_server pair
//                    <name>.pgm + <name>.yaml (writeMapServerLayers), with composite.png,
//                    observed.npy and map.yaml (map_server metadata of pignistic.png); with
//                    MapSave::anomaly_layer_only, the anomaly layer's four files only
//   octomap/         map.evidential.ot, map.bt, map.color.ot, when export_octomap is set
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/map_file.h"
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
  std::string map_file;            // the lossless map file among them
  io::MapFileStats map_file_stats;
  int map_width = 0;  // cells of the layer rasters
  int map_height = 0;
  // Why layers/ was not written (the observed box exceeds max_layer_cells); empty when it was.
  std::string layers_skipped;
  double external_conflict_scale = 0.0;  // EC drawn black in layers/external_conflict.png
  bool anomaly_layer_only = false;       // layers/ got the anomaly layer only (MapSave's)
  std::optional<OctomapFilesReport> octomap;
};

// What a saved map holds, taken from a session at save time (captureMapSave).
struct MapSave {
  EvidentialGridMap map;  // the best particle's (a copy sharing its tiles)
  AnomalyGrid anomaly;    // the best particle's anomaly layer (core/anomaly.h)
  std::vector<StampedPose> trajectory;
  std::vector<ConflictRecord> conflicts;
  // The map file's pose, odometry pose, parameters and metadata; the caller may add to the
  // metadata (e.g. "source").
  io::MapFileInfo info;
  // Drawn in trajectory.png beside the path: a reference path in the map frame (ground truth,
  // aligned as the ATE aligns it) and a caption (the ATE); set by the caller, empty by default.
  std::vector<Pose2> reference_path;
  std::string trajectory_caption;
  // layers/ holds only the anomaly layer (its four files), not the map's: for a localization's
  // output, whose map is the stored one, unchanged (its layers are those of the run that made it).
  bool anomaly_layer_only = false;
};

// The best particle's map, anomaly, path and pose, the odometry pose with it, the conflict record,
// every parameter's value (parameterValues) and as metadata the scan counts, the last scan's stamp
// and whether mapping was paused. In localization mode: the stored map (unchanged), the anomaly
// against it, the estimate's path and pose, no conflict record, metadata mode = localization.
// Read the session where it does not run (the node's worker thread).
MapSave captureMapSave(const MappingSession& session);

// Writes the files above into `dir` (created if missing). They replace the previous files
// (map.evmap too) together once all are written (io/atomic_files.h): staged into `staged` when
// given (the caller commits it with files of its own), else committed here. False with a one-line
// `error` on the first file that cannot be written; the previous files are then left as they were.
bool writeMapFiles(const std::string& dir, const MapSave& save, const SessionConfig& config,
                   MapFilesReport* report, std::string* error, io::AtomicFiles* staged = nullptr);

// A map file read to continue mapping on (the offline runner's --load-map, the node's map_file
// and ~load_map).
struct LoadedMap {
  std::string path;  // the file read (a directory stands for its map.evmap)
  EvidentialGridMap map;
  io::MapFileInfo info;
};
// Reads `path` (a file, or a directory holding map.evmap). False with a one-line `error` naming
// the file.
bool loadMapFile(const std::string& path, LoadedMap* out, std::string* error);

// Whether dense layers over `map`'s observed box fit max_layer_cells (always when it is 0). False
// and a one-line `why` with the size they would need otherwise.
bool denseLayersFit(const EvidentialGridMap& map, const SessionConfig& config, std::string* why);
bool denseLayersFit(const CellBox& box, double resolution, const SessionConfig& config,
                    std::string* why);

// The folders a command writes into (its output directory, and layers/ and octomap/ in it) as
// they were before it ran: a failed command calls removeCreated(), which removes those it made,
// so no half-written folder is left behind (the files themselves are staged by AtomicFiles).
class OutputFolders {
 public:
  explicit OutputFolders(const std::string& dir);
  void removeCreated() const;

 private:
  std::string dir_;
  bool dir_existed_ = true, layers_existed_ = true, octomap_existed_ = true;
};

}  // namespace evidential_slam
