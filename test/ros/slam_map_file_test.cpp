// rostest for maps that pass between the front ends (slam_map_file.test): the node starts on a
// map file the offline runner wrote (map_file, initial_pose_*), serves it on /map before any scan,
// continues the log on it; the map it saves then continues in the offline runner.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <std_msgs/Bool.h>
#include <nlohmann/json.hpp>

#include "evidential_slam/SaveMap.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/io/trajectory_io.h"
#include "evidential_slam/ros/conversions.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

struct Seen {
  std::mutex mutex;
  nav_msgs::OccupancyGrid::ConstPtr first_map;
  bool done = false;
  double last_pose_stamp = -1.0;
};
Seen* seen = nullptr;

std::string param(const std::string& name) {
  std::string value;
  ros::param::get("~" + name, value);
  return value;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Before the player's first scan, /map is the loaded file's map, trinary.
TEST(SlamMapFile, ServesTheLoadedMapAtStart) {
  ASSERT_TRUE(testing_ros::waitUntil(
      seen->mutex, [] { return seen->first_map != nullptr; }, 30.0));
  EvidentialGridMap loaded;
  io::MapFileInfo info;
  std::string error;
  ASSERT_TRUE(io::readMapFile(param("map_file"), &loaded, &info, &error)) << error;
  std_msgs::Header header;
  nav_msgs::OccupancyGrid expected;
  ros_adapter::toTrinaryOccupancyGrid(extractLayers(loaded), 0.65, 0.196, header, &expected);
  std::lock_guard<std::mutex> lock(seen->mutex);
  EXPECT_EQ(seen->first_map->header.stamp.toSec(), 0.0) << "the first map came after a scan";
  EXPECT_EQ(seen->first_map->info.width, expected.info.width);
  EXPECT_EQ(seen->first_map->info.height, expected.info.height);
  EXPECT_EQ(seen->first_map->data, expected.data);
}

// The whole log on the loaded map (its first scan at the map frame's origin), then the saved map
// continued by the offline runner from the log's first scan again.
TEST(SlamMapFile, ContinuesTheLogAndItsMapContinuesOffline) {
  ASSERT_TRUE(testing_ros::waitUntil(
      seen->mutex, [] { return seen->done; }, 150.0))
      << "the player did not finish";
  std::vector<StampedPose> truth;
  std::string error;
  ASSERT_TRUE(io::readGroundTruth(param("ground_truth"), &truth, &error)) << error;
  const double last_stamp = truth.back().stamp;
  ASSERT_TRUE(testing_ros::waitUntil(
      seen->mutex, [&] { return std::abs(seen->last_pose_stamp - last_stamp) < 1e-3; }, 60.0));

  const fs::path dir = fs::path(param("output_dir")) / "node";
  fs::remove_all(dir);
  SaveMap save;
  save.request.directory = dir.string();
  ASSERT_TRUE(ros::service::call("/evidential_slam/save_map", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  std::vector<StampedPose> path;
  ASSERT_TRUE(io::readTumTrajectory((dir / "trajectory.tum").string(), &path, &error)) << error;
  EXPECT_EQ(path.size(), truth.size());
  AteResult ate;
  ASSERT_TRUE(computeAte(path, truth, 0.05, &ate, &error)) << error;
  EXPECT_LT(ate.rmse, 0.15);
  RecordProperty("node_ate_m", std::to_string(ate.rmse));
  EvidentialGridMap node_map;
  io::MapFileInfo info;
  ASSERT_TRUE(io::readMapFile((dir / "map.evmap").string(), &node_map, &info, &error)) << error;

  const fs::path out = fs::path(param("output_dir")) / "offline";
  fs::remove_all(out);
  const std::string cmd = quote(ES_OFFLINE_BIN) + " --rawlog " + quote(param("rawlog")) +
                          " --ground-truth " + quote(param("ground_truth")) + " --out " +
                          quote(out.string()) + " --load-map " + quote(dir.string()) +
                          " --initial-pose 0,0,0 --max-scans 60 --preset sim --particles 20" +
                          " --seed 3 --threads 2 --quiet > /dev/null 2>&1 < /dev/null";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["start"]["map_tiles"].get<size_t>(), node_map.allocatedTiles());
  EXPECT_LT(summary["ate_rmse_m"].get<double>(), 0.15);
  RecordProperty("offline_ate_m", std::to_string(summary["ate_rmse_m"].get<double>()));
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "slam_map_file_test");
  ros::NodeHandle nh;
  evidential_slam::Seen seen;
  evidential_slam::seen = &seen;
  auto map = evidential_slam::testing_ros::subscribeLocked<nav_msgs::OccupancyGrid>(
      nh, "/map", 1, seen.mutex, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        if (!seen.first_map) seen.first_map = m;
      });
  auto done = evidential_slam::testing_ros::subscribeLocked<std_msgs::Bool>(
      nh, "/rawlog_player/done", 1, seen.mutex, [&](const auto& m) { seen.done = m->data; });
  auto pose =
      evidential_slam::testing_ros::subscribeLocked<geometry_msgs::PoseWithCovarianceStamped>(
          nh, "/evidential_slam/pose", 10, seen.mutex,
          [&](const auto& m) { seen.last_pose_stamp = m->header.stamp.toSec(); });
  return evidential_slam::testing_ros::runAllTestsSpinning();
}
