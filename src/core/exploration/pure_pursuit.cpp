#include "evidential_slam/core/exploration/pure_pursuit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {
namespace exploration {

PursuitConfig::PursuitConfig() { ES_EXPLORER_PURSUIT_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool PursuitConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_EXPLORER_PURSUIT_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

Eigen::Vector2d lookaheadPoint(const std::vector<Eigen::Vector2d>& path,
                               const Eigen::Vector2d& position, double distance) {
  if (path.size() == 1) return path.front();
  // Projection on the nearest segment.
  size_t segment = 0;
  double along = 0.0, nearest = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    const Eigen::Vector2d d = path[k + 1] - path[k];
    const double length2 = d.squaredNorm();
    const double t =
        length2 > 0.0 ? std::clamp((position - path[k]).dot(d) / length2, 0.0, 1.0) : 0.0;
    const double gap = (path[k] + t * d - position).norm();
    if (gap < nearest) {
      nearest = gap;
      segment = k;
      along = t * std::sqrt(length2);
    }
  }
  // Walk `distance` further along the path.
  double left = distance + along;
  for (size_t k = segment; k + 1 < path.size(); ++k) {
    const Eigen::Vector2d d = path[k + 1] - path[k];
    const double length = d.norm();
    if (left <= length) return path[k] + (length > 0.0 ? left / length : 0.0) * d;
    left -= length;
  }
  return path.back();
}

VelocityCommand purePursuit(const Pose2& pose, const std::vector<Eigen::Vector2d>& path,
                            const PursuitConfig& c) {
  VelocityCommand cmd;
  if (path.empty()) return cmd;
  const Eigen::Vector2d position = pose.translation();
  const double to_goal = (path.back() - position).norm();
  if (to_goal <= c.goal_tolerance) {
    cmd.goal_reached = true;
    return cmd;
  }
  const Eigen::Vector2d target = lookaheadPoint(path, position, c.lookahead);
  const Eigen::Vector2d local = pose.inverse().transformPoint(target);
  const double heading_error = std::atan2(local.y(), local.x());
  if (std::abs(heading_error) > c.rotate_in_place_angle) {
    cmd.angular =
        std::clamp(c.rotate_gain * heading_error, -c.max_angular_speed, c.max_angular_speed);
    return cmd;
  }
  double speed = c.max_linear_speed;
  if (to_goal < c.slowdown_distance) {
    const double span = std::max(c.slowdown_distance - c.goal_tolerance, 1e-9);
    const double share = std::clamp((to_goal - c.goal_tolerance) / span, 0.0, 1.0);
    speed *= 0.25 + 0.75 * share;
  }
  // The arc through the target: curvature 2 sin(α) / distance.
  const double distance = local.norm();
  const double curvature = distance > 1e-9 ? 2.0 * local.y() / (distance * distance) : 0.0;
  double turn = curvature * speed;
  if (std::abs(turn) > c.max_angular_speed) {
    speed *= c.max_angular_speed / std::abs(turn);
    turn = std::copysign(c.max_angular_speed, turn);
  }
  cmd.linear = speed;
  cmd.angular = turn;
  return cmd;
}

}  // namespace exploration
}  // namespace evidential_slam
