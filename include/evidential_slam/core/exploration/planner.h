// Path planning on the pignistic map: a cost grid (obstacles inflated by the robot's radius, a
// cost that decays away from walls like costmap_2d's inflation, unknown cells passable or not),
// Dijkstra's cost to reach every cell from the robot (to weigh goals), and A* (8-connected,
// octile heuristic) with a shortcutting pass for the path to the chosen goal.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/parameter_fields/explorer_planner.h"

namespace evidential_slam {
namespace exploration {

// The wall cost of a cell at clearance c (robot_radius <= c < inflation_radius) multiplies a
// step's length by 1 + wall_cost · exp(-cost_scaling_factor · (c - robot_radius)); 1 beyond.
struct PlannerConfig {
  PlannerConfig();  // the table's defaults
  ES_EXPLORER_PLANNER_FIELDS

  bool isValid(std::string* why) const;
};

class CostGrid {
 public:
  // Obstacles are the kOccupied cells. A cell's clearance is the distance from its centre to the
  // nearest obstacle cell's centre less half a cell. Cells within robot_radius of `robot` (the
  // robot stands there: the laser's blind spot behind it, or a map that drifted onto it) stay
  // passable whatever their class.
  CostGrid(const GridGeometry& geometry, const std::vector<CellClass>& classes,
           const PlannerConfig& config, const Eigen::Vector2d* robot = nullptr);

  const GridGeometry& geometry() const { return geometry_; }
  const PlannerConfig& config() const { return config_; }
  // Multiplier of a step's length in the cell: >= 1, +inf when impassable.
  float cost(int index) const { return cost_[index]; }
  bool passable(int index) const { return cost_[index] < kImpassable; }
  // m from the cell's centre to the nearest obstacle cell less half a cell (large when none).
  float clearance(int index) const { return clearance_[index]; }

  static constexpr float kImpassable = 1e30f;

 private:
  GridGeometry geometry_;
  PlannerConfig config_;
  std::vector<float> cost_;
  std::vector<float> clearance_;
};

// Dijkstra from the cell holding `start`: the cost (m, weighted by the cells' costs) of the
// cheapest 8-connected path to every cell; CostGrid::kImpassable where none exists or `start` is
// outside the grid. A step between neighbours costs its length times the mean of their costs;
// a diagonal step needs both cells beside it passable.
std::vector<float> costToReach(const CostGrid& grid, const Eigen::Vector2d& start);

struct PlanResult {
  bool found = false;
  std::vector<Eigen::Vector2d> path;  // start, the cells' centres (or shortcut corners), goal
  double cost = 0.0;                  // of the A* path (before shortcutting)
  std::string why;                    // when not found
};

// A* from `start` to `goal` over the same steps and costs as costToReach (octile heuristic, which
// is admissible: no cell costs less than 1).
PlanResult planPath(const CostGrid& grid, const Eigen::Vector2d& start,
                    const Eigen::Vector2d& goal);

// Cost of the straight segment a-b (m weighted by the costs of the cells it crosses, sampled at a
// quarter cell); kImpassable when it crosses an impassable cell or leaves the grid.
double segmentCost(const CostGrid& grid, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// Length (m) of a polyline.
double pathLength(const std::vector<Eigen::Vector2d>& path);

}  // namespace exploration
}  // namespace evidential_slam
