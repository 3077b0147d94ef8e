#include "evidential_slam/io/map_input.h"

#include <cmath>
#include <exception>
#include <filesystem>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "evidential_slam/core/fusion/layer_map.h"
#include "evidential_slam/core/layers.h"
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
  try {
    const YAML::Node yaml = YAML::LoadFile(yaml_path.string());
    r.resolution = yaml["resolution"].as<double>();
    const YAML::Node origin = yaml["origin"];
    if (!origin.IsSequence() || origin.size() < 2) throw YAML::Exception(YAML::Mark(), "origin");
    r.origin_x = origin[0].as<double>();
    r.origin_y = origin[1].as<double>();
    if (origin.size() >= 3 && origin[2].as<double>() != 0.0) {
      *error = "'" + yaml_path.string() + "': a rotated origin is not a layer raster";
      return false;
    }
  } catch (const std::exception& e) {
    *error = "'" + yaml_path.string() + "': no resolution and origin (" + e.what() + ")";
    return false;
  }
  bool have_size = false;
  auto readLayer = [&](const std::string& name, NpyArray* array) {
    const std::string path = (root / (name + ".npy")).string();
    if (!readNpy(path, array, error)) return false;
    if (array->shape.size() != 2) {
      *error = "'" + path + "' is not a 2-D array";
      return false;
    }
    const int rows = static_cast<int>(array->shape[0]), cols = static_cast<int>(array->shape[1]);
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
      *error = "'" + (root / (layerName(l) + ".npy")).string() + "' is not float32";
      return false;
    }
  }
  NpyArray observed;
  if (!readLayer("observed", &observed)) return false;
  r.observed = observed.asUint8();
  if (r.observed.size() != observed.elementCount()) {
    *error = "'" + (root / "observed.npy").string() + "' is not uint8";
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
    *error = "map '" + path + "' does not exist";
    return false;
  }
  fs::path layers = p / "layers";
  if (!isFile(layers / "map.yaml")) layers = p;  // the layers directory itself
  if (!isFile(layers / "map.yaml")) {
    *error = "'" + path + "' holds no " + kMapFileName + " and no layers/map.yaml: not a map";
    return false;
  }
  LayerRaster raster;
  if (!readLayerDirectory(layers.string(), &raster, error)) return false;
  std::string why;
  EvidentialGridMap rebuilt;
  if (!fusion::mapFromLayers(raster, &rebuilt, &in.offset, &why)) {
    *error = "'" + layers.string() + "': " + why;
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
