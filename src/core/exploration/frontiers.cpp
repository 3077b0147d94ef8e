#include "evidential_slam/core/exploration/frontiers.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {
namespace exploration {
namespace {

constexpr int k4[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
constexpr int k8[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};

// 8-connected components of the cells where `member` is true, each a list of indices.
template <typename Member>
std::vector<std::vector<int>> clusters(const GridGeometry& g, Member&& member) {
  std::vector<std::vector<int>> out;
  std::vector<uint8_t> seen(static_cast<size_t>(g.size()), 0);
  std::vector<int> stack;
  for (int start = 0; start < g.size(); ++start) {
    if (seen[start] || !member(start)) continue;
    out.emplace_back();
    seen[start] = 1;
    stack.push_back(start);
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      out.back().push_back(i);
      for (const auto& d : k8) {
        const int c = g.col(i) + d[0], r = g.row(i) + d[1];
        if (!g.inside(c, r)) continue;
        const int j = g.index(c, r);
        if (!seen[j] && member(j)) {
          seen[j] = 1;
          stack.push_back(j);
        }
      }
    }
    std::sort(out.back().begin(), out.back().end());
  }
  return out;
}

Frontier describe(const GridGeometry& g, std::vector<int> cells, const Eigen::Vector2d& robot) {
  Frontier f;
  f.cells = std::move(cells);
  f.centroid.setZero();
  f.min_distance = std::numeric_limits<double>::infinity();
  for (int i : f.cells) {
    const Eigen::Vector2d p = g.center(i);
    f.centroid += p;
    f.min_distance = std::min(f.min_distance, (p - robot).norm());
  }
  f.centroid /= static_cast<double>(f.cells.size());
  f.size = static_cast<double>(f.cells.size()) * g.resolution;
  return f;
}

}  // namespace

bool parseStrategy(const std::string& name, Strategy* strategy) {
  if (name == "ns") {
    *strategy = Strategy::kNonSpecificity;
  } else if (name == "frontier") {
    *strategy = Strategy::kFrontier;
  } else if (name == "entropy") {
    *strategy = Strategy::kEntropy;
  } else {
    return false;
  }
  return true;
}

const char* strategyName(Strategy strategy) {
  switch (strategy) {
    case Strategy::kNonSpecificity:
      return "ns";
    case Strategy::kEntropy:
      return "entropy";
    default:
      return "frontier";
  }
}

Strategy FrontierConfig::kind() const {
  Strategy s = Strategy::kNonSpecificity;
  parseStrategy(strategy, &s);
  return s;
}

FrontierConfig::FrontierConfig() { ES_EXPLORER_GOAL_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool FrontierConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_EXPLORER_GOAL_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  Strategy s;
  if (ok && !parseStrategy(strategy, &s)) {
    if (why != nullptr) *why = "strategy must be ns, entropy or frontier, not '" + strategy + "'";
    return false;
  }
  return ok;
}

std::vector<Frontier> findFrontiers(const GridGeometry& g, const std::vector<CellClass>& classes,
                                    const Eigen::Vector2d& robot, const FrontierConfig& config) {
  auto is_frontier = [&](int i) {
    if (classes[i] != CellClass::kFree) return false;
    const int c = g.col(i), r = g.row(i);
    for (const auto& d : k4) {
      if (!g.inside(c + d[0], r + d[1]) ||
          classes[g.index(c + d[0], r + d[1])] == CellClass::kUnknown) {
        return true;
      }
    }
    return false;
  };
  std::vector<Frontier> out;
  for (auto& cells : clusters(g, is_frontier)) {
    Frontier f = describe(g, std::move(cells), robot);
    if (f.size + 1e-9 >= config.min_frontier_size) out.push_back(std::move(f));
  }
  return out;
}

double visibleGain(const LayerRaster& raster, const std::vector<CellClass>& classes, Layer layer,
                   const Eigen::Vector2d& viewpoint, double range, int rays) {
  const GridGeometry g = GridGeometry::of(raster);
  const auto& values = raster.layer(layer);
  const double step = g.resolution;
  const int samples = static_cast<int>(std::lround(range / step));
  const double dphi = 2.0 * M_PI / rays;
  double total = 0.0;
  for (int k = 0; k < rays; ++k) {
    const double phi = (k + 0.5) * dphi;
    const Eigen::Vector2d dir(std::cos(phi), std::sin(phi));
    double ray = 0.0;
    for (int s = 0; s < samples; ++s) {
      const double r = (s + 0.5) * step;
      int c = 0, row = 0;
      const Eigen::Vector2d p = viewpoint + r * dir;
      g.cellOf(p.x(), p.y(), &c, &row);
      double value = 1.0;  // beyond the raster: never observed
      if (g.inside(c, row)) {
        const int i = g.index(c, row);
        if (classes[i] == CellClass::kOccupied) break;
        value = values[i];
      }
      ray += value * r;
    }
    total += ray;
  }
  return total * dphi * step;
}

std::vector<Frontier> findConflictClusters(const LayerRaster& raster, const Eigen::Vector2d& robot,
                                           const FrontierConfig& config) {
  const GridGeometry g = GridGeometry::of(raster);
  const auto& ec = raster.layer(Layer::kExternalConflict);
  auto suspect = [&](int i) { return ec[i] >= config.revisit_ec_threshold; };
  std::vector<Frontier> out;
  for (auto& cells : clusters(g, suspect)) {
    if (static_cast<int>(cells.size()) < config.revisit_min_cells) continue;
    Frontier f = describe(g, std::move(cells), robot);
    f.revisit = true;
    for (int i : f.cells) f.gain += ec[i] * g.resolution * g.resolution;
    out.push_back(std::move(f));
  }
  return out;
}

void placeGoals(const GridGeometry& g, const std::vector<CellClass>& classes,
                const std::vector<float>& cost_to_reach, const FrontierConfig& config,
                std::vector<Frontier>* frontiers) {
  for (Frontier& f : *frontiers) {
    f.reachable = false;
    f.goal_cell = -1;
    double best = std::numeric_limits<double>::infinity();
    auto consider = [&](int i, double badness) {
      if (cost_to_reach[i] >= CostGrid::kImpassable) return;
      if (badness < best || (badness == best && cost_to_reach[i] < cost_to_reach[f.goal_cell])) {
        best = badness;
        f.goal_cell = i;
      }
    };
    if (!f.revisit) {
      for (int i : f.cells) consider(i, (g.center(i) - f.centroid).norm());
    } else {
      // Free cells in a window around the cluster, the one nearest the standoff distance.
      const double reach = config.revisit_standoff + 2.0;
      int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
      g.cellOf(f.centroid.x() - reach, f.centroid.y() - reach, &c0, &r0);
      g.cellOf(f.centroid.x() + reach, f.centroid.y() + reach, &c1, &r1);
      for (int r = std::max(r0, 0); r <= std::min(r1, g.height - 1); ++r) {
        for (int c = std::max(c0, 0); c <= std::min(c1, g.width - 1); ++c) {
          const int i = g.index(c, r);
          if (classes[i] != CellClass::kFree) continue;
          consider(i, std::abs((g.center(i) - f.centroid).norm() - config.revisit_standoff));
        }
      }
    }
    if (f.goal_cell >= 0) {
      f.reachable = true;
      f.goal = g.center(f.goal_cell);
      f.path_cost = cost_to_reach[f.goal_cell];
    }
  }
}

void scoreFrontiers(const LayerRaster& raster, const std::vector<CellClass>& classes,
                    const FrontierConfig& config, std::vector<Frontier>* frontiers) {
  const double res = raster.resolution;
  const Strategy strategy = config.kind();
  for (Frontier& f : *frontiers) {
    if (!f.reachable) {
      f.utility = -std::numeric_limits<double>::infinity();
      continue;
    }
    const double discount = std::exp(-config.distance_decay * f.path_cost);
    if (f.revisit) {
      f.utility = config.revisit_weight * f.gain * discount;
    } else if (strategy != Strategy::kFrontier) {
      const Layer layer = strategy == Strategy::kEntropy ? Layer::kEntropy : Layer::kNonspecificity;
      f.gain = visibleGain(raster, classes, layer, f.goal, config.gain_range, config.gain_rays);
      f.utility = f.gain * discount;
    } else {
      const double cells = f.size / res;
      f.utility =
          -(config.potential_scale * f.min_distance * res - config.gain_scale * cells * res);
    }
  }
}

}  // namespace exploration
}  // namespace evidential_slam
