// The robot of the rostests that feed the nodelet themselves (slam_robustness_test,
// slam_config_test).
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "evidential_slam/ros/conversions.h"
#include "ros_test_support.h"
#include "test_support.h"

namespace evidential_slam {
namespace testing_ros {

// The robot of the rostests that feed the nodelet themselves: it drives /clock, the odometry tf
// and scans of a 4 m x 4 m room (testing_room::roomScan), and records the warnings on /rosout and
// the stamps of ~pose. Callbacks need a spinner.
struct Robot {
  explicit Robot(ros::NodeHandle& nh) {
    clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    scan = nh.advertise<sensor_msgs::LaserScan>("/scan", 10);
    mount.header.frame_id = "base_link";
    mount.child_frame_id = "laser";
    mount.transform.rotation.w = 1.0;
    static_tf.sendTransform(mount);
    rosout = nh.subscribe<rosgraph_msgs::Log>("/rosout", 100, [this](const auto& m) {
      if (m->level < rosgraph_msgs::Log::WARN) return;
      std::lock_guard<std::mutex> lock(mutex);
      warnings.push_back(m->msg);
    });
    pose = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        "/evidential_slam/pose", 100, [this](const auto& m) {
          std::lock_guard<std::mutex> lock(mutex);
          pose_stamps.push_back(m->header.stamp.toSec());
        });
  }
  // Lets the SLAM subscribe before the first scan (20 s at most).
  void waitForSlam() {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (scan.getNumSubscribers() == 0 && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }

  ros::Publisher clock, scan;
  ros::Subscriber rosout, pose;
  geometry_msgs::TransformStamped mount;  // base_link -> laser
  tf2_ros::TransformBroadcaster tf;
  tf2_ros::StaticTransformBroadcaster static_tf;
  std::mutex mutex;
  std::vector<std::string> warnings;
  std::vector<double> pose_stamps;

  // Publishes the clock, the odometry tf and a room scan at `t` (robot at x = 0.1 t, 0, 0); the
  // tf and the scan are stamped `t + stamp_offset` (a driver whose clock is off).
  void step(double t, const std::string& laser_frame = "laser",
            const std::function<void(sensor_msgs::LaserScan*)>& spoil = {},
            double stamp_offset = 0.0) {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(t);
    clock.publish(c);
    // Again at every step, as a looping bag replays it: a tf listener forgets everything,
    // static transforms included, when time jumps back.
    static_tf.sendTransform(mount);
    const Pose2 odom(0.1 * (t - 100.0), 0.0, 0.0);
    geometry_msgs::TransformStamped ts;
    ts.header.stamp = ros::Time(t + stamp_offset);
    ts.header.frame_id = "odom";
    ts.child_frame_id = "base_link";
    ts.transform = ros_adapter::toTransformMsg(odom);
    tf.sendTransform(ts);
    LaserScan core = testing_room::roomScan(odom, t + stamp_offset);
    core.bearings.pop_back();  // a LaserScan's rays are evenly spaced over [-pi, pi)
    core.ranges.pop_back();
    core.valid.pop_back();
    sensor_msgs::LaserScan msg;
    std::string why;
    ASSERT_TRUE(ros_adapter::scanToRos(core, laser_frame, &msg, &why)) << why;
    if (spoil) spoil(&msg);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // tf first
    scan.publish(msg);
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
  }

  template <typename F>
  bool waitFor(F&& ready, double seconds) {
    return waitUntil(mutex, std::forward<F>(ready), seconds);
  }

  bool warned(const std::string& text, double seconds) {
    return waitFor(
        [&] {
          for (const auto& w : warnings) {
            if (w.find(text) != std::string::npos) return true;
          }
          return false;
        },
        seconds);
  }
  // A ~pose stamped `t` among those received from the `from`-th on (earlier tests may have had
  // poses at the same stamps).
  bool poseAt(double t, double seconds, size_t from = 0) {
    return waitFor(
        [&] {
          for (size_t i = from; i < pose_stamps.size(); ++i) {
            if (std::abs(pose_stamps[i] - t) < 1e-6) return true;
          }
          return false;
        },
        seconds);
  }
  size_t posesReceived() {
    std::lock_guard<std::mutex> lock(mutex);
    return pose_stamps.size();
  }
};

// The main() of a rostest whose tests drive a Robot: starts GoogleTest and ROS as `node_name`,
// hands the Robot to the tests through `*robot`, lets the SLAM subscribe, runs the tests.
inline int runRobotTests(int argc, char** argv, const char* node_name, Robot** robot) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, node_name);
  ros::NodeHandle nh;
  Robot the_robot(nh);
  *robot = &the_robot;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  the_robot.waitForSlam();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}

}  // namespace testing_ros
}  // namespace evidential_slam
