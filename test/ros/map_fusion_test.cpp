// rostest for the map fusion nodelet (map_fusion.test): this node publishes three robots' maps as
// EvidentialGrid on /robotN/evidential_slam/grid; robot1 and robot2 have map_merge's init_pose_*
// parameters, robot3 none. The fused map must appear in `world`, hold both posed robots' areas
// where their poses put them (its free space, its walls in the trinary map), nothing between
// them, and nothing of robot3.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/ros/conversions.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

constexpr double kResolution = 0.1;

// A robot's map in its own frame: free space x in [x0, x0 + 4) m, y in [0, 2) m, a wall along
// x = x0 + 4 m (x0 in cells).
EvidentialGrid roomGrid(int x0) {
  EvidentialGridMap map(kResolution);
  for (int y = 0; y < 20; ++y) {
    for (int x = x0; x <= x0 + 40; ++x) {
      map.mutableCell(x, y) = x == x0 + 40 ? Cell::fromStored(0.9f, 0.0f, 0.0f)
                                           : Cell::fromStored(0.0f, 0.8f, 0.0f);
    }
  }
  std_msgs::Header header;
  header.stamp = ros::Time(1.0);
  header.frame_id = "map";
  EvidentialGrid msg;
  ros_adapter::toEvidentialGridMsg(extractLayers(map), header, &msg);
  return msg;
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

TEST(MapFusion, FusesThePosedRobotsMapsInTheWorldFrame) {
  ros::NodeHandle nh;
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
  auto grid_sub = nh.subscribe<EvidentialGrid>(
      "/map_fusion/grid", 1, [&](const EvidentialGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        grid = *m;
        have_grid = true;
      });
  std::vector<ros::Publisher> pubs;
  for (const char* robot : {"robot1", "robot2", "robot3"}) {
    pubs.push_back(nh.advertise<EvidentialGrid>(std::string("/") + robot + "/evidential_slam/grid",
                                                1, true));
  }
  pubs[0].publish(roomGrid(0));
  pubs[1].publish(roomGrid(0));
  pubs[2].publish(roomGrid(-60));  // from x = -6 m: it would show left of robot1 if it were fused
  // The node looks for robots every 0.2 s and fuses at 5 Hz.
  auto both = [&] {
    return have_map && have_grid && valueAt(map, 1.0, 1.0) == 0 && valueAt(map, 9.0, 1.0) == 0;
  };
  ASSERT_TRUE(testing_ros::waitUntil(mutex, both, 30.0)) << "no fused map with both robots";

  std::lock_guard<std::mutex> lock(mutex);
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
  EXPECT_NEAR(raster.layer(Layer::kFree)[static_cast<size_t>(row * raster.width + col)], 0.8,
              1e-6);
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "map_fusion_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}
