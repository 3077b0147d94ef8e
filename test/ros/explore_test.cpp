// rostest for explore.launch (explore.test): the simulator, the SLAM and the explorer explore
// test/data/sim_map.png's two rooms. This node watches the explorer's outputs and, once
// exploration_monitor has written exploration.json, checks that the explorer stopped by itself
// (latched ~done) within max_time, knows >= 95 % of the reachable free space without a
// collision, and that the map was saved beside the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <string>

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include "ros_test_support.h"

namespace evidential_slam {
namespace {

struct Observed {
  std::mutex mutex;
  std::string done, map_saved;
  size_t goals = 0, paths = 0, marker_arrays = 0, maps = 0;
  std::set<int> map_values;
};

TEST(Explore, ExploresTheTwoRoomsAndStopsByItself) {
  ros::NodeHandle nh, pnh("~");
  std::string out;
  ASSERT_TRUE(pnh.getParam("out", out)) << "~out: the launch's out directory";
  const double wait = pnh.param("wait", 600.0);
  Observed o;
  auto sub = [&](auto cb, const std::string& topic) { return nh.subscribe(topic, 10, cb); };
  boost::function<void(const std_msgs::String::ConstPtr&)> on_done =
      [&o](const std_msgs::String::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(o.mutex);
        o.done = m->data;
      };
  boost::function<void(const std_msgs::String::ConstPtr&)> on_saved =
      [&o](const std_msgs::String::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(o.mutex);
        o.map_saved = m->data;
      };
  boost::function<void(const geometry_msgs::PoseStamped::ConstPtr&)> on_goal =
      [&o](const geometry_msgs::PoseStamped::ConstPtr&) {
        std::lock_guard<std::mutex> lock(o.mutex);
        ++o.goals;
      };
  boost::function<void(const nav_msgs::Path::ConstPtr&)> on_path =
      [&o](const nav_msgs::Path::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(o.mutex);
        if (!m->poses.empty() && m->header.frame_id == "map") ++o.paths;
      };
  boost::function<void(const visualization_msgs::MarkerArray::ConstPtr&)> on_markers =
      [&o](const visualization_msgs::MarkerArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(o.mutex);
        if (m->markers.size() > 1) ++o.marker_arrays;
      };
  boost::function<void(const nav_msgs::OccupancyGrid::ConstPtr&)> on_map =
      [&o](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(o.mutex);
        ++o.maps;
        for (int8_t v : m->data) o.map_values.insert(v);
      };
  ros::Subscriber subs[] = {sub(on_done, "explorer/done"), sub(on_saved, "explorer/map_saved"),
                            sub(on_goal, "explorer/goal"), sub(on_path, "explorer/path"),
                            sub(on_markers, "explorer/frontiers"),
                            sub(on_map, "explorer/exploration_map")};
  (void)subs;

  const std::string json_path = out + "/exploration.json";
  ASSERT_TRUE(testing_ros::waitUntil(
      o.mutex, [&] { return std::filesystem::exists(json_path); }, wait))
      << "no " << json_path << " after " << wait << " s";
  {
    std::lock_guard<std::mutex> lock(o.mutex);
    EXPECT_NE(o.done, "");
    EXPECT_NE(o.done, "max_time reached");
    EXPECT_EQ(o.map_saved.rfind("save_map failed", 0), std::string::npos) << o.map_saved;
    EXPECT_GT(o.goals, 0u);
    EXPECT_GT(o.paths, 0u);
    EXPECT_GT(o.marker_arrays, 0u);
    EXPECT_GT(o.maps, 0u);
    for (int v : o.map_values) EXPECT_TRUE(v == -1 || v == 0 || v == 100) << v;
    EXPECT_EQ(o.map_values.size(), 3u);
  }
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  std::printf("explore.launch: coverage %.4f after %.1f m in %.1f s simulated, %d collision(s); "
              "%s\n",
              j["final_coverage"].get<double>(), j["distance_m"].get<double>(),
              j["sim_time_s"].get<double>(), j["collisions"].get<int>(),
              j["stop_reason"].get<std::string>().c_str());
  EXPECT_GE(j["final_coverage"].get<double>(), 0.95);
  EXPECT_EQ(j["collisions"].get<int>(), 0);
  EXPECT_TRUE(j["done"].get<bool>());
  EXPECT_FALSE(j["time_to_90_s"].is_null());
  EXPECT_GT(j["coverage"].size(), 2u);
  EXPECT_GT(j["distance_m"].get<double>(), 5.0);
  EXPECT_TRUE(std::filesystem::exists(out + "/layers/map.yaml")) << "no saved map in " << out;
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "explore_test");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int failed = RUN_ALL_TESTS();
  // A passed run leaves nothing behind; a failed one keeps its folder to look at.
  std::string out;
  if (failed == 0 && ros::NodeHandle("~").getParam("out", out) && !out.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(out, ignored);
  }
  return failed;
}
