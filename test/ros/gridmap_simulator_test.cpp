// rostest for gridmap_simulator (gridmap_simulator.test): the simulator drives a short route
// through test/data/sim_map.png on simulated time with noisy odometry and feeds the SLAM nodelet;
// this node checks that scans, tf and the ground truth arrive, that ~done turns true, that the
// route made no collision, and that the SLAM ends near the true pose while the odometry alone
// does not; and that map -> odom is on tf at each handled scan's stamp.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/Bool.h>
#include <std_msgs/UInt32.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "evidential_slam/core/pose2.h"
#include "evidential_slam/ros/conversions.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

struct Observed {
  std::mutex mutex;
  bool done = false;
  bool have_collisions = false;
  uint32_t collisions = 0;
  size_t scans = 0;
  double last_scan_stamp = 0.0;
  size_t scan_rays = 0;
  std::string scan_frame;
  std::vector<geometry_msgs::PoseStamped> truth_poses;
  nav_msgs::Path::ConstPtr truth_path;
  geometry_msgs::PoseWithCovarianceStamped::ConstPtr slam_pose;
  std::set<uint64_t> pose_stamps_ns;  // of every ~pose (one per handled scan)
  std::vector<geometry_msgs::TransformStamped> map_to_odom;  // every map -> odom on /tf
};

Observed* observed = nullptr;
tf2_ros::Buffer* tf_buffer = nullptr;

template <typename F>
bool waitFor(F&& ready, double seconds) {
  return testing_ros::waitUntil(observed->mutex, std::forward<F>(ready), seconds);
}

double yawError(const Pose2& a, const Pose2& b) {
  return std::abs(normalizeAngle(a.theta - b.theta));
}

TEST(GridmapSimulatorRos, DrivesTheRouteAndTheSlamEndsNearTheTruth) {
  ASSERT_TRUE(waitFor([] { return observed->done; }, 180.0)) << "~done never turned true";
  ASSERT_TRUE(
      waitFor([] { return observed->truth_path && !observed->truth_path->poses.empty(); }, 10.0))
      << "no ground-truth path";
  Pose2 truth_end;
  double last_stamp = 0.0;
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    const nav_msgs::Path& path = *observed->truth_path;
    const size_t published = path.poses.size();
    // The route is about 18.5 m at 0.5 m/s with 10 scans/s: some 390 scans.
    EXPECT_GT(published, 300u);
    EXPECT_GE(observed->scans, published - 5) << "scans were lost";
    EXPECT_LE(observed->scans, published);
    EXPECT_GE(observed->truth_poses.size(), published - 5);
    EXPECT_LE(observed->truth_poses.size(), published);
    EXPECT_EQ(observed->scan_rays, 361u);
    EXPECT_EQ(observed->scan_frame, "laser");
    EXPECT_EQ(path.header.frame_id, "map");
    // The true path is moved so that the true start pose is the map origin.
    const Pose2 start = ros_adapter::pose2FromPoseMsg(path.poses.front().pose);
    EXPECT_NEAR(start.x, 0.0, 1e-6);
    EXPECT_NEAR(start.y, 0.0, 1e-6);
    EXPECT_NEAR(start.theta, 0.0, 1e-6);
    truth_end = ros_adapter::pose2FromPoseMsg(path.poses.back().pose);
    last_stamp = path.poses.back().header.stamp.toSec();
    EXPECT_NEAR(observed->last_scan_stamp, last_stamp, 1e-6);
    EXPECT_GT(truth_end.translation().norm(), 5.0);  // it went somewhere
    // The route keeps clear of the walls (robot_radius 0.2 m).
    EXPECT_TRUE(observed->have_collisions);
    EXPECT_EQ(observed->collisions, 0u);
  }

  // tf: the odometry at the last scan and the laser's mounting.
  std::string error;
  ASSERT_TRUE(tf_buffer->canTransform("odom", "base_link", ros::Time(last_stamp),
                                      ros::Duration(5.0), &error))
      << error;
  const Pose2 odometry_end = ros_adapter::pose2FromTransform(
      tf_buffer->lookupTransform("odom", "base_link", ros::Time(last_stamp)).transform);
  ASSERT_TRUE(
      tf_buffer->canTransform("base_link", "laser", ros::Time(0), ros::Duration(1.0), &error))
      << error;
  const Pose2 laser = ros_adapter::pose2FromTransform(
      tf_buffer->lookupTransform("base_link", "laser", ros::Time(0)).transform);
  EXPECT_NEAR(laser.x, 0.2, 1e-6);

  // The SLAM's pose at the last scan, against the truth (both in the map frame, which starts at
  // the first odometry pose).
  ASSERT_TRUE(waitFor(
      [&] {
        return observed->slam_pose &&
               std::abs(observed->slam_pose->header.stamp.toSec() - last_stamp) < 1e-3;
      },
      60.0))
      << "the SLAM pose of the last scan never came";
  Pose2 slam_end;
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    slam_end = ros_adapter::pose2FromPoseMsg(observed->slam_pose->pose.pose);
  }
  const double slam_error = (slam_end.translation() - truth_end.translation()).norm();
  const double odometry_error = (odometry_end.translation() - truth_end.translation()).norm();
  RecordProperty("slam_end_error_m", std::to_string(slam_error));
  RecordProperty("odometry_end_error_m", std::to_string(odometry_error));
  // The simulated odometry (seed 3) drifts ~0.75 m; the SLAM must correct it.
  EXPECT_GT(odometry_error, 0.4) << "the odometry is too good for this test to mean anything";
  EXPECT_LT(slam_error, 0.25) << "SLAM " << slam_error << " m, odometry " << odometry_error << " m";
  EXPECT_LT(yawError(slam_end, truth_end), 0.1);
}

