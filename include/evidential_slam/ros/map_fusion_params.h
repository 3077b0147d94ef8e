// The map_fusion nodelet's parameters (the table's map fusion rows, and the session's map
// thresholds) and map_merge's per-robot initial poses.
#pragma once

#include <string>

#include <ros/ros.h>

#include "evidential_slam/core/parameter_fields/map_fusion.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace ros_adapter {

struct MapFusionParams {
  SessionConfig session;  // occupied_thresh and free_thresh of the trinary `map`
  MapFusionParams();      // the table's defaults
  ES_MAP_FUSION_FIELDS

  bool isValid(std::string* why) const;
};

// Reads the node's parameters from its private handle; missing ones keep their defaults. False
// with a one-line `why` for a value of the wrong type or out of range.
bool readMapFusionParams(const ros::NodeHandle& private_nh, MapFusionParams* params,
                         std::string* why);

// <robot>/map_merge/init_pose_x, _y, _z, _yaw (map_merge's names) as the robot's map frame in
// world_frame (z is read and not used: the maps are planar). False when one is missing or not a
// number.
bool readInitPose(const std::string& robot, Pose2* pose);

}  // namespace ros_adapter
}  // namespace evidential_slam
