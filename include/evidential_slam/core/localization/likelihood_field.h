// amcl's likelihood field laser model (Thrun, Burgard, Fox, Probabilistic Robotics 6.4) on an
// evidential map. A beam may plausibly end in an observed cell that is not confidently empty,
// Pl(o) = 1 - m(e) >= 1/2: occupied, conflicting, or still ignorant (the Θ gap in front of a
// wall). Never-observed cells are not plausible ends: the field sees only a beam's end, and the
// unobserved space behind or inside a wall, which a beam reaches only through the wall, cannot be
// told from unexplored space it reached freely (docs/decisions.md). The field holds, per cell of
// the map's observed box, the distance to the nearest plausible end, capped at max_dist; it is
// computed once per map, since localization never writes the map. A beam ending at distance d
// from one has the likelihood p = z_hit exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max (amcl's
// unnormalised Gaussian). A scan weighs a pose as amcl's likelihood_field does, 1 + Σ p^3, not by
// the product of the p: a beam the map cannot explain (unmapped space, an object not in the map)
// then costs the pose at most that beam's share instead of ln(z_rand / range_max) each.
#pragma once

#include <vector>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/mass.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

// What a scan scores at one pose.
struct FieldScore {
  double log_likelihood = 0.0;  // Σ ln p over the beams (the plausibility the filter reports)
  double amcl_weight = 1.0;     // 1 + Σ p^3 (amcl's weight of the pose)
};

class LikelihoodField {
 public:
  // Observed and Pl(o) = 1 - m(e) >= 1/2.
  static bool plausibleEnd(const Cell& cell);

  // The field of `map`'s observed box. Throws std::invalid_argument unless max_dist > 0.
  LikelihoodField(const EvidentialGridMap& map, double max_dist);

  double maxDistance() const { return max_dist_; }
  const CellBox& box() const { return box_; }
  // Distance (m) between the centres of the cell at (x, y) and of the nearest cell where a beam
  // may plausibly end, capped at maxDistance(); maxDistance() off the observed box (as amcl
  // counts off-map endpoints: the map holds no evidence there for a beam to end on).
  double distance(double x, double y) const;

  // Σ over the beams of `beams` (hits only, e.g. ParticleFilter::hitBeamSubset) of
  // ln(z_hit exp(-d^2 / (2 sigma_hit^2)) + z_rand / beams.max_range), their endpoints seen from
  // `sensor` (the laser's pose in the map). A beam of likelihood 0 (z_rand = 0, far off) counts
  // as the smallest positive double.
  double logLikelihood(const Pose2& sensor, const LaserScan& beams, double sigma_hit,
                       double z_hit, double z_rand) const;
  // Both sums over the beams of `beams`, p as for logLikelihood, in one pass.
  FieldScore score(const Pose2& sensor, const LaserScan& beams, double sigma_hit, double z_hit,
                   double z_rand) const;

 private:
  CellBox box_;
  double resolution_ = 0.05;
  double max_dist_ = 0.0;
  std::vector<float> distance_;  // m, row-major over box_
};

}  // namespace evidential_slam
