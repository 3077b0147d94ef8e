// evidential_octomap_info: reads an EvidentialOcTree (.evidential.ot, either layout) back through
// the library and prints its resolution, bounds, node counts and per-layer statistics of the masses
// and the anomaly; with --compare-layers it checks every voxel against the layers/ the offline
// runner wrote for the same map.
//   evidential_octomap_info FILE.ot [--compare-layers DIR]
// Exit codes: 0 success, 1 bad usage, 2 unreadable file or layers, 3 the masses differ from DIR.
#include <cstdio>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "evidential_slam/io/command_line.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/evidential_octree.h"
#include "evidential_slam/io/octomap_info.h"

namespace {

namespace es = evidential_slam;

int run(int argc, char** argv) {
  const std::string program = argc > 0 ? argv[0] : "evidential_octomap_info";
  std::string path, layers_dir;
  es::io::CommandLine cl(
      "usage: " + program +
          " FILE.ot [--compare-layers DIR]\n"
          "\n"
          "Reads an EvidentialOcTree file (evidential_slam's <name>.evidential.ot) and prints\n"
          "its resolution, bounds, node count and statistics of every layer over its voxels\n"
          "(the anomaly only in files that hold it: layout 2, id EvidentialAnomalyOcTree).",
      "Exit codes: 0 success, 1 bad usage, 2 unreadable file or layers, 3 the masses differ.");
  cl.positional("FILE", "the .evidential.ot file", &path, true);
  cl.option("--compare-layers", "DIR",
            "compare each voxel's masses (and anomaly) with a run's\n"
            "layers/ (the occupied/free/unknown/conflict/anomaly .npy\n"
            "files); exit 3 on any difference",
            [&](const std::string& v) { layers_dir = v; });
  if (const int code = cl.parseMain(argc, argv, 1); code >= 0) return code;
  if (path.empty()) {
    std::fprintf(stderr, "error: FILE is required (see --help)\n");
    return 1;
  }

  std::unique_ptr<es::io::EvidentialOcTree> tree;
  std::string error;
  if (!es::io::readEvidentialOctree(path, &tree, &error)) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return 2;
  }
  const es::io::OctreeStats s = es::io::computeOctreeStats(*tree);
  std::printf("file:        %s\n", path.c_str());
  std::printf("type:        %s (layout %d), resolution %.9g m\n", tree->getTreeType().c_str(),
              static_cast<int>(s.layout), s.resolution);
  std::printf("bounds:      x [%.4f, %.4f]  y [%.4f, %.4f]  z [%.4f, %.4f] m\n", s.min[0], s.max[0],
              s.min[1], s.max[1], s.min[2], s.max[2]);
  std::printf("nodes:       %zu (%zu leaves), %llu voxels in %zu height layer(s)\n", s.nodes,
              s.leaves, static_cast<unsigned long long>(s.voxels), s.voxels_per_z_key.size());
  std::printf("occupancy:   %llu voxels occupied, %llu free (BetP(o) >= 0.5 is occupied)\n",
              static_cast<unsigned long long>(s.occupied_voxels),
              static_cast<unsigned long long>(s.voxels - s.occupied_voxels));
  std::printf("%-20s %12s %12s %12s\n", "layer", "min", "mean", "max");
  for (int l = 0; l < es::kLayerCount; ++l) {
    if (static_cast<es::Layer>(l) == es::Layer::kAnomaly && !s.has_anomaly) continue;
    std::printf("%-20s %12.6f %12.6f %12.6f\n", es::layerNames()[l].c_str(), s.layers[l].min,
                s.layers[l].mean, s.layers[l].max);
  }
  if (s.has_anomaly) {
    std::printf("anomaly:     %llu voxels with an anomaly, %.6g bits over all voxels\n",
                static_cast<unsigned long long>(s.anomaly_voxels), s.anomaly_voxel_bits);
  } else {
    std::printf(
        "anomaly:     not in this file (layout 1, written before the anomaly was exported)\n");
  }
  if (layers_dir.empty()) return 0;

  es::io::LayerComparison cmp;
  if (!es::io::compareWithLayers(*tree, s, layers_dir, &cmp, &error)) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return 2;
  }
  std::printf(
      "compare:     %llu observed cells x %zu layer(s) = %llu voxels vs %s: %llu missing, %llu "
      "extra; max |diff| m(o) %.3g, m(e) %.3g, m(Theta) %.3g, m(empty set) %.3g\n",
      static_cast<unsigned long long>(cmp.cells), s.voxels_per_z_key.size(),
      static_cast<unsigned long long>(cmp.voxels_checked), layers_dir.c_str(),
      static_cast<unsigned long long>(cmp.missing_voxels),
      static_cast<unsigned long long>(cmp.extra_voxels), cmp.max_abs_diff[0], cmp.max_abs_diff[1],
      cmp.max_abs_diff[2], cmp.max_abs_diff[3]);
  if (cmp.anomaly_compared)
    std::printf("             max |diff| anomaly %.3g bits\n", cmp.anomaly_max_abs_diff);
  const bool same = cmp.identical(1e-6);
  const char* what = cmp.anomaly_compared ? "masses and anomaly" : "masses";
  std::printf("result:      %s %s\n", same ? "identical" : "DIFFERENT", what);
  return same ? 0 : 3;
}

}  // namespace

// Every exception ends here as one line (exit 2): nothing of a file reaches the terminal raw.
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", es::io::oneLineMessage(e.what()).c_str());
  }
  return 2;
}
