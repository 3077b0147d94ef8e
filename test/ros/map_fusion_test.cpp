// rostests for the map fusion nodelet. map_fusion.test: this node publishes three robots' maps as
// EvidentialGrid on /robotN/evidential_slam/grid; robot1 and robot2 have map_merge's init_pose_*
// parameters, robot3 none. The fused map must appear in `world`, hold both posed robots' areas
// where their poses put them (its free space, its walls in the trinary map), nothing between
// them, and nothing of robot3. map_fusion_estimated.test (known_init_poses: false): robot2's map
// overlaps robot1's and must be placed by alignment, robot3's matches nothing and is left out.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <sstream>
#include <string>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include "../core/fusion/synthetic_world.h"
#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/ros/conversions.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

constexpr double kResolution = 0.1;

// A robot's map in its own frame: free space x in [x0, x0 + 4) m, y in [0, 2) m, a wall along
// x = x0 + 4 m (x0 in cells).
EvidentialGrid gridMsg(const EvidentialGridMap& map) {
  std_msgs::Header header;
  header.stamp = ros::Time(1.0);
  header.frame_id = "map";
  EvidentialGrid msg;
  ros_adapter::toEvidentialGridMsg(extractLayers(map), header, &msg);
  return msg;
}

EvidentialGrid roomGrid(int x0) {
  EvidentialGridMap map(kResolution);
  for (int y = 0; y < 20; ++y) {
    for (int x = x0; x <= x0 + 40; ++x) {
      map.mutableCell(x, y) =
          x == x0 + 40 ? Cell::fromStored(0.9f, 0.0f, 0.0f) : Cell::fromStored(0.0f, 0.8f, 0.0f);
    }
  }
  return gridMsg(map);
}

// The value of the occupancy grid at a world point; -2 outside it.
int valueAt(const nav_msgs::OccupancyGrid& g, double x, double y) {
  const int col = static_cast<int>(std::floor((x - g.info.origin.position.x) / g.info.resolution));
  const int row = static_cast<int>(std::floor((y - g.info.origin.position.y) / g.info.resolution));
  if (col < 0 || row < 0 || col >= static_cast<int>(g.info.width) ||
      row >= static_cast<int>(g.info.height)) {
    return -2;
  }
  return g.data[static_cast<size_t>(row) * g.info.width + static_cast<size_t>(col)];
}

// What the test last received on /map, for a failure message.
std::string describe(bool have_map, const nav_msgs::OccupancyGrid& g, double x, double y) {
  if (!have_map) return "no /map received";
  std::ostringstream out;
  out << "the last /map: " << g.info.width << " x " << g.info.height << " cells from ("
      << g.info.origin.position.x << ", " << g.info.origin.position.y << "), value "
      << valueAt(g, x, y) << " at (" << x << ", " << y << ")";
  return out.str();
}

TEST(MapFusion, FusesThePosedRobotsMapsInTheWorldFrame) {
  ros::NodeHandle nh;
  testing_ros::NodeLog node_log(nh);
  std::mutex mutex;
  nav_msgs::OccupancyGrid map;
  EvidentialGrid grid;
  bool have_map = false, have_grid = false;
  auto map_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map", 1, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        map = *m;
        have_map = true;
      });
  auto grid_sub =
      nh.subscribe<EvidentialGrid>("/map_fusion/grid", 1, [&](const EvidentialGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        grid = *m;
        have_grid = true;
      });
  std::vector<ros::Publisher> pubs;
  for (const char* robot : {"robot1", "robot2", "robot3"}) {
    pubs.push_back(
        nh.advertise<EvidentialGrid>(std::string("/") + robot + "/evidential_slam/grid", 1, true));
  }
  pubs[0].publish(roomGrid(0));
  pubs[1].publish(roomGrid(0));
  pubs[2].publish(roomGrid(-60));  // from x = -6 m: it would show left of robot1 if it were fused
  // The node looks for robots every 0.2 s and fuses at 5 Hz.
  auto both = [&] {
    return have_map && have_grid && valueAt(map, 1.0, 1.0) == 0 && valueAt(map, 9.0, 1.0) == 0;
  };
  const bool fused = testing_ros::waitUntil(mutex, both, 30.0);
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_TRUE(fused) << "no fused map with both robots; " << describe(have_map, map, 9.0, 1.0)
                     << "\n"
                     << node_log.str();
  EXPECT_EQ(map.header.frame_id, "world");
  EXPECT_EQ(grid.header.frame_id, "world");
  EXPECT_EQ(grid.layers.size(), static_cast<size_t>(kLayerCount));
  EXPECT_NEAR(map.info.resolution, kResolution, 1e-6);
  // robot1 at (0, 0, 0): free at (1, 1), its wall at x = 4.05.
  EXPECT_EQ(valueAt(map, 1.0, 1.0), 0);
  EXPECT_EQ(valueAt(map, 4.05, 1.0), 100);
  // robot2 at (10, 0, pi/2): its x axis is the world's y: free at (9, 1), its wall at y = 4.05.
  EXPECT_EQ(valueAt(map, 9.0, 1.0), 0);
  EXPECT_EQ(valueAt(map, 9.0, 4.05), 100);
  // Between them: never observed.
  EXPECT_EQ(valueAt(map, 6.0, 1.0), -1);
  // robot3 (no init pose) is not fused: nothing beyond robot2's area on the left of the world.
  EXPECT_GE(map.info.origin.position.x, -1.5);
  // The fused EvidentialGrid: m(e) of a free cell of robot1 as the map holds it (0.8).
  LayerRaster raster;
  std::string why;
  ASSERT_TRUE(ros_adapter::layerRasterFromMsg(grid, &raster, nullptr, &why)) << why;
  const int col = static_cast<int>(std::floor((1.05 - raster.origin_x) / raster.resolution));
  const int row = static_cast<int>(std::floor((1.05 - raster.origin_y) / raster.resolution));
  EXPECT_NEAR(raster.layer(Layer::kFree)[static_cast<size_t>(row * raster.width + col)], 0.8, 1e-6);
}

