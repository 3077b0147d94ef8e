// The map.yaml of a layer folder (layers/, written by layer_writer.h): what the layer readers
// (map_input.h, octomap_info.h) take from it, read strictly and bounded.
#pragma once

#include <string>

namespace evidential_slam {
namespace io {

// How far from its frame's origin a layer raster may reach, in m: the parameter table's largest
// max_map_extent (the SLAM never maps farther from where it started).
double layerExtentLimit();

// A layer folder's map.yaml (strict_yaml.h): the resolution within the map file's range, the
// origin [x, y(, 0)] within layerExtentLimit(). False and a one-line `error` naming the path and
// the field otherwise.
bool parseLayerMapYaml(const std::string& text, const std::string& source, double* resolution,
                       double* origin_x, double* origin_y, std::string* error);
bool readLayerMapYaml(const std::string& path, double* resolution, double* origin_x,
                      double* origin_y, std::string* error);

}  // namespace io
}  // namespace evidential_slam
