#include "evidential_slam/core/localization/mixture_proposal.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace evidential_slam {
namespace {

constexpr double kLog2Pi = 1.8378770664093453;

double logOf(double p) { return p > 0.0 ? std::log(p) : -std::numeric_limits<double>::infinity(); }

double logSumExp(double a, double b) {
  const double m = std::max(a, b);
  if (m == -std::numeric_limits<double>::infinity()) return m;
  return m + std::log(std::exp(a - m) + std::exp(b - m));
}

Eigen::Matrix3d floors(const OdometryDrift& drift) {
  return Eigen::Vector3d(drift.min_sigma_xy * drift.min_sigma_xy,
                         drift.min_sigma_xy * drift.min_sigma_xy,
                         drift.min_sigma_theta * drift.min_sigma_theta)
      .asDiagonal();
}

// `pose` in the frame of `previous`, as (x, y, θ), the heading wrapped.
Eigen::Vector3d relative(const Pose2& previous, const Pose2& pose) {
  const double c = std::cos(previous.theta), s = std::sin(previous.theta);
  const double dx = pose.x - previous.x, dy = pose.y - previous.y;
  return Eigen::Vector3d(c * dx + s * dy, -s * dx + c * dy,
                         normalizeAngle(pose.theta - previous.theta));
}

}  // namespace

MixtureProposal::MixtureProposal(const Pose2& increment, const OdometryDrift& drift, double reach,
                                 const Pose2& matched, const Eigen::Matrix3d& spread)
    : increment_(increment), matched_(matched) {
  const Eigen::Matrix3d cov = driftCovariance(increment, drift);
  drift_info_ = cov.inverse();
  drift_log_norm_ = -0.5 * (3.0 * kLog2Pi + std::log(cov.determinant()));

  double sd_rot1, sd_trans, sd_rot2;
  driftSigmas(increment, drift, &sd_rot1, &sd_trans, &sd_rot2);
  const double trans = std::hypot(increment.x, increment.y);
  // A failed increment: anywhere within its reach around the previous pose.
  fail_var_xy_ = trans * trans + reach * reach + sd_trans * sd_trans;
  fail_var_theta_ = increment.theta * increment.theta + sd_rot1 * sd_rot1 + sd_rot2 * sd_rot2;

  const Eigen::Matrix3d scan_cov = spread + floors(drift);
  scan_root_ = scan_cov.llt().matrixL();
  scan_info_ = scan_cov.inverse();
  scan_log_norm_ = -0.5 * (3.0 * kLog2Pi + std::log(scan_cov.determinant()));
}

Eigen::Matrix3d MixtureProposal::driftCovariance(const Pose2& increment,
                                                 const OdometryDrift& drift) {
  // sampleDrift's rotate-translate-rotate linearized at the increment: position along the first
  // rotation's direction u by the translation's σ, across it (v) by the translation times the
  // first rotation's σ, which also turns the heading.
  double sd_rot1, sd_trans, sd_rot2;
  driftSigmas(increment, drift, &sd_rot1, &sd_trans, &sd_rot2);
  double trans = std::hypot(increment.x, increment.y);
  double rot1 = trans > 1e-3 ? std::atan2(increment.y, increment.x) : 0.0;
  if (std::abs(rot1) > M_PI_2) {  // driving backwards, as sampleDrift splits it
    rot1 = normalizeAngle(rot1 + M_PI);
    trans = -trans;
  }
  const Eigen::Vector2d u(std::cos(rot1), std::sin(rot1)), v(-std::sin(rot1), std::cos(rot1));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.topLeftCorner<2, 2>() = sd_trans * sd_trans * u * u.transpose() +
                              trans * trans * sd_rot1 * sd_rot1 * v * v.transpose() +
                              drift.min_sigma_xy * drift.min_sigma_xy * Eigen::Matrix2d::Identity();
  cov.block<2, 1>(0, 2) = trans * sd_rot1 * sd_rot1 * v;
  cov.block<1, 2>(2, 0) = cov.block<2, 1>(0, 2).transpose();
  cov(2, 2) = sd_rot1 * sd_rot1 + sd_rot2 * sd_rot2;
  return cov;
}

Pose2 MixtureProposal::sampleScan(Rng* rng) const {
  const Eigen::Vector3d d =
      scan_root_ * Eigen::Vector3d(rng->gaussian(), rng->gaussian(), rng->gaussian());
  return Pose2(matched_.x + d.x(), matched_.y + d.y(), normalizeAngle(matched_.theta + d.z()));
}

double MixtureProposal::logDrift(const Pose2& previous, const Pose2& pose) const {
  Eigen::Vector3d d = relative(previous, pose);
  d -= Eigen::Vector3d(increment_.x, increment_.y, 0.0);
  d.z() = normalizeAngle(d.z() - increment_.theta);
  return drift_log_norm_ - 0.5 * d.dot(drift_info_ * d);
}

double MixtureProposal::logFailure(const Pose2& previous, const Pose2& pose) const {
  const double dx = pose.x - previous.x, dy = pose.y - previous.y;
  const double da = normalizeAngle(pose.theta - previous.theta - increment_.theta);
  return -1.5 * kLog2Pi - std::log(fail_var_xy_) - 0.5 * std::log(fail_var_theta_) -
         0.5 * ((dx * dx + dy * dy) / fail_var_xy_ + da * da / fail_var_theta_);
}

double MixtureProposal::logScan(const Pose2& pose) const {
  const Eigen::Vector3d d(pose.x - matched_.x, pose.y - matched_.y,
                          normalizeAngle(pose.theta - matched_.theta));
  return scan_log_norm_ - 0.5 * d.dot(scan_info_ * d);
}

double MixtureProposal::logWeightFactor(const Pose2& previous, const Pose2& pose,
                                        double failure_rate, double fraction) const {
  const double drift = logDrift(previous, pose);
  return logSumExp(logOf(1.0 - failure_rate) + drift,
                   logOf(failure_rate) + logFailure(previous, pose)) -
         logSumExp(logOf(1.0 - fraction) + drift, fraction > 0.0
                                                      ? logOf(fraction) + logScan(pose)
                                                      : -std::numeric_limits<double>::infinity());
}

double MixtureProposal::failureShare(const Pose2& previous, const Pose2& pose,
                                     double failure_rate) const {
  const double failed = logOf(failure_rate) + logFailure(previous, pose);
  const double total = logSumExp(logOf(1.0 - failure_rate) + logDrift(previous, pose), failed);
  return total == -std::numeric_limits<double>::infinity() ? 0.0 : std::exp(failed - total);
}

}  // namespace evidential_slam
