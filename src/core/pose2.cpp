#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

double normalizeAngle(double angle) {
  // Eigen's smallestAngle() maps to [-pi, pi]; keep pi for -pi so the range is (-pi, pi].
  const double a = Eigen::Rotation2Dd(angle).smallestAngle();
  return a <= -M_PI ? M_PI : a;
}

Pose2::Pose2(double x_in, double y_in, double theta_in)
    : x(x_in), y(y_in), theta(normalizeAngle(theta_in)) {}

Pose2 Pose2::fromIsometry(const Eigen::Isometry2d& iso) {
  const Eigen::Rotation2Dd rot(iso.linear());
  return Pose2(iso.translation().x(), iso.translation().y(), rot.angle());
}

Eigen::Isometry2d Pose2::toIsometry() const {
  Eigen::Isometry2d iso = Eigen::Isometry2d::Identity();
  iso.linear() = Eigen::Rotation2Dd(theta).toRotationMatrix();
  iso.translation() = Eigen::Vector2d(x, y);
  return iso;
}

Pose2 Pose2::compose(const Pose2& other) const {
  return fromIsometry(toIsometry() * other.toIsometry());
}

Pose2 Pose2::inverse() const { return fromIsometry(toIsometry().inverse(Eigen::Isometry)); }

Pose2 Pose2::between(const Pose2& to) const {
  return fromIsometry(toIsometry().inverse(Eigen::Isometry) * to.toIsometry());
}

Eigen::Vector2d Pose2::transformPoint(const Eigen::Vector2d& p) const { return toIsometry() * p; }

}  // namespace evidential_slam
