#include "evidential_slam/core/exploration/coverage.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {
namespace exploration {

std::vector<uint8_t> reachableFreeCells(const OccupancyImage& truth, const Eigen::Vector2d& start) {
  const GridGeometry& g = truth.geometry;
  std::vector<uint8_t> reachable(static_cast<size_t>(g.size()), 0);
  const int s = g.indexOf(start);
  if (s < 0 || truth.occupied[s] != 0) return reachable;
  std::vector<int> stack{s};
  reachable[s] = 1;
  constexpr int k4[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    for (const auto& d : k4) {
      const int c = g.col(i) + d[0], r = g.row(i) + d[1];
      if (!g.inside(c, r)) continue;
      const int j = g.index(c, r);
      if (reachable[j] || truth.occupied[j] != 0) continue;
      reachable[j] = 1;
      stack.push_back(j);
    }
  }
  return reachable;
}

double distanceToObstacle(const OccupancyImage& truth, const Eigen::Vector2d& p,
                          double max_distance) {
  const GridGeometry& g = truth.geometry;
  int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
  g.cellOf(p.x() - max_distance, p.y() - max_distance, &c0, &r0);
  g.cellOf(p.x() + max_distance, p.y() + max_distance, &c1, &r1);
  double nearest = max_distance;
  for (int r = std::max(r0, 0); r <= std::min(r1, g.height - 1); ++r) {
    for (int c = std::max(c0, 0); c <= std::min(c1, g.width - 1); ++c) {
      if (!truth.occupied[g.index(c, r)]) continue;
      const double x0 = g.origin_x + c * g.resolution, y0 = g.origin_y + r * g.resolution;
      const double dx = std::max({x0 - p.x(), 0.0, p.x() - (x0 + g.resolution)});
      const double dy = std::max({y0 - p.y(), 0.0, p.y() - (y0 + g.resolution)});
      nearest = std::min(nearest, std::hypot(dx, dy));
    }
  }
  return nearest;
}

double thetaGapBand(double free_gap, double hit_sigma, double resolution) {
  return free_gap * hit_sigma + resolution;
}

std::vector<uint8_t> cellsBeyondBand(const OccupancyImage& truth, const std::vector<uint8_t>& cells,
                                     double band) {
  const GridGeometry& g = truth.geometry;
  std::vector<uint8_t> out(cells.size(), 0);
  // A cap just above the band: "none within the band" reads as the cap.
  const double cap = band + 0.5 * g.resolution;
  for (int i = 0; i < g.size(); ++i) {
    if (cells[i] && distanceToObstacle(truth, g.center(i), cap) > band) out[i] = 1;
  }
  return out;
}

double knownFraction(const OccupancyImage& truth, const std::vector<uint8_t>& reachable,
                     const LayerRaster& map, const Pose2& map_in_truth, double max_ns) {
  const GridGeometry& g = truth.geometry;
  const GridGeometry m = GridGeometry::of(map);
  const auto& ns = map.layer(Layer::kNonspecificity);
  const auto& betp = map.layer(Layer::kPignistic);
  const Pose2 truth_in_map = map_in_truth.inverse();
  size_t total = 0, known = 0;
  for (int i = 0; i < g.size(); ++i) {
    if (!reachable[i]) continue;
    ++total;
    const int j = m.indexOf(truth_in_map.transformPoint(g.center(i)));
    if (j >= 0 && ns[j] < max_ns && betp[j] < 0.5) ++known;
  }
  return total == 0 ? 0.0 : static_cast<double>(known) / static_cast<double>(total);
}

}  // namespace exploration
}  // namespace evidential_slam