// While mapping, map -> odom goes to tf at each handled scan's stamp as well as post-dated: a
// lookup at a scan's stamp gets the correction the filter found for that scan, not an earlier one.
TEST(GridmapSimulatorRos, MapToOdomAtEachScansStamp) {
  ASSERT_TRUE(waitFor([] { return observed->done; }, 180.0));
  std::vector<geometry_msgs::TransformStamped> at_scans;
  size_t poses = 0;
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    poses = observed->pose_stamps_ns.size();
    for (const auto& t : observed->map_to_odom)
      if (observed->pose_stamps_ns.count(t.header.stamp.toNSec())) at_scans.push_back(t);
  }
  ASSERT_GT(poses, 20u);
  // Every handled scan's, but for one a post-dated broadcast took first (a stamp tf holds).
  EXPECT_GE(at_scans.size(), poses - 1) << at_scans.size() << " of " << poses << " scans";
  RecordProperty("map_to_odom_at_scans",
                 std::to_string(at_scans.size()) + "/" + std::to_string(poses));
  size_t exact = 0;
  for (const auto& t : at_scans) {
    geometry_msgs::TransformStamped looked_up;
    try {
      looked_up = tf_buffer->lookupTransform("map", "odom", t.header.stamp);
    } catch (const tf2::TransformException& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    const Pose2 a = ros_adapter::pose2FromTransform(t.transform);
    const Pose2 b = ros_adapter::pose2FromTransform(looked_up.transform);
    exact += (a.translation() - b.translation()).norm() < 1e-9 && yawError(a, b) < 1e-9;
  }
  EXPECT_EQ(exact, at_scans.size()) << "a lookup at a scan's stamp gave another correction";
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "gridmap_simulator_test");
  ros::NodeHandle nh;
  evidential_slam::Observed obs;
  evidential_slam::observed = &obs;
  tf2_ros::Buffer buffer(ros::Duration(300.0));
  tf2_ros::TransformListener listener(buffer);
  evidential_slam::tf_buffer = &buffer;
  auto done = evidential_slam::testing_ros::subscribeLocked<std_msgs::Bool>(
      nh, "/gridmap_simulator/done", 1, obs.mutex, [&](const auto& m) { obs.done = m->data; });
  auto collisions = evidential_slam::testing_ros::subscribeLocked<std_msgs::UInt32>(
      nh, "/gridmap_simulator/collisions", 1, obs.mutex, [&](const std_msgs::UInt32::ConstPtr& m) {
        obs.have_collisions = true;
        obs.collisions = m->data;
      });
  auto scan = evidential_slam::testing_ros::subscribeLocked<sensor_msgs::LaserScan>(
      nh, "/scan", 1000, obs.mutex, [&](const sensor_msgs::LaserScan::ConstPtr& m) {
        ++obs.scans;
        obs.last_scan_stamp = m->header.stamp.toSec();
        obs.scan_rays = m->ranges.size();
        obs.scan_frame = m->header.frame_id;
      });
  auto truth_pose = evidential_slam::testing_ros::subscribeLocked<geometry_msgs::PoseStamped>(
      nh, "/ground_truth_pose", 1000, obs.mutex,
      [&](const geometry_msgs::PoseStamped::ConstPtr& m) { obs.truth_poses.push_back(*m); });
  auto truth_path = evidential_slam::testing_ros::subscribeLocked<nav_msgs::Path>(
      nh, "/ground_truth", 1, obs.mutex,
      [&](const nav_msgs::Path::ConstPtr& m) { obs.truth_path = m; });
  auto pose =
      evidential_slam::testing_ros::subscribeLocked<geometry_msgs::PoseWithCovarianceStamped>(
          nh, "/evidential_slam/pose", 10, obs.mutex,
          [&](const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) {
            obs.slam_pose = m;
            obs.pose_stamps_ns.insert(m->header.stamp.toNSec());
          });
  auto tf = evidential_slam::testing_ros::subscribeLocked<tf2_msgs::TFMessage>(
      nh, "/tf", 1000, obs.mutex, [&](const auto& m) {
        for (const auto& t : m->transforms)
          if (t.header.frame_id == "map" && t.child_frame_id == "odom")
            obs.map_to_odom.push_back(t);
      });
  return evidential_slam::testing_ros::runAllTestsSpinning();
}
