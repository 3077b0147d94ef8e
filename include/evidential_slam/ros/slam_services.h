// The SLAM node's services, on the multi-threaded callback queue (a save waits for the filter
// while scans keep flowing): ~save_map, dynamic_map (gmapping's), ~load_map, ~pause_mapping,
// ~reset and, in localization mode, ~global_localization (amcl's); and /initialpose.
#pragma once

#include <string>

#include <nav_msgs/GetMap.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>

#include "evidential_slam/LoadMap.h"
#include "evidential_slam/SaveMap.h"
#include "evidential_slam/ros/guarded_params.h"
#include "evidential_slam/ros/scan_input.h"
#include "evidential_slam/ros/slam_control.h"
#include "evidential_slam/ros/slam_outputs.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class SlamServices {
 public:
  // `mt_nh`, `mt_private_nh`: the nodelet's multi-threaded handles; `nh` for /initialpose.
  SlamServices(std::string name, ros::NodeHandle& nh, ros::NodeHandle& mt_nh,
               ros::NodeHandle& mt_private_nh, GuardedParams& params, SlamWorker& worker,
               SlamControl& control, SlamOutputs& outputs, ScanInput& scans);

 private:
  bool saveMap(SaveMap::Request& request, SaveMap::Response& response);
  bool getMap(nav_msgs::GetMap::Request& request, nav_msgs::GetMap::Response& response);
  bool loadMap(LoadMap::Request& request, LoadMap::Response& response);
  bool pauseMapping(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  bool resetSlam(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool globalLocalization(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);

  const std::string name_;
  const std::string scan_topic_;  // resolved, for the saved map's metadata
  GuardedParams& params_;
  SlamWorker& worker_;
  SlamControl& control_;
  SlamOutputs& outputs_;
  ScanInput& scans_;
  ros::ServiceServer save_map_srv_, get_map_srv_, load_map_srv_, pause_srv_, reset_srv_,
      global_localization_srv_;
  ros::Subscriber initial_pose_sub_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
