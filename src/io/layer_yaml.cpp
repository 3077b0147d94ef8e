// A layer folder's map.yaml. See layer_yaml.h.
#include "evidential_slam/io/layer_yaml.h"

#include <cmath>
#include <exception>

#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/io/strict_yaml.h"

namespace evidential_slam {
namespace io {

double layerExtentLimit() {
  static const double limit = [] {
    for (const ParameterSpec& spec : sharedParameterSpecs()) {
      if (std::string(spec.name) == "max_map_extent") return spec.max;
    }
    return 1e5;
  }();
  return limit;
}

namespace {

bool layerMapYaml(const YAML::Node& yaml, const std::string& source, double* resolution,
                  double* origin_x, double* origin_y, std::string* error) {
  auto fail = [&](const std::string& why) {
    *error = source + ": " + why;
    return false;
  };
  if (!yaml.IsMap()) return fail("not a map of `key: value` lines");
  std::string why;
  try {
    double res = 0.0, x = 0.0, y = 0.0, theta = 0.0;
    if (!strictYamlNumber(yaml["resolution"], "resolution", &res, &why)) return fail(why);
    if (!(res >= MapFileLimits::kMinResolution && res <= MapFileLimits::kMaxResolution)) {
      return fail("'resolution' " + std::to_string(res) + " m is outside [" +
                  std::to_string(MapFileLimits::kMinResolution) + ", " +
                  std::to_string(MapFileLimits::kMaxResolution) + "]");
    }
    const YAML::Node origin = yaml["origin"];
    if (!origin.IsSequence() || origin.size() < 2 || origin.size() > 3) {
      return fail("'origin' is not a list [x, y] or [x, y, theta]");
    }
    if (!strictYamlNumber(origin[0], "origin[0]", &x, &why) ||
        !strictYamlNumber(origin[1], "origin[1]", &y, &why)) {
      return fail(why);
    }
    if (origin.size() == 3) {
      if (!strictYamlNumber(origin[2], "origin[2]", &theta, &why)) return fail(why);
      if (theta != 0.0) return fail("'origin': a rotated origin is not a layer raster");
    }
    const double limit = layerExtentLimit();
    if (std::abs(x) > limit || std::abs(y) > limit) {
      return fail("'origin' (" + std::to_string(x) + ", " + std::to_string(y) +
                  ") m is farther than " + std::to_string(limit) +
                  " m (the largest max_map_extent) from the map's frame");
    }
    *resolution = res;
    *origin_x = x;
    *origin_y = y;
  } catch (const std::exception& e) {
    return fail(oneLineMessage(e.what()));
  }
  return true;
}

}  // namespace

bool parseLayerMapYaml(const std::string& text, const std::string& source, double* resolution,
                       double* origin_x, double* origin_y, std::string* error) {
  YAML::Node yaml;
  if (!loadStrictYaml(text, source, &yaml, error)) return false;
  return layerMapYaml(yaml, source, resolution, origin_x, origin_y, error);
}

bool readLayerMapYaml(const std::string& path, double* resolution, double* origin_x,
                      double* origin_y, std::string* error) {
  YAML::Node yaml;
  if (!loadStrictYamlFile(path, &yaml, error)) return false;
  return layerMapYaml(yaml, quotedPath(path), resolution, origin_x, origin_y, error);
}

}  // namespace io
}  // namespace evidential_slam
