// Trajectory accuracy: absolute trajectory error after the best rigid (SE(2)) alignment.
#pragma once

#include <string>
#include <vector>

#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

struct StampedPose {
  double stamp = 0.0;
  Pose2 pose;
};

struct AteResult {
  size_t matched = 0;      // pose pairs associated by timestamp
  double rmse = 0.0;       // m, after alignment
  double max_error = 0.0;  // m
  Pose2 alignment;         // applied to the estimate to bring it onto the truth
};

// Associates each estimated pose with the ground-truth pose nearest in time (within max_dt
// seconds), aligns the estimate on the truth with the least-squares rotation + translation
// (Eigen::umeyama, no scale) and returns the RMSE of the positions. False (and `why`) when fewer
// than 2 pairs match.
bool computeAte(const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth,
                double max_dt, AteResult* result, std::string* why);

}  // namespace evidential_slam
