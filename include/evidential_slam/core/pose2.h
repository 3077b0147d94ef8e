// Planar pose (x, y, theta) and its algebra. The maths is Eigen's (Isometry2d); this struct is the
// plain value type the rest of the core and the adapters exchange.
#pragma once

#include <Eigen/Geometry>

namespace evidential_slam {

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;  // radians, kept in (-pi, pi]

  Pose2() = default;
  Pose2(double x_in, double y_in, double theta_in);

  static Pose2 fromIsometry(const Eigen::Isometry2d& iso);
  Eigen::Isometry2d toIsometry() const;

  // this ⊕ other: `other` expressed in this pose's frame, returned in the parent frame.
  Pose2 compose(const Pose2& other) const;
  Pose2 inverse() const;
  // The pose of `to` seen from this pose: this⁻¹ ⊕ to.
  Pose2 between(const Pose2& to) const;
  Eigen::Vector2d transformPoint(const Eigen::Vector2d& p) const;
  Eigen::Vector2d translation() const { return {x, y}; }
};

// Wraps an angle to (-pi, pi].
double normalizeAngle(double angle);

}  // namespace evidential_slam
