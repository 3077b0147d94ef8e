// The mixture proposal's densities (core/localization/mixture_proposal.h) by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "evidential_slam/core/localization/mixture_proposal.h"

namespace evidential_slam {
namespace {

OdometryDrift drift() {
  OdometryDrift d;
  d.rot_rot = d.rot_trans = d.trans_trans = 0.006;
  d.trans_rot = 0.001;
  d.min_sigma_xy = 0.005;
  d.min_sigma_theta = 0.002;
  return d;
}

// 0.2 m straight ahead: σ²(rot1) = σ²(rot2) = 0.5 · 0.006 · 0.2 + 0.002² = 0.000604, σ²(trans) =
// 0.006 · 0.2 + 0.005² = 0.001225; along x σ²(trans) + 0.005² = 0.00125, across 0.2² · 0.000604 +
// 0.005² = 0.00004916, across-heading 0.2 · 0.000604 = 0.0001208, heading 2 · 0.000604 = 0.001208.
TEST(MixtureProposal, DriftCovarianceByHand) {
  const Eigen::Matrix3d c = MixtureProposal::driftCovariance(Pose2(0.2, 0.0, 0.0), drift());
  EXPECT_NEAR(c(0, 0), 0.00125, 1e-9);
  EXPECT_NEAR(c(1, 1), 0.00004916, 1e-9);
  EXPECT_NEAR(c(1, 2), 0.0001208, 1e-9);
  EXPECT_NEAR(c(2, 1), 0.0001208, 1e-9);
  EXPECT_NEAR(c(2, 2), 0.001208, 1e-9);
  EXPECT_NEAR(c(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(c(0, 2), 0.0, 1e-12);
}

// At the odometry's prediction the drift's density is the Gaussian's peak; without failures and
// scan-drawn samples the weight factor is 1; a pose the reversed increment reached (0.2 m back)
// is the failure's, not the drift's.
TEST(MixtureProposal, WeightsAndFailureShare) {
  const Pose2 increment(0.2, 0.0, 0.0), previous(1.0, 2.0, M_PI / 2);
  const Pose2 ahead = previous.compose(increment), back = previous.compose(Pose2(-0.2, 0, 0));
  const MixtureProposal p(increment, drift(), 0.2, back, Eigen::Matrix3d::Identity() * 1e-4);
  const Eigen::Matrix3d c = MixtureProposal::driftCovariance(increment, drift());
  EXPECT_NEAR(p.logDrift(previous, ahead),
              -0.5 * (3.0 * std::log(2.0 * M_PI) + std::log(c.determinant())), 1e-9);
  EXPECT_NEAR(p.logWeightFactor(previous, ahead, 0.0, 0.0), 0.0, 1e-12);
  // Failure rate ε, no scan draws: log((1 − ε) + ε p_fail / p_drift).
  const double ratio = std::exp(p.logFailure(previous, ahead) - p.logDrift(previous, ahead));
  EXPECT_NEAR(p.logWeightFactor(previous, ahead, 0.01, 0.0), std::log(0.99 + 0.01 * ratio), 1e-9);
  EXPECT_LT(p.failureShare(previous, ahead, 0.01), 0.01);
  EXPECT_GT(p.failureShare(previous, back, 0.01), 0.999);
  // The failed increment: position σ² = 0.2² + 0.2² + σ²(trans) around the previous pose.
  const double var_xy = 0.08 + 0.001225, var_a = 2 * 0.000604;
  EXPECT_NEAR(
      p.logFailure(previous, back),
      -1.5 * std::log(2 * M_PI) - std::log(var_xy) - 0.5 * std::log(var_a) - 0.5 * (0.04 / var_xy),
      1e-9);
  // A sample drawn from the scan where the odometry did not go: ε p_fail / (φ p_scan).
  EXPECT_NEAR(p.logWeightFactor(previous, back, 0.01, 0.1),
              std::log(0.01) + p.logFailure(previous, back) - std::log(0.1) - p.logScan(back),
              1e-6);
}

}  // namespace
}  // namespace evidential_slam
