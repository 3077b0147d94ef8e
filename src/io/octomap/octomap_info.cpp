// Statistics of an EvidentialOcTree and the comparison with layers/. See octomap_info.h.
#include "evidential_slam/io/octomap_info.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <vector>

#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/layer_yaml.h"
#include "evidential_slam/io/npy.h"

namespace evidential_slam {
namespace io {

OctreeStats computeOctreeStats(const EvidentialOcTree& tree) {
  OctreeStats s;
  s.resolution = tree.getResolution();
  s.nodes = tree.size();
  s.layout = tree.layout();
  s.has_anomaly = tree.layout() != EvidentialLayout::kMasses;
  std::array<double, kLayerCount> sum{};
  s.min.fill(std::numeric_limits<double>::max());
  s.max.fill(std::numeric_limits<double>::lowest());
  for (int l = 0; l < kLayerCount; ++l) {
    s.layers[l].min = std::numeric_limits<double>::max();
    s.layers[l].max = std::numeric_limits<double>::lowest();
  }
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    ++s.leaves;
    const unsigned level = tree.getTreeDepth() - it.getDepth();
    const uint64_t side = uint64_t{1} << level;  // finest voxels per axis
    const uint64_t count = side * side * side;
    s.voxels += count;
    if (tree.isNodeOccupied(*it)) s.occupied_voxels += count;
    const octomap::OcTreeKey corner = it.getIndexKey();
    for (uint64_t z = 0; z < side; ++z) s.voxels_per_z_key[corner[2] + z] += side * side;
    const double half = 0.5 * it.getSize();
    const double centre[3] = {it.getX(), it.getY(), it.getZ()};
    for (int a = 0; a < 3; ++a) {
      s.min[a] = std::min(s.min[a], centre[a] - half);
      s.max[a] = std::max(s.max[a], centre[a] + half);
    }
    if (it->anomaly() > 0.0f) {
      s.anomaly_voxels += count;
      s.anomaly_voxel_bits += static_cast<double>(it->anomaly()) * static_cast<double>(count);
    }
    for (int l = 0; l < kLayerCount; ++l) {
      const double v = static_cast<Layer>(l) == Layer::kAnomaly
                           ? static_cast<double>(it->anomaly())
                           : layerValue(it->cell(), static_cast<Layer>(l));
      s.layers[l].min = std::min(s.layers[l].min, v);
      s.layers[l].max = std::max(s.layers[l].max, v);
      sum[l] += v * static_cast<double>(count);
    }
  }
  if (s.leaves == 0) {
    s.min.fill(0.0);
    s.max.fill(0.0);
    s.layers.fill(LayerStats());
    return s;
  }
  for (int l = 0; l < kLayerCount; ++l) s.layers[l].mean = sum[l] / static_cast<double>(s.voxels);
  return s;
}

bool LayerComparison::identical(double tolerance) const {
  if (missing_voxels != 0 || extra_voxels != 0 || cells == 0) return false;
  if (anomaly_compared && !(anomaly_max_abs_diff <= tolerance)) return false;
  return std::all_of(max_abs_diff.begin(), max_abs_diff.end(),
                     [&](double d) { return d <= tolerance; });
}

bool compareWithLayers(const EvidentialOcTree& tree, const OctreeStats& stats,
                       const std::string& layers_dir, LayerComparison* comparison,
                       std::string* error) {
  *comparison = LayerComparison();
  std::string why;
  auto fail = [&](const std::string& w) {
    if (error) *error = w;
    return false;
  };
  double res = 0.0, origin_x = 0.0, origin_y = 0.0;
  if (!readLayerMapYaml(layers_dir + "/map.yaml", &res, &origin_x, &origin_y, &why)) {
    return fail(why);
  }
  if (std::abs(res - tree.getResolution()) > 1e-9 * res) {
    return fail("the layers' resolution differs from the tree's");
  }
  const Layer kMasses[4] = {Layer::kOccupied, Layer::kFree, Layer::kUnknown, Layer::kConflict};
  std::vector<std::vector<float>> masses;
  size_t rows = 0, cols = 0;
  // Every layer must have the shape of the first (readNpy bounds the shape by the file's size).
  auto readLayer = [&](const std::string& name, bool float32, NpyArray* a) {
    const std::string path = layers_dir + "/" + name + ".npy";
    if (!readNpy(path, a, &why)) return fail(why);
    if (a->shape.size() != 2) return fail(quotedPath(path) + ": 'shape' is not 2-D");
    if (masses.empty() && float32) {
      rows = a->shape[0];
      cols = a->shape[1];
    } else if (a->shape[0] != rows || a->shape[1] != cols) {
      return fail(quotedPath(path) + ": 'shape' differs from the other layers'");
    }
    if ((float32 ? a->asFloat32().size() : a->asUint8().size()) != rows * cols) {
      return fail(quotedPath(path) + ": 'descr' is not " + (float32 ? "float32" : "uint8"));
    }
    return true;
  };
  for (Layer l : kMasses) {
    NpyArray a;
    if (!readLayer(layerName(l), true, &a)) return false;
    masses.push_back(a.asFloat32());
  }
  NpyArray observed_npy;
  if (!readLayer("observed", false, &observed_npy)) return false;
  const std::vector<uint8_t> observed = observed_npy.asUint8();
  std::vector<float> anomaly;
  if (tree.layout() != EvidentialLayout::kMasses) {
    NpyArray a;
    if (!readLayer(layerName(Layer::kAnomaly), true, &a)) return false;
    anomaly = a.asFloat32();
    comparison->anomaly_compared = true;
  }

  // Cell (row, col) of the raster is grid cell (col0 + col, row0 + row), OctoMap key + 32768.
  const long col0 = std::lround(origin_x / res), row0 = std::lround(origin_y / res);
  uint64_t matched = 0;
  for (size_t r = 0; r < rows; ++r) {
    for (size_t c = 0; c < cols; ++c) {
      const size_t i = r * cols + c;
      if (!observed[i]) continue;
      ++comparison->cells;
      const long kx = col0 + static_cast<long>(c) + 32768, ky = row0 + static_cast<long>(r) + 32768;
      for (const auto& [kz, count] : stats.voxels_per_z_key) {
        (void)count;
        ++comparison->voxels_checked;
        const EvidentialOcTreeNode* node = nullptr;
        if (kx >= 0 && kx <= 65535 && ky >= 0 && ky <= 65535) {
          node = tree.search(octomap::OcTreeKey(
              static_cast<uint16_t>(kx), static_cast<uint16_t>(ky), static_cast<uint16_t>(kz)));
        }
        if (node == nullptr) {
          ++comparison->missing_voxels;
          continue;
        }
        ++matched;
        for (int m = 0; m < 4; ++m) {
          const float value = static_cast<float>(layerValue(node->cell(), kMasses[m]));
          comparison->max_abs_diff[m] = std::max(
              comparison->max_abs_diff[m], std::abs(static_cast<double>(value) - masses[m][i]));
        }
        if (!anomaly.empty()) {
          comparison->anomaly_max_abs_diff =
              std::max(comparison->anomaly_max_abs_diff,
                       std::abs(static_cast<double>(node->anomaly()) - anomaly[i]));
        }
      }
    }
  }
  comparison->extra_voxels = stats.voxels - matched;
  return true;
}

}  // namespace io
}  // namespace evidential_slam
