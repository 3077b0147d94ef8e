#include "evidential_slam/core/exploration/planner.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {
namespace exploration {
namespace {

constexpr double kSqrt2 = 1.4142135623730951;
constexpr float kFarSquared = 1e20f;  // squared distance (cells²) of a cell with no obstacle

// Squared Euclidean distance transform of one line (Felzenszwalb & Huttenlocher, "Distance
// Transforms of Sampled Functions", 2012): d[q] = min_p (q - p)² + f[p], the lower envelope of
// the parabolas rooted at each p. v: scratch of n entries, z: of n + 1.
void distanceTransform1d(const float* f, int n, float* d, int* v, float* z) {
  auto intersection = [f](int q, int p) {
    return ((f[q] + static_cast<float>(q) * q) - (f[p] + static_cast<float>(p) * p)) /
           (2.0f * static_cast<float>(q - p));
  };
  int k = 0;
  v[0] = 0;
  z[0] = -kFarSquared;
  z[1] = kFarSquared;
  for (int q = 1; q < n; ++q) {
    float s = intersection(q, v[k]);
    while (s <= z[k]) {  // never below k = 0: f <= kFarSquared keeps s above -kFarSquared
      --k;
      s = intersection(q, v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kFarSquared;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < static_cast<float>(q)) ++k;
    const float dq = static_cast<float>(q - v[k]);
    d[q] = dq * dq + f[v[k]];
  }
}

// Squared distance (cells²) from each cell's centre to the nearest obstacle cell's centre.
std::vector<float> squaredObstacleDistance(const GridGeometry& g,
                                           const std::vector<CellClass>& classes) {
  const int w = g.width, h = g.height;
  std::vector<float> d(static_cast<size_t>(g.size()));
  for (size_t i = 0; i < d.size(); ++i) {
    d[i] = classes[i] == CellClass::kOccupied ? 0.0f : kFarSquared;
  }
  const int n = std::max(w, h);
  std::vector<float> f(n), out(n), z(n + 1);
  std::vector<int> v(n);
  for (int c = 0; c < w; ++c) {
    for (int r = 0; r < h; ++r) f[r] = d[g.index(c, r)];
    distanceTransform1d(f.data(), h, out.data(), v.data(), z.data());
    for (int r = 0; r < h; ++r) d[g.index(c, r)] = out[r];
  }
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) f[c] = d[g.index(c, r)];
    distanceTransform1d(f.data(), w, out.data(), v.data(), z.data());
    for (int c = 0; c < w; ++c) d[g.index(c, r)] = out[c];
  }
  return d;
}

struct Neighbour {
  int dc, dr;
  double length;  // in cells
};
constexpr Neighbour kNeighbours[8] = {{1, 0, 1.0},     {-1, 0, 1.0},    {0, 1, 1.0},
                                      {0, -1, 1.0},    {1, 1, kSqrt2},  {1, -1, kSqrt2},
                                      {-1, 1, kSqrt2}, {-1, -1, kSqrt2}};

// Calls fn(neighbour index, step cost) for each neighbour of `i` that can be stepped to.
template <typename Fn>
void forEachStep(const CostGrid& grid, int i, Fn&& fn) {
  const GridGeometry& g = grid.geometry();
  const int c = g.col(i), r = g.row(i);
  const float here = grid.cost(i);
  for (const Neighbour& n : kNeighbours) {
    const int nc = c + n.dc, nr = r + n.dr;
    if (!g.inside(nc, nr)) continue;
    const int j = g.index(nc, nr);
    if (!grid.passable(j)) continue;
    if (n.dc != 0 && n.dr != 0 &&
        (!grid.passable(g.index(nc, r)) || !grid.passable(g.index(c, nr)))) {
      continue;  // no corner cutting
    }
    fn(j, n.length * g.resolution * 0.5 * (here + grid.cost(j)));
  }
}

using QueueEntry = std::pair<double, int>;
using MinQueue = std::priority_queue<QueueEntry, std::vector<QueueEntry>, std::greater<QueueEntry>>;

// Octile distance between two cells (m).
double octile(const GridGeometry& g, int a, int b) {
  const int dc = std::abs(g.col(a) - g.col(b)), dr = std::abs(g.row(a) - g.row(b));
  return g.resolution * (std::max(dc, dr) + (kSqrt2 - 1.0) * std::min(dc, dr));
}

}  // namespace

PlannerConfig::PlannerConfig() { ES_EXPLORER_PLANNER_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool PlannerConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_EXPLORER_PLANNER_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (ok && inflation_radius < robot_radius) {
    if (why != nullptr) *why = "inflation_radius must not be below robot_radius";
    return false;
  }
  return ok;
}

CostGrid::CostGrid(const GridGeometry& geometry, const std::vector<CellClass>& classes,
                   const PlannerConfig& config, const Eigen::Vector2d* robot)
    : geometry_(geometry), config_(config) {
  const size_t n = static_cast<size_t>(geometry.size());
  const std::vector<float> squared = squaredObstacleDistance(geometry, classes);
  const double res = geometry.resolution;
  cost_.assign(n, 1.0f);
  clearance_.assign(n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    const double clearance =
        squared[i] >= kFarSquared ? 1e6 : std::max(0.0, (std::sqrt(squared[i]) - 0.5) * res);
    clearance_[i] = static_cast<float>(clearance);
    if (classes[i] == CellClass::kOccupied || clearance < config.robot_radius ||
        (classes[i] == CellClass::kUnknown && !config.unknown_passable)) {
      cost_[i] = kImpassable;
    } else if (clearance < config.inflation_radius) {
      cost_[i] =
          static_cast<float>(1.0 + config.wall_cost * std::exp(-config.cost_scaling_factor *
                                                               (clearance - config.robot_radius)));
    }
  }
  if (robot != nullptr) {
    int rc = 0, rr = 0;
    geometry.cellOf(robot->x(), robot->y(), &rc, &rr);
    const int reach = static_cast<int>(std::ceil(config.robot_radius / res));
    for (int r = rr - reach; r <= rr + reach; ++r) {
      for (int c = rc - reach; c <= rc + reach; ++c) {
        if (!geometry.inside(c, r)) continue;
        const int i = geometry.index(c, r);
        if ((geometry.center(i) - *robot).norm() > config.robot_radius + 0.5 * res) continue;
        if (!passable(i)) cost_[i] = static_cast<float>(1.0 + config.wall_cost);
      }
    }
  }
}

