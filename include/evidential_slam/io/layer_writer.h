// Writes the ten map layers of a LayerRaster to a directory:
//   <name>.png      one 8-bit grey image per layer, north-up, dark = high value (the paper's
//                   convention: black = 1); EC and the anomaly, unbounded, are scaled by their
//                   maximum in the map.
//   composite.png   RGB = (m(o), m(e), m(Θ)): occupied red, free green, unknown blue, and
//                   conflict, which takes mass from all three, dark.
//   <name>.npy      the raw float32 values, shape (height, width), row 0 = lowest y (the layout
//                   of nav_msgs/OccupancyGrid), plus observed.npy (uint8, 1 = cell has evidence).
//   map.yaml        map_server metadata for pignistic.png, plus each layer's PNG value range.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "evidential_slam/core/layers.h"

namespace evidential_slam {
namespace io {

class AtomicFiles;

struct LayerWriterConfig {
  double occupied_thresh = 0.65;  // map.yaml (map_server): BetP above this is occupied
  double free_thresh = 0.196;     // and below this free
};

// How one layer's values were mapped to its PNG: value `white` -> 255, value `black` -> 0,
// linear in between, clamped.
struct LayerImageScale {
  std::string name;
  double white = 0.0;
  double black = 1.0;
  float min_value = 0.0f;  // range of the raw values over the raster (finite ones)
  float max_value = 0.0f;
};

struct LayerWriteResult {
  std::vector<std::string> files;  // everything written, full paths
  std::array<LayerImageScale, kLayerCount> scales;
  double external_conflict_scale = 1.0;  // EC value drawn black (its maximum)
};

// Grey level of `value` under `scale`: 255 at `white`, 0 at `black`.
uint8_t layerPixel(float value, const LayerImageScale& scale);

// Writes everything listed above into `dir` (which must exist). False (and `error`, with the
// reason) on the first file that cannot be written. The files replace the old ones together, once
// all are written (atomic_files.h): staged into `files` when given (the caller commits), else
// committed here; a failed write leaves the old files as they were.
bool writeLayers(const LayerRaster& raster, const std::string& dir, const LayerWriterConfig& config,
                 LayerWriteResult* result, std::string* error, AtomicFiles* files = nullptr);

// Writes every layer as a map_server image + metadata pair: <name>.pgm (north-up, dark = high
// value, EC and the anomaly scaled by their maximum as above) and <name>.yaml. pignistic.yaml
// loads in map_server's trinary mode with `config`'s thresholds (an ordinary occupancy map); the
// other layers load in scale mode with thresholds 1 and 0, so map_server turns a layer value v
// into about 99 v.
// Written like writeLayers' files.
bool writeMapServerLayers(const LayerRaster& raster, const std::string& dir,
                          const LayerWriterConfig& config, std::vector<std::string>* files,
                          std::string* error, AtomicFiles* staged = nullptr);

// Writes one layer's files: <name>.png and <name>.npy as writeLayers does, <name>.pgm and
// <name>.yaml as writeMapServerLayers does (the same bytes); only that layer of `raster` is read.
// Written like writeLayers' files; their paths are appended to `files`.
bool writeLayerFiles(const LayerRaster& raster, Layer layer, const std::string& dir,
                     const LayerWriterConfig& config, std::vector<std::string>* files,
                     std::string* error, AtomicFiles* staged = nullptr);

}  // namespace io
}  // namespace evidential_slam
