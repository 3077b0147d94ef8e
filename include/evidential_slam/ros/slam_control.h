// Where the SLAM node starts and starts again, each change run by the worker between two scans:
// at start-up on map_file's map or at initial_pose_* (amcl's names), on a map loaded later, at an
// /initialpose (rviz's "2D Pose Estimate"), or spread over the map (global localization). In
// localization mode the session's Localizer runs on the map instead of the SLAM.
#pragma once

#include <atomic>
#include <string>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "evidential_slam/ros/guarded_params.h"
#include "evidential_slam/ros/map_publisher.h"
#include "evidential_slam/ros/slam_outputs.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class SlamControl {
 public:
  SlamControl(std::string name, ros::NodeHandle& private_nh, GuardedParams& params,
              SlamWorker& worker, SlamOutputs& outputs, tf2_ros::Buffer& tf_buffer);

  bool localizationMode() const { return localization_mode_; }
  // The map topics to refresh after a start (none before it exists).
  void setMapPublisher(MapPublisher* map_publisher) { map_publisher_ = map_publisher; }

  // At start-up: on map_file's map (at its saved pose or initial_pose_*), or with no map at
  // initial_pose_* when given. False and `why` when the map cannot be used.
  bool startFromParameters(std::string* why);
  // Restarts the SLAM on `map` at `pose` (map frame). With the odometry pose at that moment
  // (`odometry`, from tf) the scans to come are placed by the odometry since; map -> odom is
  // then known at once. False and `why` when the session refuses.
  bool startOnMap(const EvidentialGridMap& map, const Pose2& pose, const Pose2* odometry,
                  std::string* why);
  // Localization mode: localizes on `map` from `start`. False and `why` when refused.
  bool localizeOn(const EvidentialGridMap& map, const LocalizationStart& start, std::string* why);
  // Localization mode: the particles start again as `start` says on the same map.
  bool restartLocalization(const LocalizationStart& start, std::string* why);
  // Localization mode: `pose` with the initial_cov_* variances.
  LocalizationStart startAt(const Pose2& pose) const;
  // The latest odom -> base pose from tf, if there is one.
  bool currentOdometry(Pose2* odometry) const;
  // /initialpose: in its frame or brought into the map frame through tf; amcl's use of the
  // covariance in localization mode, a restart on the current map when mapping.
  void onInitialPose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg);

 private:
  const std::string name_;
  ros::NodeHandle private_nh_;
  GuardedParams& params_;
  SlamWorker& worker_;
  SlamOutputs& outputs_;
  tf2_ros::Buffer& tf_buffer_;
  const bool localization_mode_;
  std::atomic<MapPublisher*> map_publisher_{nullptr};
};

}  // namespace ros_adapter
}  // namespace evidential_slam
