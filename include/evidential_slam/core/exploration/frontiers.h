// Exploration goals on a layer raster. Frontiers: free cells next to (4-neighbour) not yet
// observed cells, clustered 8-connected. Each is weighed by one of two strategies:
// - kNonSpecificity ("ns"): the non-specificity it expects to remove, the m(Θ) within the laser's
//   range and line of sight from the frontier's goal (ray casting on the raster, integrated over
//   the disc: m²), discounted by the path cost to reach it: gain · exp(-distance_decay · cost);
// - kEntropy ("entropy"): the probabilistic planner's information gain, the same rays and
//   discount summing the Shannon entropy H(BetP) (bits · m²) instead of NS: it cannot tell space
//   never measured from space measured with balanced evidence (glass, clutter, people), where more
//   measurements resolve nothing;
// - kFrontier ("frontier"): explore_lite's cost, potential_scale · distance − gain_scale · size
//   (its parameter names and defaults; see FrontierConfig).
// Optional revisit goals: clusters of high external conflict, where the map says something is
// wrong, weighed like frontiers by the conflict they hold.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/exploration/planner.h"
#include "evidential_slam/core/parameter_fields/explorer_goal.h"

namespace evidential_slam {
namespace exploration {

enum class Strategy { kNonSpecificity, kFrontier, kEntropy };
// "ns", "frontier" or "entropy"; false for anything else.
bool parseStrategy(const std::string& name, Strategy* strategy);
const char* strategyName(Strategy strategy);

// Frontier strategies' settings. The "frontier" strategy's cost of a frontier of `size` cells
// whose nearest cell lies `min_distance` m (straight line) from the robot is explore_lite's:
// potential_scale · min_distance · resolution − gain_scale · size · resolution (its distance term
// is multiplied by the resolution too). Its orientation_scale "does currently nothing"
// (explore_lite's documentation) and is not offered. Revisit goals (off by default) are weighed
// in both strategies as revisit_weight · gain · exp(-distance_decay · path_cost), their gain the
// bit·m² of external conflict in the cluster.
struct FrontierConfig {
  FrontierConfig();  // the table's defaults
  ES_EXPLORER_GOAL_FIELDS

  // The strategy `strategy` names (isValid refuses other names).
  Strategy kind() const;
  bool isValid(std::string* why) const;
};

struct Frontier {
  std::vector<int> cells;     // raster indices
  Eigen::Vector2d centroid;   // mean of the cells' centres
  double size = 0.0;          // m: cells × resolution
  double min_distance = 0.0;  // m, straight line from the robot to the nearest cell
  bool reachable = false;     // some cell of it can be reached
  int goal_cell = -1;         // the reachable cell nearest the centroid
  Eigen::Vector2d goal = Eigen::Vector2d::Zero();
  double path_cost = 0.0;  // costToReach at the goal cell
  double gain = 0.0;       // "ns": m² of m(Θ) seen from the goal; "entropy": bit·m² of H(BetP);
                           // revisit: bit·m² of EC
  double utility = 0.0;    // higher is better (the "frontier" strategy: minus explore_lite's cost)
  bool revisit = false;    // a conflict cluster, not a frontier
};

// The frontier clusters of `classes` (cells outside the raster count as unknown), each with its
// centroid, size and straight-line distance from `robot`; those below min_frontier_size dropped.
std::vector<Frontier> findFrontiers(const GridGeometry& geometry,
                                    const std::vector<CellClass>& classes,
                                    const Eigen::Vector2d& robot, const FrontierConfig& config);

// The `layer` visible from `viewpoint` within `range`: Σ over `rays` rays evenly spread over the
// circle and samples at r = (k + ½)·resolution of value(cell)·r·Δφ·resolution, the integral of
// the layer over the visible part of the disc: a disc of value 1 gives πr², and no gain exceeds
// the sensor's footprint times the layer's largest value. A ray stops at the first occupied cell
// (classes); beyond the raster cells count as never observed (value 1: NS 1, H 1 bit) and do not
// stop it.
double visibleGain(const LayerRaster& raster, const std::vector<CellClass>& classes, Layer layer,
                   const Eigen::Vector2d& viewpoint, double range, int rays);
inline double visibleNonSpecificity(const LayerRaster& raster,
                                    const std::vector<CellClass>& classes,
                                    const Eigen::Vector2d& viewpoint, double range, int rays) {
  return visibleGain(raster, classes, Layer::kNonspecificity, viewpoint, range, rays);
}

// Clusters (8-connected, at least revisit_min_cells) of cells whose EC reaches
// revisit_ec_threshold, each with gain = Σ EC · cell area; reachable/goal/path_cost unset.
std::vector<Frontier> findConflictClusters(const LayerRaster& raster, const Eigen::Vector2d& robot,
                                           const FrontierConfig& config);

// Fills reachable, goal_cell, goal and path_cost of each frontier from `cost_to_reach`
// (costToReach from the robot): the reachable cell of the cluster nearest its centroid. For a
// revisit cluster: the reachable free cell nearest to revisit_standoff from its centroid.
void placeGoals(const GridGeometry& geometry, const std::vector<CellClass>& classes,
                const std::vector<float>& cost_to_reach, const FrontierConfig& config,
                std::vector<Frontier>* frontiers);

// Sets gain (strategies "ns" and "entropy", frontiers only) and utility of each reachable goal.
void scoreFrontiers(const LayerRaster& raster, const std::vector<CellClass>& classes,
                    const FrontierConfig& config, std::vector<Frontier>* frontiers);

}  // namespace exploration
}  // namespace evidential_slam
