// rostest (slam_final_map.test): when ROS time stops (a bag's /clock ended) the map of the last
// scans is still published, timed on wall time; and a map is not sent again while it is unchanged.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <vector>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include "room_robot.h"

namespace evidential_slam {
namespace {

testing_ros::Robot* robot = nullptr;

TEST(SlamFinalMap, TheLastScanReachesTheMapAfterTheClockStops) {
  ros::NodeHandle nh;
  std::mutex mutex;
  std::vector<double> map_stamps;
  auto map_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map", 10, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        map_stamps.push_back(m->header.stamp.toSec());
      });
  // Each scan the filter takes is processed (0.01 m per scan, update_min_distance 0.005 m).
  const double last = 101.9;
  for (int i = 0; i <= 19; ++i) robot->step(100.0 + 0.1 * i);
  // The clock stands at 101.9 from now on: only the wall-time timer can send the last map.
  EXPECT_TRUE(testing_ros::waitUntil(
      mutex, [&] { return !map_stamps.empty() && std::abs(map_stamps.back() - last) < 1e-6; },
      15.0))
      << (map_stamps.empty() ? -1.0 : map_stamps.back());
  // Nothing changes any more: no further map.
  size_t sent = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    sent = map_stamps.size();
  }
  ros::WallDuration(4.0).sleep();
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(map_stamps.size(), sent);
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  return evidential_slam::testing_ros::runRobotTests(argc, argv, "slam_final_map_test",
                                                     &evidential_slam::robot);
}
