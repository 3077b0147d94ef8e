// A map given on a command line: a lossless map file, a directory holding one (a SLAM run's or a
// fusion's output), or a run's directory that holds only its layers (layers/<layer>.npy,
// observed.npy and map.yaml; rebuilt by fusion::mapFromLayers at the layers' float precision).
#pragma once

#include <string>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/io/map_file.h"

namespace evidential_slam {
namespace io {

struct MapInput {
  enum class Kind { kMapFile, kLayers };
  Kind kind = Kind::kMapFile;
  std::string path;  // the file read: the map file, or the layers' map.yaml
  // The map's frame in the frame of the run that made it (non-zero only for layers whose origin
  // lies off the cell grid); a front end composes it into the map's pose.
  Pose2 offset;
  MapFileInfo info;  // the map file's (default for layers)
};

// "map file" or "layers".
const char* mapInputKindName(MapInput::Kind kind);

// Reads `path` as above, preferring the map file when a directory holds both. False (and a
// one-line `error` naming the path) when it is none of them or cannot be read.
bool readMapInput(const std::string& path, EvidentialGridMap* map, MapInput* input,
                  std::string* error);

// Reads a run's layers directory (`dir`/map.yaml, `dir`/<layer>.npy, `dir`/observed.npy) into a
// raster; the same errors.
bool readLayerDirectory(const std::string& dir, LayerRaster* raster, std::string* error);

}  // namespace io
}  // namespace evidential_slam
