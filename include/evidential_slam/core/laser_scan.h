// A planar range scan in core terms: one range and bearing per ray, a validity flag per ray and the
// sensor's pose on the robot. Adapters (MRPT rawlogs, ROS LaserScan) fill it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

struct LaserScan {
  double stamp = 0.0;           // seconds
  Pose2 sensor_pose;            // laser frame in the robot (base) frame
  float max_range = 0.0f;       // sensor's nominal maximum range (m)
  float range_sigma = 0.0f;     // sensor's declared 1-σ range noise (m); 0: unknown
  std::vector<float> ranges;    // m; NaN/inf/negative are bad data and skipped
  std::vector<float> bearings;  // rad, in the laser frame, one per range
  std::vector<uint8_t> valid;   // 0: no return (the ray saw nothing up to max_range)

  size_t size() const { return ranges.size(); }
  // True when sizes agree; `why` says what is wrong otherwise.
  bool isConsistent(std::string* why) const;
};

}  // namespace evidential_slam
