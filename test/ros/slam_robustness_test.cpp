// rostest for the nodelet's handling of bad input (slam_robustness.test). This node is the
// robot: it drives /clock, the odometry tf and scans of a 4 m x 4 m room, and breaks them on
// purpose: a scan whose frame has no tf, rays that are NaN or inf, time that jumps backwards, a
// save_map to a directory that cannot be written.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/GetMap.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "evidential_slam/SaveMap.h"
#include "evidential_slam/ros/conversions.h"
#include "ros_test_support.h"
#include "test_support.h"

namespace evidential_slam {
namespace {

struct Robot {
  ros::Publisher clock, scan;
  geometry_msgs::TransformStamped mount;  // base_link -> laser
  tf2_ros::TransformBroadcaster tf;
  tf2_ros::StaticTransformBroadcaster static_tf;
  std::mutex mutex;
  std::vector<std::string> warnings;
  std::vector<double> pose_stamps;

  // Publishes the clock, the odometry tf and a room scan at `t` (robot at x = 0.1 t, 0, 0).
  void step(double t, const std::string& laser_frame = "laser",
            const std::function<void(sensor_msgs::LaserScan*)>& spoil = {}) {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(t);
    clock.publish(c);
    // Again at every step, as a looping bag replays it: a tf listener forgets everything,
    // static transforms included, when time jumps back.
    static_tf.sendTransform(mount);
    const Pose2 odom(0.1 * (t - 100.0), 0.0, 0.0);
    geometry_msgs::TransformStamped ts;
    ts.header.stamp = ros::Time(t);
    ts.header.frame_id = "odom";
    ts.child_frame_id = "base_link";
    ts.transform = ros_adapter::toTransformMsg(odom);
    tf.sendTransform(ts);
    LaserScan core = testing_room::roomScan(odom, t);
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
    return testing_ros::waitUntil(mutex, std::forward<F>(ready), seconds);
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
  bool poseAt(double t, double seconds) {
    return waitFor(
        [&] {
          for (double s : pose_stamps) {
            if (std::abs(s - t) < 1e-6) return true;
          }
          return false;
        },
        seconds);
  }
};

Robot* robot = nullptr;

TEST(SlamRobustness, NormalScansAreMapped) {
  for (int i = 0; i < 5; ++i) robot->step(100.0 + i);
  EXPECT_TRUE(robot->poseAt(104.0, 10.0));
}

TEST(SlamRobustness, ScanWithoutTransformIsDroppedWithAWarningNamingTheFrames) {
  for (int i = 0; i < 3; ++i) robot->step(105.0 + i, "laser_without_tf");
  EXPECT_TRUE(robot->warned("laser_without_tf", 15.0));
  EXPECT_FALSE(robot->poseAt(105.0, 0.5));
  robot->step(108.0);  // and the next good scan is mapped
  EXPECT_TRUE(robot->poseAt(108.0, 10.0));
  // The scans without tf stay in the filter while later ones go through: reported as lost.
  EXPECT_TRUE(robot->warned("lost: it still waits for its transform", 15.0));
}

TEST(SlamRobustness, NanAndInfRangesAreSkipped) {
  robot->step(109.0, "laser", [](sensor_msgs::LaserScan* m) {
    for (size_t i = 0; i < m->ranges.size(); i += 2) {
      m->ranges[i] = std::numeric_limits<float>::quiet_NaN();
    }
    for (size_t i = 1; i < m->ranges.size(); i += 4) {
      m->ranges[i] = std::numeric_limits<float>::infinity();
    }
  });
  EXPECT_TRUE(robot->poseAt(109.0, 10.0));
  robot->step(110.0, "laser", [](sensor_msgs::LaserScan* m) {
    for (float& r : m->ranges) r = std::numeric_limits<float>::quiet_NaN();
  });
  EXPECT_TRUE(robot->warned("unusable", 10.0));
}

TEST(SlamRobustness, TimeJumpingBackRestartsTheSlam) {
  robot->step(111.0);
  ASSERT_TRUE(robot->poseAt(111.0, 10.0));
  for (int i = 0; i < 3; ++i) robot->step(100.0 + i);  // the bag loops
  EXPECT_TRUE(robot->warned("time jumped back", 15.0));
  EXPECT_TRUE(robot->poseAt(102.0, 10.0));  // and it maps again
}

TEST(SlamRobustness, SaveMapReportsUnwritableDirectories) {
  ASSERT_TRUE(ros::service::waitForService("/evidential_slam/save_map", 10000));
  SaveMap save;
  save.request.directory = "/proc/evidential_slam_cannot_write_here";
  ASSERT_TRUE(ros::service::call("/evidential_slam/save_map", save));
  EXPECT_FALSE(save.response.success);
  EXPECT_NE(save.response.message.find("/proc/evidential_slam_cannot_write_here"),
            std::string::npos)
      << save.response.message;
  save.request.directory = "";
  ASSERT_TRUE(ros::service::call("/evidential_slam/save_map", save));
  EXPECT_FALSE(save.response.success);

  nav_msgs::GetMap get;
  ASSERT_TRUE(ros::service::call("/dynamic_map", get));
  EXPECT_GT(get.response.map.data.size(), 100u);
  EXPECT_EQ(get.response.map.header.frame_id, "map");
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "slam_robustness_test");
  ros::NodeHandle nh;
  evidential_slam::Robot robot;
  evidential_slam::robot = &robot;
  robot.clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  robot.scan = nh.advertise<sensor_msgs::LaserScan>("/scan", 10);
  robot.mount.header.frame_id = "base_link";
  robot.mount.child_frame_id = "laser";
  robot.mount.transform.rotation.w = 1.0;
  robot.static_tf.sendTransform(robot.mount);
  auto rosout = nh.subscribe<rosgraph_msgs::Log>("/rosout", 100, [&](const auto& m) {
    if (m->level < rosgraph_msgs::Log::WARN) return;
    std::lock_guard<std::mutex> lock(robot.mutex);
    robot.warnings.push_back(m->msg);
  });
  auto pose = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
      "/evidential_slam/pose", 100, [&](const auto& m) {
        std::lock_guard<std::mutex> lock(robot.mutex);
        robot.pose_stamps.push_back(m->header.stamp.toSec());
      });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // Let the SLAM subscribe before the first scan.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (robot.scan.getNumSubscribers() == 0 && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}
