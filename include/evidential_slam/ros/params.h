// Every ROS parameter of the SLAM nodelet, read in one place. The names are those of
// cfg/EvidentialSlam.cfg (dynamic_reconfigure) for the parameters that may change at run time;
// the rest (particles, resolution, frames, ...) are read once at start-up.
#pragma once

#include <string>

#include <ros/node_handle.h>

#include "evidential_slam/EvidentialSlamConfig.h"
#include "evidential_slam/core/config.h"
#include "evidential_slam/core/conflict_alarm.h"

namespace evidential_slam {
namespace ros_adapter {

struct NodeParams {
  SlamConfig slam;                     // core defaults (config.h)
  ConflictAlarmConfig conflict_alarm;  // core defaults (conflict_alarm.h)
  // The laser's declared 1-σ range noise (m), given to every scan; 0 = unknown. LaserScan carries
  // no noise figure, so it is a parameter (MRPT rawlogs declare it: rawlog_player prints it).
  double laser_range_sigma = 0.0;

  // Frames (REP-105).
  std::string map_frame = "map";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";

  double map_update_interval = 5.0;  // s between map publications (ROS time)
  // EC is unbounded (bits); ~layers/external_conflict draws this value and above as 100.
  double external_conflict_display_max = 2.0;
  double transform_publish_period = 0.05;  // s between map->odom broadcasts; 0 disables tf
  double transform_tolerance = 0.1;        // s the map->odom stamp is post-dated (as gmapping)
  // A scan older than the previous one by more than this (s) means time jumped backwards (a
  // looping bag, a restarted simulator): the SLAM starts over. Smaller steps back are dropped.
  double time_jump_tolerance = 1.0;
  int scan_queue_size = 1000;  // scans waiting for tf or for the filter, at most (then dropped)

  bool isValid(std::string* why) const;
};

// Reads every parameter from the private node handle; missing ones keep their defaults.
NodeParams readParams(const ros::NodeHandle& private_nh);

// dynamic_reconfigure <-> parameters: the run-time part of `params` to and from the cfg struct.
EvidentialSlamConfig toReconfigure(const NodeParams& params);
void applyReconfigure(const EvidentialSlamConfig& config, NodeParams* params);

}  // namespace ros_adapter
}  // namespace evidential_slam