// The office of the core's alignment tests: robot1 maps its west part from the world origin,
// robot2 its east part from a map frame at (12.3, -4.1, 2.2 rad), robot3 a world of clutter.
// Without init poses the node must put robot2's part where the office is and leave robot3 out.
TEST(MapFusion, EstimatesWhereARobotsMapFitsAndLeavesOutOneThatFitsNowhere) {
  ros::NodeHandle nh;
  testing_ros::NodeLog node_log(nh);
  std::mutex mutex;
  nav_msgs::OccupancyGrid map;
  bool have_map = false;
  auto map_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map", 1, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        map = *m;
        have_map = true;
      });
  constexpr double kCell = 0.05;
  const synthetic::World office = synthetic::office();
  std::vector<ros::Publisher> pubs;
  for (const char* robot : {"robot1", "robot2", "robot3"}) {
    pubs.push_back(
        nh.advertise<EvidentialGrid>(std::string("/") + robot + "/evidential_slam/grid", 1, true));
  }
  pubs[0].publish(gridMsg(synthetic::paint(office, Pose2(), {7.0, 7.0}, 9.0, kCell, 1)));
  pubs[1].publish(
      gridMsg(synthetic::paint(office, Pose2(12.3, -4.1, 2.2), {13.0, 7.0}, 9.0, kCell, 2)));
  // Its cells 30 m to the right of its world: if it were fused at its own frame, the map would
  // reach x = 30 m and beyond.
  pubs[2].publish(gridMsg(
      synthetic::paint(synthetic::clutter(5), Pose2(-30.0, 0.0, 0.0), {8.0, 8.0}, 8.0, kCell, 3)));
  // Free in the corridor east of robot1's reach: only robot2 saw it.
  auto placed = [&] { return have_map && valueAt(map, 19.0, 7.0) == 0; };
  const bool was_placed = testing_ros::waitUntil(mutex, placed, 90.0);
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_TRUE(was_placed) << "robot2's map was not placed; " << describe(have_map, map, 19.0, 7.0)
                          << "\n"
                          << node_log.str();
  EXPECT_EQ(map.header.frame_id, "world");
  // The office's east wall (x = 20 m) where robot2 saw it, within a cell.
  for (double y : {2.0, 7.0, 12.0}) {
    EXPECT_TRUE(valueAt(map, 19.975, y) == 100 || valueAt(map, 19.925, y) == 100 ||
                valueAt(map, 20.025, y) == 100)
        << "no wall at (20, " << y << ")";
  }
  // robot1's part: free in the west corridor, its west wall.
  EXPECT_EQ(valueAt(map, 1.0, 7.0), 0);
  // robot3 was not fused: the map ends within a metre of the office's walls (the raster's margin
  // is 0.5 m).
  const double x1 = map.info.origin.position.x + map.info.width * map.info.resolution;
  const double y1 = map.info.origin.position.y + map.info.height * map.info.resolution;
  EXPECT_GE(map.info.origin.position.x, -1.0);
  EXPECT_GE(map.info.origin.position.y, -1.0);
  EXPECT_LE(x1, 21.0);
  EXPECT_LE(y1, 15.0);
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "map_fusion_test");
  return evidential_slam::testing_ros::runAllTestsSpinning(1);
}
