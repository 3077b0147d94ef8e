#include "evidential_slam/io/map_input.h"

#include <cmath>
#include <exception>
#include <filesystem>
#include <sstream>

#include "evidential_slam/core/fusion/layer_map.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/layer_yaml.h"
#include "evidential_slam/io/npy.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

bool isFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

bool isDirectory(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

}  // namespace

const char* mapInputKindName(MapInput::Kind kind) {
  return kind == MapInput::Kind::kMapFile ? "map file" : "layers";
}

bool readLayerDirectory(const std::string& dir, LayerRaster* raster, std::string* error) {
  const fs::path root(dir);
  const fs::path yaml_path = root / "map.yaml";
  LayerRaster r;
  if (!readLayerMapYaml(yaml_path.string(), &r.resolution, &r.origin_x, &r.origin_y, error)) {
    return false;
  }
  bool have_size = false;
  auto readLayer = [&](const std::string& name, NpyArray* array) {
    const std::string path = (root / (name + ".npy")).string();
    if (!readNpy(path, array, error)) return false;
    if (array->shape.size() != 2) {
      *error = quotedPath(path) + ": 'shape' is not 2-D";
      return false;
    }
    // readNpy bounds each dimension (kNpyMaxExtent < INT_MAX); the far corner is bounded as the
    // origin is.
    const int rows = static_cast<int>(array->shape[0]), cols = static_cast<int>(array->shape[1]);
    const double limit = layerExtentLimit();
    if (std::abs(r.origin_x + cols * r.resolution) > limit ||
        std::abs(r.origin_y + rows * r.resolution) > limit) {
      std::ostringstream msg;
      msg << quotedPath(path) << ": 'shape' " << rows << " x " << cols << " at " << r.resolution
          << " m from the origin of map.yaml reaches farther than " << limit
          << " m (the largest max_map_extent)";
      *error = msg.str();
      return false;
    }
    if (!have_size) {
      r.height = rows;
      r.width = cols;
      have_size = true;
    } else if (rows != r.height || cols != r.width) {
      std::ostringstream msg;
      msg << "'" << path << "' is " << rows << " x " << cols << ", the other layers " << r.height
          << " x " << r.width;
      *error = msg.str();
      return false;
    }
    return true;
  };
  for (const Layer l :
       {Layer::kOccupied, Layer::kFree, Layer::kUnknown, Layer::kExternalConflict}) {
    NpyArray array;
    if (!readLayer(layerName(l), &array)) return false;
    r.values[static_cast<int>(l)] = array.asFloat32();
    if (r.values[static_cast<int>(l)].size() != array.elementCount()) {
      *error = quotedPath((root / (layerName(l) + ".npy")).string()) + ": not float32";
      return false;
    }
  }
  NpyArray observed;
  if (!readLayer("observed", &observed)) return false;
  r.observed = observed.asUint8();
  if (r.observed.size() != observed.elementCount()) {
    *error = quotedPath((root / "observed.npy").string()) + ": not uint8";
    return false;
  }
  *raster = std::move(r);
  return true;
}

bool readMapInput(const std::string& path, EvidentialGridMap* map, MapInput* input,
                  std::string* error) {
  const fs::path p(path);
  MapInput in;
  const fs::path map_file = isDirectory(p) ? p / kMapFileName : p;
  if (isFile(map_file)) {
    in.kind = MapInput::Kind::kMapFile;
    in.path = map_file.string();
    if (!readMapFile(in.path, map, &in.info, error)) return false;
    *input = in;
    return true;
  }
  if (!isDirectory(p)) {
    *error = "map " + quotedPath(path) + " does not exist";
    return false;
  }
  fs::path layers = p / "layers";
  if (!isFile(layers / "map.yaml")) layers = p;  // the layers directory itself
  if (!isFile(layers / "map.yaml")) {
    *error = quotedPath(path) + " holds no " + kMapFileName + " and no layers/map.yaml: not a map";
    return false;
  }
  LayerRaster raster;
  if (!readLayerDirectory(layers.string(), &raster, error)) return false;
  std::string why;
  EvidentialGridMap rebuilt;
  if (!fusion::mapFromLayers(raster, &rebuilt, &in.offset, &why)) {
    *error = quotedPath(layers.string()) + ": " + why;
    return false;
  }
  in.kind = MapInput::Kind::kLayers;
  in.path = (layers / "map.yaml").string();
  *map = std::move(rebuilt);
  *input = in;
  return true;
}

}  // namespace io
}  // namespace evidential_slam
