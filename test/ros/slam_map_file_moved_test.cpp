// rostest for the lifelong workflow on the node (slam_map_file_moved.test): the node continues
// yesterday's map (map_file) in a world where a box moved. On /map the box's new place must turn
// occupied and its old place free, however confident yesterday's map was (bounded confidence,
// docs/algorithm.md §2.4), while the rest of yesterday's map stays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/Bool.h>

#include "evidential_slam/io/dynamic_objects.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

struct Seen {
  std::mutex mutex;
  nav_msgs::OccupancyGrid::ConstPtr first_map;
  nav_msgs::OccupancyGrid::ConstPtr last_map;
  int maps = 0;
  bool done = false;
  double last_scan_stamp = -1.0;
  double last_pose_stamp = -1.0;
};
Seen* seen = nullptr;

template <typename T>
T param(const std::string& name) {
  T value{};
  EXPECT_TRUE(ros::param::get("~" + name, value)) << "~" << name << " is not set";
  return value;
}

// The one box of an objects file, in the map frame (the world shifted so the route's start is
// the origin; the route starts heading along +x, as the map frame does).
io::DynamicObject readBox(const std::string& file) {
  std::vector<io::DynamicObject> objects;
  std::string error;
  EXPECT_TRUE(io::readDynamicObjects(param<std::string>(file), &objects, &error)) << error;
  EXPECT_EQ(objects.size(), 1u);
  io::DynamicObject box = objects.empty() ? io::DynamicObject{} : objects[0];
  const Eigen::Vector2d start(param<double>("start_x"), param<double>("start_y"));
  box.a0 -= start;
  box.b0 -= start;
  box.a1 -= start;
  box.b1 -= start;
  return box;
}

// Distance from p to the box's capsule surface (negative inside).
double boxDistance(const io::DynamicObject& box, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = box.b0 - box.a0;
  const double u = std::clamp((p - box.a0).dot(d) / std::max(d.squaredNorm(), 1e-12), 0.0, 1.0);
  return (p - box.a0 - u * d).norm() - box.radius;
}

Eigen::Vector2d cellCentre(const nav_msgs::OccupancyGrid& map, size_t i) {
  const double res = map.info.resolution;
  return {map.info.origin.position.x + (i % map.info.width + 0.5) * res,
          map.info.origin.position.y + (i / map.info.width + 0.5) * res};
}

// The value of `map` at p (-1 outside it).
int valueAt(const nav_msgs::OccupancyGrid& map, const Eigen::Vector2d& p) {
  const double res = map.info.resolution;
  const long c = std::lround(std::floor((p.x() - map.info.origin.position.x) / res));
  const long r = std::lround(std::floor((p.y() - map.info.origin.position.y) / res));
  if (c < 0 || r < 0 || c >= long(map.info.width) || r >= long(map.info.height)) return -1;
  return map.data[r * map.info.width + c];
}

// Occupied cells of `map` within `margin` of the box.
std::vector<Eigen::Vector2d> occupiedNear(const nav_msgs::OccupancyGrid& map,
                                          const io::DynamicObject& box, double margin) {
  std::vector<Eigen::Vector2d> cells;
  for (size_t i = 0; i < map.data.size(); ++i) {
    const Eigen::Vector2d p = cellCentre(map, i);
    if (map.data[i] == 100 && boxDistance(box, p) <= margin) cells.push_back(p);
  }
  return cells;
}

