// rostest for parameter files in the node (slam_config.test): slam.launch config:=F loads F and
// its own arguments do not override it unless given (F sets 7 particles, the launch file passes
// no `particles`), and every file in config/ loads into a node namespace the way a launch file
// loads it (rosparam load) and reads back as valid parameters.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <geometry_msgs/PoseArray.h>
#include <ros/ros.h>

#include "evidential_slam/ros/params.h"
#include "room_robot.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;
testing_ros::Robot* robot = nullptr;

TEST(SlamConfig, ConfigFileSetsTheParticleCount) {
  int particles = 0;
  ASSERT_TRUE(ros::param::get("/evidential_slam/particles", particles));
  EXPECT_EQ(particles, 7);
  ros::NodeHandle nh;
  std::mutex mutex;
  size_t poses = 0;
  auto sub = nh.subscribe<geometry_msgs::PoseArray>(
      "/evidential_slam/particles", 10, [&](const geometry_msgs::PoseArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        poses = m->poses.size();
      });
  for (int i = 0; i < 5 && poses == 0; ++i) {
    robot->step(100.0 + i);
    testing_ros::waitUntil(mutex, [&] { return poses > 0; }, 3.0);
  }
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(poses, 7u);
}

TEST(SlamConfig, EveryShippedConfigFileReadsAsValidParameters) {
  const fs::path dir = fs::path(ES_CONFIG_DIR);
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    const std::string ns = "/config_check/" + entry.path().stem().string();
    const std::string cmd = "rosparam load '" + entry.path().string() + "' " + ns;
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    ros_adapter::NodeParams params;
    std::string why;
    std::vector<std::string> unknown;
    EXPECT_TRUE(ros_adapter::readParams(ros::NodeHandle(ns), &params, &why, &unknown))
        << entry.path() << ": " << why;
    EXPECT_TRUE(params.isValid(&why)) << entry.path() << ": " << why;
    EXPECT_TRUE(unknown.empty()) << entry.path() << ": " << unknown.front();
  }
  EXPECT_GE(files, 1);
}

// A value of the wrong type or out of range is refused with a message naming the parameter.
TEST(SlamConfig, BadValuesAreRefused) {
  ros::NodeHandle nh("/bad_values");
  nh.setParam("particles", 7.5);
  ros_adapter::NodeParams params;
  std::string why;
  EXPECT_FALSE(ros_adapter::readParams(nh, &params, &why));
  EXPECT_NE(why.find("particles"), std::string::npos) << why;
  nh.setParam("particles", 7);
  nh.setParam("usable_range", 1e9);
  EXPECT_FALSE(ros_adapter::readParams(nh, &params, &why));
  EXPECT_NE(why.find("usable_range"), std::string::npos) << why;
  nh.setParam("usable_range", 30);  // an int where a double is expected is fine
  nh.setParam("particels", 40);     // a typo is reported
  std::vector<std::string> unknown;
  ASSERT_TRUE(ros_adapter::readParams(nh, &params, &why, &unknown)) << why;
  EXPECT_EQ(params.slam.particles, 7);
  EXPECT_DOUBLE_EQ(params.slam.sensor.usable_range, 30.0);
  EXPECT_EQ(unknown, (std::vector<std::string>{"particels"}));
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  return evidential_slam::testing_ros::runRobotTests(argc, argv, "slam_config_test",
                                                     &evidential_slam::robot);
}
