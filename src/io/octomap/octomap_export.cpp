// Grid -> OctoMap files (.evidential.ot, .bt, .color.ot). See octomap_export.h.
#include "evidential_slam/io/octomap_export.h"

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <system_error>

#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/evidential_octree.h"

namespace evidential_slam {
namespace io {

const char* const kEvidentialOtSuffix = ".evidential.ot";
const char* const kBinarySuffix = ".bt";
const char* const kColorOtSuffix = ".color.ot";

namespace fs = std::filesystem;

namespace {

// OctoMap's key of coordinate x is floor(x / res) + 32768 (tree_max_val), 16 bits per axis.
constexpr int kKeyOffset = 32768;
constexpr int kKeyMax = 65535;

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Calls fn(key_x, key_y, cell) for every observed cell of the box.
void forEachObserved(const EvidentialGridMap& grid, const CellBox& box,
                     const std::function<void(uint16_t, uint16_t, const Cell&)>& fn) {
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& c = grid.cell(x, y);
      if (c.observed())
        fn(static_cast<uint16_t>(x + kKeyOffset), static_cast<uint16_t>(y + kKeyOffset), c);
    }
  }
}

uint8_t channel(double mass) {
  return static_cast<uint8_t>(std::lround(255.0 * std::clamp(mass, 0.0, 1.0)));
}

}  // namespace

bool OctomapExportConfig::isValid(std::string* why) const {
  auto bad = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (!std::isfinite(z_min) || !std::isfinite(z_max)) return bad("octomap z_min/z_max not finite");
  if (z_min > z_max) return bad("octomap z_min must be <= z_max");
  if (max_layers < 1) return bad("octomap max_layers must be >= 1");
  return true;
}

bool exportOctomap(const EvidentialGridMap& grid, const OctomapExportConfig& config,
                   const std::string& path_prefix, OctomapExportResult* result, std::string* error,
                   AtomicFiles* staged) {
  return exportOctomap(grid, AnomalyGrid(), config, path_prefix, result, error, staged);
}

bool exportOctomap(const EvidentialGridMap& grid, const AnomalyGrid& anomaly,
                   const OctomapExportConfig& config, const std::string& path_prefix,
                   OctomapExportResult* result, std::string* error, AtomicFiles* staged) {
  AtomicFiles own;
  AtomicFiles* files = staged ? staged : &own;
  const auto t0 = Clock::now();
  *result = OctomapExportResult();
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  std::string why;
  if (!config.isValid(&why)) return fail(why);
  const double res = grid.resolution();

  const CellBox box = grid.observedBox();
  if (!box.empty() && (box.min_x < -kKeyOffset || box.min_y < -kKeyOffset ||
                       box.max_x > kKeyMax - kKeyOffset || box.max_y > kKeyMax - kKeyOffset)) {
    return fail("the map exceeds OctoMap's range of +-32768 cells from the origin");
  }
  // Voxel layers as OctoMap itself locates z_min and z_max.
  octomap::key_type kz_min = 0, kz_max = 0;
  {
    const octomap::OcTree probe(res);
    if (!probe.coordToKeyChecked(config.z_min, kz_min) ||
        !probe.coordToKeyChecked(config.z_max, kz_max)) {
      return fail("octomap z_min/z_max outside OctoMap's range at this resolution");
    }
  }
  const int layers = static_cast<int>(kz_max) - static_cast<int>(kz_min) + 1;
  if (layers > config.max_layers) {
    return fail("the octomap slab has " + std::to_string(layers) + " voxel layers, more than " +
                std::to_string(config.max_layers));
  }
  result->z_layers = layers;
  forEachObserved(grid, box, [&](uint16_t, uint16_t, const Cell&) { ++result->observed_cells; });
  result->voxels = result->observed_cells * static_cast<size_t>(layers);

  // Each tree is built, written and freed before the next one.
  auto forEachVoxel = [&](const std::function<void(const octomap::OcTreeKey&, const Cell&)>& fn) {
    forEachObserved(grid, box, [&](uint16_t kx, uint16_t ky, const Cell& c) {
      for (int kz = kz_min; kz <= kz_max; ++kz) {
        fn(octomap::OcTreeKey(kx, ky, static_cast<uint16_t>(kz)), c);
      }
    });
  };

  {  // Evidential: every mass and the anomaly; pruned where both are equal.
    const auto t = Clock::now();
    OctomapExportFile file{"evidential", path_prefix + kEvidentialOtSuffix};
    EvidentialOcTree tree(res, EvidentialLayout::kMassesAnomaly);
    forEachObserved(grid, box, [&](uint16_t kx, uint16_t ky, const Cell& c) {
      const float bits = anomaly.empty() ? 0.0f : anomaly.at(kx - kKeyOffset, ky - kKeyOffset);
      for (int kz = kz_min; kz <= kz_max; ++kz) {
        tree.setNodeCell(octomap::OcTreeKey(kx, ky, static_cast<uint16_t>(kz)), c, bits);
      }
    });
    tree.updateInnerNodes();
    tree.prune();
    file.nodes = tree.size();
    if (!files->add(
            file.path, [&](std::ostream& s) { return tree.write(s); }, error, &file.bytes)) {
      return false;
    }
    file.seconds = secondsSince(t);
    result->files.push_back(file);
  }
  {  // Standard OcTree, binary: writeBinary thresholds BetP at 0.5 and prunes.
    const auto t = Clock::now();
    OctomapExportFile file{"binary", path_prefix + kBinarySuffix};
    octomap::OcTree tree(res);
    forEachVoxel([&](const octomap::OcTreeKey& key, const Cell& c) {
      tree.setNodeValue(key, occupancyLogOdds(c), /*lazy_eval=*/true);
    });
    tree.updateInnerOccupancy();
    if (!files->add(
            file.path, [&](std::ostream& s) { return tree.writeBinary(s); }, error, &file.bytes)) {
      return false;
    }
    file.nodes = tree.size();
    file.seconds = secondsSince(t);
    result->files.push_back(file);
  }
  {  // ColorOcTree: RGB = (m(o), m(e), m(Θ)). Not pruned: its pruning ignores colours.
    const auto t = Clock::now();
    OctomapExportFile file{"color", path_prefix + kColorOtSuffix};
    octomap::ColorOcTree tree(res);
    forEachVoxel([&](const octomap::OcTreeKey& key, const Cell& c) {
      const float value = occupancyLogOdds(c);
      octomap::ColorOcTreeNode* node = tree.setNodeValue(key, value, /*lazy_eval=*/true);
      node->setLogOdds(value);  // setNodeValue clamps to OctoMap's thresholds
      const Mass m = c.toMass();
      node->setColor(channel(m.occupied), channel(m.free), channel(m.unknown));
    });
    // Inner nodes: maximum value, average colour (ColorOcTree's version crashes on an empty tree).
    if (tree.getRoot() != nullptr) tree.updateInnerOccupancy();
    file.nodes = tree.size();
    if (!files->add(
            file.path, [&](std::ostream& s) { return tree.write(s); }, error, &file.bytes)) {
      return false;
    }
    file.seconds = secondsSince(t);
    result->files.push_back(file);
  }
  if (!staged && !own.commit(error)) return false;
  result->seconds = secondsSince(t0);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