std::vector<float> costToReach(const CostGrid& grid, const Eigen::Vector2d& start) {
  const GridGeometry& g = grid.geometry();
  std::vector<float> cost(static_cast<size_t>(g.size()), CostGrid::kImpassable);
  const int s = g.indexOf(start);
  if (s < 0 || !grid.passable(s)) return cost;
  // Float keys: half the heap's memory traffic of doubles, and precise enough for costs of a
  // few hundred metres.
  using Entry = std::pair<float, int>;
  std::vector<Entry> storage;
  storage.reserve(cost.size());
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open(std::greater<Entry>(),
                                                                           std::move(storage));
  cost[s] = 0.0f;
  open.push({0.0f, s});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > cost[i]) continue;
    forEachStep(grid, i, [&](int j, double step) {
      const float reached = d + static_cast<float>(step);
      if (reached < cost[j]) {
        cost[j] = reached;
        open.push({reached, j});
      }
    });
  }
  return cost;
}

double segmentCost(const CostGrid& grid, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const GridGeometry& g = grid.geometry();
  const double length = (b - a).norm();
  const int samples = std::max(1, static_cast<int>(std::ceil(length / (0.25 * g.resolution))));
  const double ds = length / samples;
  double total = 0.0;
  for (int k = 0; k < samples; ++k) {
    const int i = g.indexOf(a + (b - a) * ((k + 0.5) / samples));
    if (i < 0 || !grid.passable(i)) return CostGrid::kImpassable;
    total += grid.cost(i) * ds;
  }
  return total;
}

double pathLength(const std::vector<Eigen::Vector2d>& path) {
  double length = 0.0;
  for (size_t k = 1; k < path.size(); ++k) length += (path[k] - path[k - 1]).norm();
  return length;
}

PlanResult planPath(const CostGrid& grid, const Eigen::Vector2d& start,
                    const Eigen::Vector2d& goal) {
  PlanResult result;
  const GridGeometry& g = grid.geometry();
  const int s = g.indexOf(start), t = g.indexOf(goal);
  if (s < 0 || t < 0) {
    result.why = s < 0 ? "start is outside the map" : "goal is outside the map";
    return result;
  }
  if (!grid.passable(s) || !grid.passable(t)) {
    result.why = !grid.passable(s) ? "start cell is impassable" : "goal cell is impassable";
    return result;
  }
  std::vector<double> best(static_cast<size_t>(g.size()), std::numeric_limits<double>::infinity());
  std::vector<int> parent(best.size(), -1);
  std::vector<uint8_t> closed(best.size(), 0);
  MinQueue open;
  best[s] = 0.0;
  open.push({octile(g, s, t), s});
  while (!open.empty()) {
    const int i = open.top().second;
    open.pop();
    if (closed[i]) continue;
    closed[i] = 1;
    if (i == t) break;
    forEachStep(grid, i, [&](int j, double step) {
      if (closed[j] || best[i] + step >= best[j]) return;
      best[j] = best[i] + step;
      parent[j] = i;
      open.push({best[j] + octile(g, j, t), j});
    });
  }
  if (!closed[t]) {
    result.why = "no path: the goal is cut off by obstacles" +
                 std::string(grid.config().unknown_passable ? "" : " or unknown space");
    return result;
  }
  std::vector<int> cells;
  for (int i = t; i != -1; i = parent[i]) cells.push_back(i);
  std::reverse(cells.begin(), cells.end());
  result.found = true;
  result.cost = best[t];

  // Points: the exact start and goal at the ends, cell centres between.
  std::vector<Eigen::Vector2d> points;
  points.reserve(cells.size() + 1);
  points.push_back(start);
  for (size_t k = 1; k + 1 < cells.size(); ++k) points.push_back(g.center(cells[k]));
  points.push_back(goal);
  if (!grid.config().smooth_path || points.size() <= 2) {
    result.path = std::move(points);
    return result;
  }
  // Greedy shortcuts: from each kept point, the farthest later point reachable by a straight
  // segment that costs no more than the A* run it replaces.
  std::vector<double> run(points.size(), 0.0);  // A* cost from the start to each point
  for (size_t k = 1; k < points.size(); ++k) run[k] = best[cells[std::min(k, cells.size() - 1)]];
  size_t anchor = 0;
  result.path.push_back(points[0]);
  while (anchor + 1 < points.size()) {
    size_t reach = anchor + 1;
    for (size_t j = anchor + 2; j < points.size(); ++j) {
      const double straight = segmentCost(grid, points[anchor], points[j]);
      if (straight > run[j] - run[anchor] + 1e-6) break;
      reach = j;
    }
    result.path.push_back(points[reach]);
    anchor = reach;
  }
  return result;
}

}  // namespace exploration
}  // namespace evidential_slam
