// rostest for the nodelet's handling of bad input (slam_robustness.test). This node is the
// robot: it drives /clock, the odometry tf and scans of a 4 m x 4 m room, and breaks them on
// purpose: a scan whose frame has no tf, rays that are NaN or inf, time that jumps backwards, a
// save_map to a directory that cannot be written.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/GetMap.h>
#include <ros/ros.h>

#include "evidential_slam/SaveMap.h"
#include "room_robot.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

using testing_ros::Robot;

Robot* robot = nullptr;

TEST(SlamRobustness, NormalScansAreMapped) {
  for (int i = 0; i < 5; ++i) robot->step(100.0 + i);
  EXPECT_TRUE(robot->poseAt(104.0, 10.0));
  std::lock_guard<std::mutex> lock(robot->mutex);
  for (const auto& w : robot->warnings) fprintf(stderr, "DBG %s\n", w.c_str());
  for (double p : robot->pose_stamps) fprintf(stderr, "DBGP %.3f\n", p);
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

TEST(SlamRobustness, MalformedScansAreDroppedWithAWarningNamingTheField) {
  robot->step(111.0, "laser", [](sensor_msgs::LaserScan* m) { m->intensities.assign(3, 1.0f); });
  EXPECT_TRUE(robot->warned("malformed LaserScan", 10.0));
  EXPECT_TRUE(robot->warned("intensities has 3 values", 1.0));
  EXPECT_FALSE(robot->poseAt(111.0, 0.5));
  robot->step(112.0);
  EXPECT_TRUE(robot->poseAt(112.0, 10.0));
}

// One scan stamped 1.5 s behind its neighbours: dropped and reported, no restart. (Later than
// the throttle, 5 s of ROS time, of the earlier tests' warnings.)
TEST(SlamRobustness, OneStampBehindIsAnOutlierNotARestart) {
  robot->step(116.0);
  robot->step(117.0, "laser",
              [](sensor_msgs::LaserScan* m) { m->header.stamp = ros::Time(114.5); });
  EXPECT_TRUE(robot->warned("an outlier", 10.0));
  robot->step(118.0);
  EXPECT_TRUE(robot->poseAt(118.0, 10.0));
  EXPECT_FALSE(robot->warned("jumped back", 0.5));  // no restart
}

// The heartbeat counts what was dropped, once a second, whatever the robot does.
TEST(SlamRobustness, HeartbeatOnDiagnosticsCountsTheDrops) {
  std::mutex mutex;
  std::map<std::string, std::string> values;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& status : m->status) {
          if (status.name.find("heartbeat") == std::string::npos) continue;
          std::lock_guard<std::mutex> lock(mutex);
          for (const auto& kv : status.values) values[kv.key] = kv.value;
        }
      });
  // Wall-timed: no scan and no clock tick while waiting.
  const bool seen = testing_ros::waitUntil(
      mutex, [&] { return values.count("dropped: malformed") > 0; }, 10.0);
  ASSERT_TRUE(seen);
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_GE(std::stoi(values["dropped: malformed"]), 1);
  EXPECT_GE(std::stoi(values["dropped: stamp outlier"]), 1);
  EXPECT_GE(std::stoi(values["dropped: no transform"]), 1);
  EXPECT_GE(std::stoi(values["scans received"]), 10);
  EXPECT_EQ(values["restarts"], "0");
  EXPECT_TRUE(values.count("queue length"));
  EXPECT_TRUE(values.count("latency max (s)"));
  EXPECT_TRUE(values.count("conflict alarm"));
}

TEST(SlamRobustness, TimeJumpingBackRestartsTheSlam) {
  robot->step(119.0);
  ASSERT_TRUE(robot->poseAt(119.0, 10.0));
  for (int i = 0; i < 3; ++i) robot->step(100.0 + i);  // the bag loops
  EXPECT_TRUE(robot->warned("time jumped back", 15.0));
  EXPECT_TRUE(robot->poseAt(102.0, 10.0));  // and it maps again
}

// A looping bag: /tf of the previous loop, queued behind /clock, lands after the clock went back.
// tf2's listener has cleared its buffer at the jump and takes that late transform, after which
// every transform of the new loop is older than its cache: the node clears the buffer again at
// the new loop's first scan, so the SLAM maps again at once.
TEST(SlamRobustness, ALateTransformOfTheLastLoopDoesNotBlockTheNext) {
  robot->step(115.0);
  robot->step(116.0);
  ASSERT_TRUE(robot->poseAt(116.0, 10.0));
  rosgraph_msgs::Clock back;
  back.clock = ros::Time(100.0);
  robot->clock.publish(back);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  geometry_msgs::TransformStamped late;
  late.header.stamp = ros::Time(116.5);  // 16.5 s ahead: beyond the tf cache's 10 s
  late.header.frame_id = "odom";
  late.child_frame_id = "base_link";
  late.transform = ros_adapter::toTransformMsg(Pose2(1.65, 0.0, 0.0));
  robot->tf.sendTransform(late);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const size_t poses_before = robot->posesReceived();
  for (int i = 0; i < 5; ++i) robot->step(100.0 + i);
  // The first scan of the loop, whose transform came before the clear, is dropped; the rest map.
  // (Earlier tests had poses at these stamps: only poses published from here on count.)
  EXPECT_TRUE(robot->poseAt(103.0, 10.0, poses_before));
  EXPECT_TRUE(robot->poseAt(104.0, 10.0, poses_before));
}

// A driver stamps 0.25 s of tf and scans 3 h ahead, then normal stamps again while ROS time goes
// on as before: tf2's buffer holds the future and would refuse every later transform as too old
// (TF_OLD_DATA) until the clock caught up. The node clears it once the stamps have jumped back for
// time_jump_scans scans in a row, says so, and maps the normal scans again.
TEST(SlamRobustness, ABurstOfFutureStampsIsRecoveredFrom) {
  const size_t poses_first = robot->posesReceived();
  robot->step(105.0);
  ASSERT_TRUE(robot->poseAt(105.0, 10.0, poses_first));
  for (int i = 1; i <= 5; ++i) robot->step(105.0 + 0.05 * i, "laser", {}, 3.0 * 3600.0);
  const size_t poses_before = robot->posesReceived();
  for (int i = 1; i <= 9; ++i) robot->step(106.0 + i);
  EXPECT_TRUE(robot->warned("the transform buffer is cleared", 15.0));
  // The session drops the first normal stamps as outliers, then starts over on them.
  EXPECT_TRUE(robot->poseAt(114.0, 15.0, poses_before));
  EXPECT_TRUE(robot->poseAt(115.0, 15.0, poses_before));
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
  return evidential_slam::testing_ros::runRobotTests(argc, argv, "slam_robustness_test",
                                                     &evidential_slam::robot);
}
