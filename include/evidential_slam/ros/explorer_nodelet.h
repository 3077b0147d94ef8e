// The explorer nodelet: a thin shell around exploration::Explorer. In: the SLAM's `grid`
// (EvidentialGrid) and the robot's pose from tf (map_frame -> base_frame). Out: `cmd_vel`
// (Twist) at control_frequency, and at each replanning `~goal` (PoseStamped), `~path` (Path),
// `~frontiers` (MarkerArray) and `~exploration_map` (trinary OccupancyGrid: -1 / 0 / 100). When
// no frontier is left (or max_time has passed) it stops the robot, says why in the log and on the
// latched `~done` (String), then calls the SLAM's `save_map` service with save_map_directory and
// reports the answer on the latched `~map_saved` (String). Parameters: explorer_params.h.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/exploration/explorer.h"
#include "evidential_slam/ros/explorer_params.h"

namespace evidential_slam {
namespace ros_adapter {

class ExplorerNodelet : public nodelet::Nodelet {
 public:
  ExplorerNodelet();
  ~ExplorerNodelet() override;

 private:
  void onInit() override;
  void onGrid(const EvidentialGrid::ConstPtr& msg);
  void onTimer(const ros::TimerEvent& event);
  void publishPlan(const ros::Time& stamp);
  void stopRobot();
  void finish(const std::string& reason);
  void saveMap();

  ExplorerNodeParams params_;
  std::unique_ptr<exploration::Explorer> explorer_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Subscriber grid_sub_;
  ros::Publisher cmd_pub_, goal_pub_, path_pub_, frontiers_pub_, exploration_map_pub_, done_pub_,
      saved_pub_;
  ros::Timer timer_;

  std::mutex map_mutex_;
  std::shared_ptr<const LayerRaster> new_map_;  // arrived since the last control step
  std::shared_ptr<const LayerRaster> map_;      // the last one given to the explorer
  double start_time_ = -1.0;                    // of the first control step with a map
  uint64_t replans_seen_ = 0;
  size_t blacklist_seen_ = 0;  // blacklist entries already reported
  bool finished_ = false;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
