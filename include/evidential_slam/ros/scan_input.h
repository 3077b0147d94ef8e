// The SLAM node's laser input: a tf2 MessageFilter holds each LaserScan until its transform to the
// odometry frame arrives; the scan then goes to the worker with its odometry pose. It also says
// what the filter would do silently: scans waiting for a missing transform (a watchdog), scans
// lost in the filter, and ROS time or scan stamps jumping back (a looping bag: the SLAM starts
// over, the tf buffer is cleared).
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include "evidential_slam/core/stamp_order.h"
#include "evidential_slam/ros/guarded_params.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class ScanInput {
 public:
  struct Counters {
    uint64_t received = 0;    // every LaserScan that arrived
    uint64_t malformed = 0;   // refused by scanFromRos
    uint64_t without_tf = 0;  // dropped or lost for want of a transform
  };

  // `name`: the nodelet's, for the log.
  ScanInput(std::string name, GuardedParams& params, tf2_ros::Buffer& tf_buffer,
            SlamWorker& worker);
  ~ScanInput();  // unsubscribes first

  // Subscribes to `scan` on `nh` (its callback queue also serves the tf listener: see the nodelet).
  void start(ros::NodeHandle& nh);
  Counters counters() const;
  // Empties the tf buffer (a reset, a loaded map) and forgets the scans' stamps.
  void clearTransforms();

 private:
  void onRawScan(const sensor_msgs::LaserScan::ConstPtr& msg);
  void onScan(const sensor_msgs::LaserScan::ConstPtr& msg);
  void onScanWithoutTransform(const sensor_msgs::LaserScan::ConstPtr& msg,
                              tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void checkWaitingScans(const ros::WallTimerEvent&);

  const std::string name_;
  GuardedParams& params_;
  tf2_ros::Buffer& tf_buffer_;
  SlamWorker& worker_;
  std::unique_ptr<message_filters::Subscriber<sensor_msgs::LaserScan>> scan_sub_;
  std::unique_ptr<tf2_ros::MessageFilter<sensor_msgs::LaserScan>> scan_filter_;
  ros::WallTimer watchdog_;

  std::atomic<uint64_t> received_{0}, malformed_{0}, without_tf_{0};
  std::mutex mutex_;  // everything below
  sensor_msgs::LaserScan::ConstPtr last_raw_scan_;
  ros::WallTime last_raw_arrival_, last_passed_arrival_;
  // Scans inside the filter, by arrival: one still there when newer ones have gone through is
  // reported as lost (the filter itself would only drop it silently, much later).
  std::map<sensor_msgs::LaserScan::ConstPtr, ros::WallTime> in_filter_;
  // ROS time of the last scan's arrival: when it goes back the SLAM starts over at once.
  ros::Time last_arrival_ros_time_;
  StampOrder scan_stamps_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
