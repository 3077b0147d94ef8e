// Pure-pursuit path following for a differential-drive robot: steer on the arc through the point
// `lookahead` metres further along the path than the robot's projection on it; turn in place
// while that point lies too far off the heading; slow down near the goal.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/parameter_fields/explorer_pursuit.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace exploration {

// Within slowdown_distance of the goal the speed falls linearly, to a quarter of the maximum at
// goal_tolerance.
struct PursuitConfig {
  PursuitConfig();  // the table's defaults
  ES_EXPLORER_PURSUIT_FIELDS

  bool isValid(std::string* why) const;
};

struct VelocityCommand {
  double linear = 0.0;   // m/s
  double angular = 0.0;  // rad/s, counter-clockwise
  bool goal_reached = false;
};

// The command that follows `path` (map frame, from near the robot to the goal) from `pose`.
// An empty path or a reached goal gives (0, 0).
VelocityCommand purePursuit(const Pose2& pose, const std::vector<Eigen::Vector2d>& path,
                            const PursuitConfig& config);

// The point `distance` m along the path after the projection of `position` on it (the goal
// when the path ends before).
Eigen::Vector2d lookaheadPoint(const std::vector<Eigen::Vector2d>& path,
                               const Eigen::Vector2d& position, double distance);

}  // namespace exploration
}  // namespace evidential_slam
