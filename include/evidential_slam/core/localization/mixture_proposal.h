// Mixture MCL's proposal (Thrun, Fox, Burgard, Dellaert 2001, "Robust Monte Carlo localization
// for mobile robots") for odometry that can fail. The motion model it targets is a mixture: the
// drift (sampleDrift) with probability 1 − ε, else a failed increment, after which the robot may be
// anywhere within reach of its previous pose (position σ² = the increment's length² + reach² + the
// drift's, heading around the reported turn). The proposal draws a particle's new pose from the
// drift or, with probability φ, from the scan: a Gaussian around the scan-matched pose. A sample's
// weight is multiplied by target over proposal (logWeightFactor), so the scan-drawn samples where
// the odometry did not go keep the weight the failure gives them. The drift's density is taken as
// Gaussian (rotate-translate-rotate linearized at the increment).
#pragma once

#include <Eigen/Core>

#include "evidential_slam/core/motion_model.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

class MixtureProposal {
 public:
  // `increment`: the odometry's since the last update; `matched`: the scan-matched pose;
  // `spread`: the covariance (x, y, θ) of the scan-drawn samples (the floors of `drift` added).
  // `reach`: the failed increment's position σ beyond the increment's own length.
  MixtureProposal(const Pose2& increment, const OdometryDrift& drift, double reach,
                  const Pose2& matched, const Eigen::Matrix3d& spread);

  // A sample from the scan: N(matched, spread).
  Pose2 sampleScan(Rng* rng) const;
  // log(target / proposal) for a particle moved from `previous` to `pose`, whose odometry fails
  // at the rate ε and which was drawn from the scan with probability φ (`fraction`): log of
  // ((1 − ε) p_drift + ε p_fail) / ((1 − φ) p_drift + φ p_scan).
  double logWeightFactor(const Pose2& previous, const Pose2& pose, double failure_rate,
                         double fraction) const;
  // The failure's share of the target density at `pose`: ε p_fail / ((1 − ε) p_drift + ε p_fail).
  double failureShare(const Pose2& previous, const Pose2& pose, double failure_rate) const;
  // The log densities of the three components at `pose` (from `previous`).
  double logDrift(const Pose2& previous, const Pose2& pose) const;
  double logFailure(const Pose2& previous, const Pose2& pose) const;
  double logScan(const Pose2& pose) const;

  // The drift's covariance (x, y, θ) for `increment`, in the frame of the pose it starts from
  // (sampleDrift linearized; the floor min_sigma_xy added across the track too).
  static Eigen::Matrix3d driftCovariance(const Pose2& increment, const OdometryDrift& drift);

 private:
  Pose2 increment_;
  Eigen::Matrix3d drift_info_;  // inverse covariance of the drift, in the previous pose's frame
  double drift_log_norm_;
  double fail_var_xy_, fail_var_theta_;
  Pose2 matched_;
  Eigen::Matrix3d scan_root_, scan_info_;
  double scan_log_norm_;
};

}  // namespace evidential_slam
