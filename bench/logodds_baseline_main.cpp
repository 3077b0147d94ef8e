// evidential_slam_logodds_baseline: the probabilistic peer of the map-dynamics benchmark
// (bench/map_dynamics.py). OctoMap's log-odds occupancy tree with its own clamping (hit 0.7,
// miss 0.4, clamped to [0.12, 0.97]: OctoMap's defaults), fed the scans our SLAM processed at the
// poses our SLAM estimated (its trajectory.tum and the stamps of its conflict.csv), one voxel
// slab at z = 0. It can continue a saved tree (day 2) and writes the tree and a grid of
// occupancy probabilities over a window.
//   evidential_slam_logodds_baseline --rawlog F --trajectory T.tum --stamps conflict.csv
//       --grid-out G.txt --window X0,Y0,X1,Y1 [--load-tree IN.ot] [--save-tree OUT.ot]
//       [--resolution 0.05] [--usable-range 20]
// The grid file: a header line `x0 y0 resolution width height`, then `height` rows (lowest y
// first) of `width` integers: -1 unknown, else round(100 p(occupied)).
// The change-detection benchmark's peer score (bench/change_detection.py), with --flip-out and
// --scan-out: per cell, the sum of |delta log-odds| of the updates that flipped its sign (occupied
// <-> free; the first update of an unknown cell is not a flip), as a grid of the same window
// (floats); and per processed scan a line `stamp flip_sum flipped_cells`.
#include <octomap/octomap.h>

#include <unordered_map>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/io/trajectory_io.h"

namespace {

namespace es = evidential_slam;

constexpr double kSlabZ = 0.025;  // the one voxel slab's centre (0.05 m voxels)

int fail(const std::string& message) {
  std::fprintf(stderr, "error: %s\n", message.c_str());
  return 2;
}

// The stamps of the scans the SLAM processed: the first column of its conflict.csv.
bool readStamps(const std::string& path, std::vector<double>* stamps) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("stamp", 0) == 0) continue;
    stamps->push_back(std::stod(line.substr(0, line.find(','))));
  }
  return true;
}

// The pose of `poses` (sorted by stamp) at `stamp`, if one lies within 1 ms.
const es::StampedPose* poseAt(const std::vector<es::StampedPose>& poses, double stamp) {
  auto it = std::lower_bound(poses.begin(), poses.end(), stamp - 1e-3,
                             [](const es::StampedPose& p, double t) { return p.stamp < t; });
  if (it == poses.end() || std::abs(it->stamp - stamp) > 1e-3) return nullptr;
  return &*it;
}

}  // namespace

