// Refines a particle's sampled pose against that particle's own map, so the proposal follows the
// laser, not only the odometry (what makes few particles enough, as in GMapping). Two stages:
// ICP on the nearest occupied cells (captures errors up to search_radius), then a short hill climb
// on a smooth endpoint score for sub-cell precision.
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

// A beam endpoint and a point just in front of it (past the inverse model's Θ gap), robot frame. A
// match needs an occupied cell at the first and a free cell at the second: that finds the wall's
// visible face, not the thick band of occupied evidence that accumulates behind it.
struct MatchPoint {
  Eigen::Vector2d hit;
  Eigen::Vector2d free;
};

class ScanMatcher {
 public:
  ScanMatcher(const ScanMatcherConfig& config, const SensorModelConfig& sensor, double resolution);
  // The configuration in use (after forSensorNoise, when the filter built it for a noisy laser).
  const ScanMatcherConfig& config() const { return config_; }

  // Beam endpoints in the robot frame used for matching: every matchStride()-th usable hit,
  // starting from the first.
  std::vector<MatchPoint> endpoints(const LaserScan& scan) const;
  // Every how many beams of `scan` an endpoint is matched: the beam_spacing in the scan's mean
  // angular step, rounded, at least 1 (2 for a 1° laser, 4 for a 0.5° one).
  int matchStride(const LaserScan& scan) const;
  // Σ over endpoints of the best m̃(o)(hit)·m̃(e)(free)·exp(-d²/2σ²) over 3x3 cell offsets.
  double score(const EvidentialGridMap& map, const Pose2& robot_pose,
               const std::vector<MatchPoint>& endpoints) const;
  // Refined pose, or `initial` when too few endpoints find an occupied cell nearby.
  Pose2 refine(const EvidentialGridMap& map, const Pose2& initial,
               const std::vector<MatchPoint>& endpoints) const;
  // ICP's correspondence for an endpoint in cell `hit` whose probe in front of it is in cell
  // `free`: the nearest offset o within search_radius (ties: smaller dy, then smaller dx) with
  // m̃(o)(hit + o) and m̃(e)(free + o) both ≥ occupied_threshold; false when there is none.
  bool correspondence(const EvidentialGridMap& map, const CellIndex& hit, const CellIndex& free,
                      CellIndex* offset) const;
  // How well the scan fixes the robot's position at `pose`: the smaller over the larger eigenvalue
  // of the translation block of point-to-line ICP's normal equations there (whether this matcher
  // matches point to line or not): Σ w n nᵀ over the endpoints whose target cells line up (n their
  // line's normal), plus w I for the rest (a corner, a blob: point to point). Near 0 along a
  // corridor whose walls are lines, near 1 where walls face every way; 0 when too few endpoints
  // match. Walls mapped as bands 3 cells thick do not line up within the normal's reach, so a
  // corridor of them reads as fixed both ways (to within a cell, as point-to-point ICP fixes it).

  double translationConstraint(const EvidentialGridMap& map, const Pose2& pose,
                               const std::vector<MatchPoint>& endpoints) const;
  // ICP from `start` to convergence and score() there; score -1 (and pose `start`) when the first
  // step finds too few matches.
  struct Match {
    Pose2 pose;
    double score = -1.0;
  };
  Match matchFrom(const EvidentialGridMap& map, const Pose2& start,
                  const std::vector<MatchPoint>& endpoints) const;
  // Multi-start ICP: from `predicted` turned by 0, ±heading_step, ... up to ±`heading_window`;
  // the converged pose with the best score() (in `best_score`; -1 when no start matches and
  // `predicted` is returned). `unturned`, if given, is matchFrom(map, predicted, endpoints),
  // already computed: the unturned start is not run again.
  Pose2 search(const EvidentialGridMap& map, const Pose2& predicted,
               const std::vector<MatchPoint>& endpoints, double heading_window, double* best_score,
               const Match* unturned = nullptr) const;

 private:
  // What ICP's correspondence search found for one endpoint at the last iteration: it depends on
  // the endpoint's two cells only, so an iteration that leaves them where they were (most do, once
  // the steps are below a cell) reuses it.
  struct Correspondence {
    CellIndex hit{std::numeric_limits<int>::min(), 0};  // none yet
    CellIndex free;
    bool found = false;
    CellIndex offset;
    bool has_normal = false;  // point to line, or the information asked for
    Eigen::Vector2d normal = Eigen::Vector2d::Zero();
  };
  // One ICP iteration; false when too few endpoints matched. `correspondences`: one per endpoint,
  // kept between the iterations of one ICP run. `translation_information`, if given, receives the
  // translation block of the step's normal equations (see translationConstraint).
  bool icpStep(const EvidentialGridMap& map, const std::vector<MatchPoint>& endpoints,
               std::vector<Correspondence>* correspondences, Pose2* pose,
               Eigen::Matrix2d* translation_information = nullptr) const;
  // ICP to convergence from `start`; false when the first step finds too few matches.
  bool icp(const EvidentialGridMap& map, const std::vector<MatchPoint>& endpoints,
           Pose2* pose) const;
  Pose2 hillClimb(const EvidentialGridMap& map, const Pose2& start,
                  const std::vector<MatchPoint>& endpoints) const;

  ScanMatcherConfig config_;
  SensorModelConfig sensor_;
  double resolution_;
  int search_cells_;                 // search_radius in cells (rounded up)
  std::vector<int> row_half_width_;  // [|dy|]: largest dx with dx² + dy² ≤ search_cells_²
  double kernel_scale_;              // kernel_ table entries per squared cell distance
  std::vector<float> kernel_;        // exp(-d²/2σ²) over squared distance in cells²
};

}  // namespace evidential_slam
