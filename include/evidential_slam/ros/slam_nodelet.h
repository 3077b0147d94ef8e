// The SLAM nodelet, wiring only: reads the parameters (params.h) and hands the parts their
// handles. LaserScan + odometry from tf in (ScanInput); map -> odom, ~pose, ~particles, ~path and
// the conflict alarm out (SlamOutputs); the map topics (MapPublisher); starts on a map and at
// /initialpose (SlamControl); the services (SlamServices); the heartbeat (SlamHeartbeat);
// dynamic_reconfigure. The filter runs on SlamWorker's thread. With mode localization the same
// node localizes on map_file's map (the session's Localizer).
#pragma once

#include <atomic>
#include <memory>

#include <dynamic_reconfigure/server.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "evidential_slam/EvidentialSlamConfig.h"
#include "evidential_slam/ros/guarded_params.h"
#include "evidential_slam/ros/map_publisher.h"
#include "evidential_slam/ros/scan_input.h"
#include "evidential_slam/ros/slam_control.h"
#include "evidential_slam/ros/slam_heartbeat.h"
#include "evidential_slam/ros/slam_outputs.h"
#include "evidential_slam/ros/slam_services.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class SlamNodelet : public nodelet::Nodelet {
 public:
  SlamNodelet();
  ~SlamNodelet() override;

 private:
  void onInit() override;
  // One line each: gmapping names read, shadowed by ours, without a counterpart, refused.
  void logGmappingReport(const GmappingReport& report);
  // Asks the map publisher for the latest map (map_update_interval, on ROS or wall time).
  void requestMapUpdate();
  void startMapTimers();
  void onReconfigure(EvidentialSlamConfig& config, uint32_t level);

  ros::NodeHandle nh_, private_nh_;
  GuardedParams params_;

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<SlamOutputs> outputs_;
  std::unique_ptr<SlamWorker> worker_;
  std::unique_ptr<SlamControl> control_;
  std::unique_ptr<MapPublisher> map_publisher_;
  std::unique_ptr<ScanInput> scans_;
  std::unique_ptr<SlamServices> services_;
  std::unique_ptr<SlamHeartbeat> heartbeat_;

  ros::Timer map_timer_;
  ros::WallTimer map_wall_timer_;                  // the map also when ROS time stands still
  std::atomic<ros::WallTime> last_map_request_{};  // by either timer
  std::unique_ptr<dynamic_reconfigure::Server<EvidentialSlamConfig>> reconfigure_server_;
  boost::recursive_mutex reconfigure_mutex_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
