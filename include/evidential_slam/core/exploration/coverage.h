// How much of a world a map knows: the free cells of a ground-truth image that can be reached
// from the start, and the share of them the map holds as known free space (NS and BetP(o) both
// below 0.5: observed, and on the right side).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace exploration {

// A ground-truth map in core terms (io/ fills it from an image).
struct OccupancyImage {
  GridGeometry geometry;
  std::vector<uint8_t> occupied;  // 1 = obstacle, GridGeometry's layout

  bool occupiedAt(int col, int row) const {
    return geometry.inside(col, row) && occupied[geometry.index(col, row)] != 0;
  }
};

// 1 on the free cells 4-connected to the cell holding `start`, else 0 (all 0 when that cell is
// an obstacle or outside the image).
std::vector<uint8_t> reachableFreeCells(const OccupancyImage& truth, const Eigen::Vector2d& start);

// Distance (m) from `p` to the nearest obstacle cell's nearest point, capped at `max_distance`
// (obstacles further away are not looked for); 0 inside one.
double distanceToObstacle(const OccupancyImage& truth, const Eigen::Vector2d& p,
                          double max_distance);

// Width (m) of the band in front of every wall that the inverse model never marks free: the Θ gap
// free_gap·σ + Δ/2 it leaves before a hit (docs/algorithm.md §4; σ the hit sigma in use, Δ the
// map's resolution), plus Δ/2 because a point counts by the map cell it falls in.
double thetaGapBand(double free_gap, double hit_sigma, double resolution);

// The `cells` (a 0/1 mask) whose centre lies further than `band` from every obstacle.
std::vector<uint8_t> cellsBeyondBand(const OccupancyImage& truth, const std::vector<uint8_t>& cells,
                                     double band);

// Share of the `reachable` cells (reachableFreeCells) whose centre, taken into the map's frame
// (`map_in_truth`: the map frame's pose in the image's frame), falls on a map cell with
// NS < max_ns and BetP(o) < 0.5. 0 when nothing is reachable.
double knownFraction(const OccupancyImage& truth, const std::vector<uint8_t>& reachable,
                     const LayerRaster& map, const Pose2& map_in_truth, double max_ns = 0.5);

}  // namespace exploration
}  // namespace evidential_slam