int main(int argc, char** argv) {
  std::string rawlog, trajectory, stamps_file, grid_out, load_tree, save_tree, flip_out, scan_out;
  double resolution = 0.05, usable_range = 20.0;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--rawlog")
      rawlog = value;
    else if (key == "--trajectory")
      trajectory = value;
    else if (key == "--stamps")
      stamps_file = value;
    else if (key == "--grid-out")
      grid_out = value;
    else if (key == "--load-tree")
      load_tree = value;
    else if (key == "--save-tree")
      save_tree = value;
    else if (key == "--flip-out")
      flip_out = value;
    else if (key == "--scan-out")
      scan_out = value;
    else if (key == "--resolution")
      resolution = std::stod(value);
    else if (key == "--usable-range")
      usable_range = std::stod(value);
    else if (key == "--window") {
      if (std::sscanf(value.c_str(), "%lf,%lf,%lf,%lf", &x0, &y0, &x1, &y1) != 4) {
        return fail("--window wants X0,Y0,X1,Y1");
      }
    } else {
      return fail("unknown option " + key);
    }
  }
  if (rawlog.empty() || trajectory.empty() || stamps_file.empty() || grid_out.empty() ||
      !(x1 > x0 && y1 > y0)) {
    std::fprintf(stderr,
                 "usage: %s --rawlog F --trajectory T.tum --stamps conflict.csv --grid-out G.txt "
                 "--window X0,Y0,X1,Y1 [--load-tree IN.ot] [--save-tree OUT.ot] "
                 "[--resolution M] [--usable-range M] [--flip-out F.txt] [--scan-out S.txt]\n",
                 argv[0]);
    return 1;
  }

  std::vector<es::StampedPose> poses;
  std::string error;
  if (!es::io::readTumTrajectory(trajectory, &poses, &error)) return fail(error);
  std::vector<double> stamps;
  if (!readStamps(stamps_file, &stamps)) return fail("cannot read " + stamps_file);
  std::set<long long> processed;  // stamps in ms
  for (double t : stamps) processed.insert(std::llround(t * 1e3));

  std::unique_ptr<octomap::OcTree> tree;
  if (!load_tree.empty()) {
    std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(load_tree));
    auto* t = dynamic_cast<octomap::OcTree*>(read.get());
    if (t == nullptr) return fail("cannot read an OcTree from " + load_tree);
    read.release();
    tree.reset(t);
  } else {
    tree = std::make_unique<octomap::OcTree>(resolution);
  }

  es::io::RawlogReader reader;
  if (!reader.open(rawlog, &error)) return fail(error);
  es::io::RawlogScan s;
  int inserted = 0;
  std::unordered_map<octomap::OcTreeKey, float, octomap::OcTreeKey::KeyHash> flips;
  std::ofstream scan_file;
  if (!scan_out.empty()) {
    scan_file.open(scan_out);
    if (!scan_file) return fail("cannot write " + scan_out);
    scan_file << "# stamp flip_sum flipped_cells\n";
  }
  // One update of a cell; its |delta log-odds| when it flips the sign.
  auto update = [&](const octomap::OcTreeKey& k, bool occupied, double* sum, int* cells) {
    const octomap::OcTreeNode* before = tree->search(k);
    const float l0 = before ? before->getLogOdds() : 0.0f;
    const octomap::OcTreeNode* after = tree->updateNode(k, occupied);
    const float l1 = after->getLogOdds();
    if (l0 != 0.0f && (l0 > 0.0f) != (l1 > 0.0f)) {
      flips[k] += std::abs(l1 - l0);
      *sum += std::abs(l1 - l0);
      ++*cells;
    }
  };
  while (reader.next(&s) == es::io::RawlogReader::Status::kScan) {
    if (processed.count(std::llround(s.scan.stamp * 1e3)) == 0) continue;
    const es::StampedPose* p = poseAt(poses, s.scan.stamp);
    if (p == nullptr) continue;
    const es::Pose2 sensor = p->pose.compose(s.scan.sensor_pose);
    octomap::Pointcloud cloud;
    const double sensor_max = s.scan.max_range > 0.0f ? s.scan.max_range : usable_range;
    for (size_t i = 0; i < s.scan.size(); ++i) {
      double r = s.scan.ranges[i];
      const bool no_return = !s.scan.valid.empty() && s.scan.valid[i] == 0;
      if (no_return)
        r = usable_range + 1.0;  // clears up to the usable range
      else if (!std::isfinite(r) || r < 0.05)
        continue;
      else if (r >= sensor_max)
        r = usable_range + 1.0;
      const double a = sensor.theta + s.scan.bearings[i];
      cloud.push_back(static_cast<float>(sensor.x + r * std::cos(a)),
                      static_cast<float>(sensor.y + r * std::sin(a)), static_cast<float>(kSlabZ));
    }
    const octomap::point3d origin(static_cast<float>(sensor.x), static_cast<float>(sensor.y),
                                  static_cast<float>(kSlabZ));
    if (flip_out.empty() && scan_out.empty()) {
      tree->insertPointCloud(cloud, origin, usable_range);
    } else {
      // What insertPointCloud does (occupied wins over free within a scan), one cell at a time.
      octomap::KeySet free_cells, occupied_cells;
      tree->computeUpdate(cloud, origin, free_cells, occupied_cells, usable_range);
      double sum = 0.0;
      int cells = 0;
      for (const auto& k : free_cells) {
        if (occupied_cells.find(k) == occupied_cells.end()) update(k, false, &sum, &cells);
      }
      for (const auto& k : occupied_cells) update(k, true, &sum, &cells);
      if (scan_file.is_open()) {
        char line[96];
        std::snprintf(line, sizeof(line), "%.6f %.6g %d\n", s.scan.stamp, sum, cells);
        scan_file << line;
      }
    }
    ++inserted;
  }
  if (!save_tree.empty() && !tree->write(save_tree)) return fail("cannot write " + save_tree);

  const int width = static_cast<int>(std::ceil((x1 - x0) / resolution));
  const int height = static_cast<int>(std::ceil((y1 - y0) / resolution));
  std::ostringstream out;
  out << x0 << ' ' << y0 << ' ' << resolution << ' ' << width << ' ' << height << '\n';
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const octomap::OcTreeNode* n =
          tree->search(x0 + (c + 0.5) * resolution, y0 + (r + 0.5) * resolution, kSlabZ);
      out << (c ? " " : "") << (n == nullptr ? -1 : std::lround(100.0 * n->getOccupancy()));
    }
    out << '\n';
  }
  std::ofstream file(grid_out);
  file << out.str();
  if (!file) return fail("cannot write " + grid_out);
  if (!flip_out.empty()) {
    std::ofstream f(flip_out);
    f << x0 << ' ' << y0 << ' ' << resolution << ' ' << width << ' ' << height << '\n';
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) {
        octomap::OcTreeKey k;
        float v = 0.0f;
        if (tree->coordToKeyChecked(x0 + (c + 0.5) * resolution, y0 + (r + 0.5) * resolution,
                                    kSlabZ, k)) {
          const auto it = flips.find(k);
          if (it != flips.end()) v = it->second;
        }
        f << (c ? " " : "") << v;
      }
      f << '\n';
    }
    if (!f) return fail("cannot write " + flip_out);
  }
  if (scan_file.is_open() && !scan_file.flush()) return fail("cannot write " + scan_out);
  std::printf("%d scans inserted; OctoMap hit %.2f miss %.2f clamping [%.3f, %.3f]\n", inserted,
              tree->getProbHit(), tree->getProbMiss(), tree->getClampingThresMin(),
              tree->getClampingThresMax());
  return 0;
}
