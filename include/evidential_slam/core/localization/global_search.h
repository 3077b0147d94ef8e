// Where does a scan fit on the whole map? An exhaustive correlative search of (x, y, θ) over the
// map's free space, branch and bound over a pyramid of max-pooled score grids (Olson 2009,
// "Real-time correlative scan matching"; Hess et al. 2016, Cartographer's
// FastCorrelativeScanMatcher). A beam ending in a cell scores s = exp(-d² / 2σ²), d the distance
// from the cell to the nearest plausible end (LikelihoodField: observed, Pl(o) >= 1/2), σ the
// beam's end uncertainty; a pose scores the mean s of its beams. Level k of the pyramid holds the
// max of s over 2^k x 2^k cells, so the score of a square of 2^k x 2^k robot positions at one
// heading, summed on level k, bounds the score of every position inside it: squares that cannot
// beat the best found so far are never opened. Headings are enumerated at the step that moves the
// scan's farthest endpoint by one cell (the finest level's translation step), so the leaves are
// every (free cell, heading) a scan can tell apart on the map. The search keeps the best pose of
// each region (a KLD histogram bin: the poses the particle filter tells apart) for the `count` best
// regions: a particle filter started around them disambiguates over the next scans.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

struct PoseHypothesis {
  Pose2 pose;          // the robot's pose (cell centre, enumerated heading)
  double score = 0.0;  // mean s over the beams, in [0, 1]
};

class GlobalSearch {
 public:
  // Levels of the pyramid: the coarsest squares are 2^(kLevels - 1) cells wide (3.2 m at 5 cm).
  // The depth changes the cost only, not the result (the bounds are exact).
  static constexpr int kLevels = 7;

  // The score grids of `map`'s observed box for an end uncertainty `sigma` (m, > 0), and the robot
  // positions searched: the cells of `free_cells` (map cells). Throws std::invalid_argument for
  // a map without an observed cell or sigma <= 0.
  GlobalSearch(const EvidentialGridMap& map, double sigma,
               const std::vector<CellIndex>& free_cells);

  double sigma() const { return sigma_; }
  // The heading step for a scan whose farthest endpoint lies `max_range` from the robot: the
  // angle that moves it by one cell, acos(1 - res² / (2 max_range²)) (Cartographer's), at most
  // π/4.
  static double headingStep(double resolution, double max_range);

  struct Options {
    size_t count = 500;               // regions kept
    double region_xy = 0.5;           // m (kld_bin_xy)
    double region_angle = M_PI / 18;  // rad (kld_bin_angle)
  };
  struct Stats {
    size_t headings = 0;
    uint64_t evaluations = 0;  // squares and leaves scored
  };
  // The best pose of each of the `count` best regions, best first, for the endpoints `points`
  // (robot frame). Empty without points.
  std::vector<PoseHypothesis> search(const std::vector<Eigen::Vector2d>& points,
                                     const Options& options, Stats* stats = nullptr) const;

  // s of a cell (map cell index) as the search scores it, in [0, 1] (quantized to 1/255).
  double cellScore(int cx, int cy) const;
  // The score of one pose (mean s over `points`, their cells as the search computes them).
  double score(const Pose2& pose, const std::vector<Eigen::Vector2d>& points) const;

 private:
  struct Offset {
    int x, y;
  };
  // Level k's value at padded index (px, py), 0 outside.
  int at(int level, int px, int py) const;
  int sum(int level, int x, int y, const std::vector<Offset>& offsets) const;
  bool freeAt(int level, int x, int y) const;

  CellBox box_;
  double resolution_ = 0.05;
  double sigma_ = 0.05;
  int pad_ = 0;                 // cells of padding left of and below the box in the score levels
  int width_ = 0, height_ = 0;  // padded
  // Score levels: uint8 s * 255 (level 0), then the max over 2^k x 2^k cells from (x, y) up.
  std::vector<std::vector<uint8_t>> levels_;
  // Free levels over the box (unpadded): 1 when a free cell lies in the 2^k square from (x, y) up.
  std::vector<std::vector<uint8_t>> free_;
};

}  // namespace evidential_slam
