// rostest for slam_gmapping's parameter names (slam_gmapping.test): the node started with a
// turtlebot-style gmapping block ends with the converted values (read back from the parameter
// server, where dynamic_reconfigure writes the run-time ones; the particle count and the cell size
// from what it publishes) and maps; and readParams' handling of both names given, names without a
// counterpart, values out of our range and typos.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/PoseArray.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include "evidential_slam/ros/params.h"
#include "room_robot.h"

namespace evidential_slam {
namespace {

testing_ros::Robot* robot = nullptr;

double param(const std::string& name) {
  double value = -1.0;
  EXPECT_TRUE(ros::param::get("/slam_gmapping/" + name, value)) << name;
  return value;
}

TEST(SlamGmapping, TheNodeEndsWithTheConvertedValues) {
  EXPECT_DOUBLE_EQ(param("usable_range"), 6.0);            // maxUrange
  EXPECT_DOUBLE_EQ(param("update_min_distance"), 0.3);     // linearUpdate
  EXPECT_DOUBLE_EQ(param("update_min_angle"), 0.436);      // angularUpdate
  EXPECT_DOUBLE_EQ(param("matcher_linear_step"), 0.05);    // lstep
  EXPECT_DOUBLE_EQ(param("matcher_angular_step"), 0.05);   // astep
  EXPECT_DOUBLE_EQ(param("matcher_refinements"), 5);       // iterations
  EXPECT_DOUBLE_EQ(param("weight_beam_stride"), 1);        // lskip 0: every beam
  EXPECT_NEAR(param("alpha_trans_trans"), 0.0001, 1e-12);  // srr 0.01 squared
  EXPECT_NEAR(param("alpha_rot_trans"), 0.0002, 1e-12);    // srt 0.02 squared, halved
  EXPECT_NEAR(param("alpha_trans_rot"), 0.0001, 1e-12);    // str 0.01 squared
  EXPECT_NEAR(param("alpha_rot_rot"), 0.0004, 1e-12);      // stt 0.02 squared
  EXPECT_DOUBLE_EQ(param("map_update_interval"), 0.5);     // the same name
}

TEST(SlamGmapping, TheNodeMapsWithGmappingsParticlesAndCellSize) {
  ros::NodeHandle nh;
  std::mutex mutex;
  size_t poses = 0;
  nav_msgs::OccupancyGrid::ConstPtr map;
  auto particles = nh.subscribe<geometry_msgs::PoseArray>(
      "/slam_gmapping/particles", 10, [&](const geometry_msgs::PoseArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        poses = m->poses.size();
      });
  auto map_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map", 2, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        map = m;
      });
  for (int i = 0; i < 12; ++i) robot->step(100.0 + 0.5 * i);
  // The clock moves on (0.5 s map interval) without scans until the map is out.
  for (int i = 0; i < 20 && !testing_ros::waitUntil(
                                mutex, [&] { return map && poses > 0; }, 0.5);
       ++i) {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(106.0 + i);
    robot->clock.publish(c);
  }
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(poses, 8u);  // particles
  ASSERT_TRUE(map);
  EXPECT_FLOAT_EQ(map->info.resolution, 0.1f);  // delta
  const long occupied = std::count(map->data.begin(), map->data.end(), 100);
  EXPECT_GT(occupied, 30) << "the room's walls";
}

TEST(SlamGmapping, ReadParamsReportsWhatItDidWithGmappingsNames) {
  ros::NodeHandle nh("/gmapping_names");
  nh.setParam("maxUrange", 6.0);
  nh.setParam("usable_range", 12.0);  // ours wins
  nh.setParam("linearUpdate", -1.0);  // out of our range: refused, the default stays
  nh.setParam("lskip", 2);
  nh.setParam("minimumScore", 50.0);  // no counterpart
  nh.setParam("tf_delay", 0.2);
  nh.setParam("maxUrang", 3.0);  // a typo: unknown
  ros_adapter::NodeParams params;
  std::string why;
  std::vector<std::string> unknown;
  ros_adapter::GmappingReport report;
  ASSERT_TRUE(ros_adapter::readParams(nh, &params, &why, &unknown, &report)) << why;
  EXPECT_DOUBLE_EQ(params.slam.sensor.usable_range, 12.0);
  EXPECT_DOUBLE_EQ(params.slam.update_min_distance,
                   ros_adapter::NodeParams().slam.update_min_distance);
  EXPECT_EQ(params.slam.sensor.weight_beam_stride, 3);
  EXPECT_DOUBLE_EQ(params.transform_tolerance, 0.2);
  EXPECT_EQ(report.shadowed, (std::vector<std::string>{"maxUrange (usable_range is given)"}));
  EXPECT_EQ(report.ignored, (std::vector<std::string>{"minimumScore"}));
  ASSERT_EQ(report.refused.size(), 1u);
  EXPECT_NE(report.refused[0].find("linearUpdate"), std::string::npos) << report.refused[0];
  EXPECT_NE(report.refused[0].find("update_min_distance"), std::string::npos) << report.refused[0];
  EXPECT_EQ(report.used, (std::vector<std::string>{"lskip -> weight_beam_stride = 3",
                                                   "tf_delay -> transform_tolerance = 0.2"}));
  EXPECT_EQ(unknown, (std::vector<std::string>{"maxUrang"}));
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  return evidential_slam::testing_ros::runRobotTests(argc, argv, "slam_gmapping_test",
                                                     &evidential_slam::robot);
}