TEST(SlamMapFileMoved, TheMovedBoxShowsOnMap) {
  const io::DynamicObject from = readBox("day1_objects"), to = readBox("day2_objects");
  ASSERT_TRUE(testing_ros::waitUntil(
      seen->mutex, [] { return seen->first_map != nullptr; }, 30.0));
  nav_msgs::OccupancyGrid first;
  {
    std::lock_guard<std::mutex> lock(seen->mutex);
    first = *seen->first_map;
  }
  const double res = first.info.resolution;
  // Yesterday's map, as served before today's first scan: the box at its old place, free floor
  // where it stands today.
  ASSERT_EQ(first.header.stamp.toSec(), 0.0) << "the first map came after a scan";
  const std::vector<Eigen::Vector2d> old_place = occupiedNear(first, from, res);
  ASSERT_GE(old_place.size(), 30u) << "the loaded map does not hold the box";
  ASSERT_EQ(occupiedNear(first, to, res).size(), 0u);

  ASSERT_TRUE(testing_ros::waitUntil(
      seen->mutex, [] { return seen->done; }, 100.0))
      << "the simulator did not finish its route";
  ASSERT_TRUE(testing_ros::waitUntil(
      seen->mutex, [] { return seen->last_pose_stamp >= seen->last_scan_stamp - 1e-6; }, 60.0))
      << "the node did not handle the last scan";
  int maps_then = 0;
  {
    std::lock_guard<std::mutex> lock(seen->mutex);
    maps_then = seen->maps;
  }
  // The map the last update changed comes at the next map_update_interval (1 s of ROS time at
  // twice real time); an unchanged map is not sent again, so after that the last map is current.
  testing_ros::waitUntil(
      seen->mutex, [&] { return seen->maps > maps_then; }, 5.0);
  nav_msgs::OccupancyGrid last;
  {
    std::lock_guard<std::mutex> lock(seen->mutex);
    last = *seen->last_map;
  }

  // The new place: at least 3/4 of the box's long face (1.2 m) that the route passes.
  const size_t new_place = occupiedNear(last, to, res).size();
  EXPECT_GE(new_place, size_t(std::lround(0.75 * 1.2 / res)))
      << "the box's new place is not an obstacle";
  RecordProperty("new_place_occupied_cells", std::to_string(new_place));
  // The old place: yesterday's occupied cells there are free floor now (a cell's slack).
  size_t freed = 0;
  for (const auto& p : old_place) freed += valueAt(last, p) == 0;
  EXPECT_GE(freed, 0.9 * old_place.size()) << freed << " of " << old_place.size();
  RecordProperty("old_place_freed", std::to_string(freed) + "/" + std::to_string(old_place.size()));
  // Everything else yesterday held occupied is still occupied (within a cell: today's poses).
  size_t kept = 0, walls = 0;
  for (size_t i = 0; i < first.data.size(); ++i) {
    const Eigen::Vector2d p = cellCentre(first, i);
    if (first.data[i] != 100 || boxDistance(from, p) <= 3 * res || boxDistance(to, p) <= 3 * res)
      continue;
    ++walls;
    bool occupied = false;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        occupied = occupied || valueAt(last, p + Eigen::Vector2d(dx * res, dy * res)) == 100;
    kept += occupied;
  }
  EXPECT_GE(kept, 0.97 * walls) << kept << " of " << walls;
  RecordProperty("walls_kept", std::to_string(kept) + "/" + std::to_string(walls));
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "slam_map_file_moved_test");
  ros::NodeHandle nh;
  evidential_slam::Seen seen;
  evidential_slam::seen = &seen;
  auto map = evidential_slam::testing_ros::subscribeLocked<nav_msgs::OccupancyGrid>(
      nh, "/map", 1, seen.mutex, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        if (!seen.first_map) seen.first_map = m;
        seen.last_map = m;
        ++seen.maps;
      });
  auto scans = evidential_slam::testing_ros::subscribeLocked<sensor_msgs::LaserScan>(
      nh, "/scan", 100, seen.mutex,
      [&](const auto& m) { seen.last_scan_stamp = m->header.stamp.toSec(); });
  auto done = evidential_slam::testing_ros::subscribeLocked<std_msgs::Bool>(
      nh, "/gridmap_simulator/done", 1, seen.mutex, [&](const auto& m) { seen.done = m->data; });
  auto pose =
      evidential_slam::testing_ros::subscribeLocked<geometry_msgs::PoseWithCovarianceStamped>(
          nh, "/evidential_slam/pose", 10, seen.mutex,
          [&](const auto& m) { seen.last_pose_stamp = m->header.stamp.toSec(); });
  return evidential_slam::testing_ros::runAllTestsSpinning();
}
