// rostest for the SLAM nodelet and node (slam_rawlog_*.test, slam_rosbag.test): the rawlog
// player feeds the test log (test/data/sim.rawlog, 159 scans) on simulated time, or rosbag plays
// a bag recorded from the player (test/data/sim_player.bag); this node checks what comes out.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <thread>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <std_msgs/Bool.h>
#include <std_msgs/Float64.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/SaveMap.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/trajectory_io.h"
#include "ros_test_support.h"

namespace evidential_slam {
namespace {

struct Observed {
  std::mutex mutex;
  bool done = false;
  std::vector<size_t> path_sizes;
  EvidentialGrid::ConstPtr grid;
  nav_msgs::OccupancyGrid::ConstPtr map;
  geometry_msgs::PoseWithCovarianceStamped::ConstPtr pose;
  // Conflict alarm: per processed scan, ~conflict_added, ~open_space_conflict_added, a status.
  std::vector<double> conflict_added, open_space_added;
  std::vector<diagnostic_msgs::DiagnosticStatus> alarm_status;
};

Observed* observed = nullptr;
tf2_ros::Buffer* tf_buffer = nullptr;

// Waits (wall time) until `ready` holds; false on timeout.
template <typename F>
bool waitFor(F&& ready, double seconds) {
  return testing_ros::waitUntil(observed->mutex, std::forward<F>(ready), seconds);
}

std::string param(const std::string& name) {
  std::string value;
  ros::param::get("~" + name, value);
  return value;
}

// The whole log is mapped: every scan reaches the path, the grid carries ten consistent layers,
// map -> odom exists, and the trajectory saved by save_map matches the ground truth.
TEST(SlamRawlog, MapsTheLogThroughRos) {
  bool wait_for_player = true;  // false when a bag is played instead
  ros::param::get("~wait_for_player", wait_for_player);
  if (wait_for_player) {
    ASSERT_TRUE(waitFor([] { return observed->done; }, 150.0)) << "the player did not finish";
  }
  std::vector<StampedPose> truth;  // one pose per scan of the log
  std::string error;
  ASSERT_TRUE(io::readGroundTruth(param("ground_truth"), &truth, &error)) << error;
  const size_t scans = truth.size();
  const double last_stamp = truth.back().stamp;
  ASSERT_TRUE(waitFor(
      [&] {
        return observed->pose && std::abs(observed->pose->header.stamp.toSec() - last_stamp) < 1e-3;
      },
      60.0))
      << "the pose of the last scan never came";
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    // The path (published at every processed scan) grows while the log plays.
    ASSERT_GE(observed->path_sizes.size(), 3u);
    EXPECT_LT(observed->path_sizes.front(), observed->path_sizes.back());
    EXPECT_GT(observed->path_sizes.back(), scans - 10);
    for (size_t i = 1; i < observed->path_sizes.size(); ++i) {
      EXPECT_LE(observed->path_sizes[i - 1], observed->path_sizes[i]);
    }
  }
  ASSERT_TRUE(waitFor([] { return observed->grid && observed->map && observed->pose; }, 30.0))
      << "no grid, map or pose arrived";
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    const EvidentialGrid& g = *observed->grid;
    const std::vector<std::string> names = {
        "occupied",  "free",           "unknown",           "conflict",
        "pignistic", "nonspecificity", "internal_conflict", "external_conflict",
        "entropy",   "anomaly"};
    EXPECT_EQ(g.layers, names);
    ASSERT_EQ(g.data.size(), names.size());
    const size_t cells = static_cast<size_t>(g.info.width) * g.info.height;
    EXPECT_GT(cells, 1000u);
    EXPECT_NEAR(g.info.resolution, 0.05, 1e-6);
    EXPECT_EQ(g.header.frame_id, "map");
    for (const auto& layer : g.data) EXPECT_EQ(layer.data.size(), cells);
    EXPECT_EQ(g.observed.size(), cells);
    const nav_msgs::OccupancyGrid& m = *observed->map;
    EXPECT_EQ(m.data.size(), static_cast<size_t>(m.info.width) * m.info.height);
    // Trinary, as the navigation stack reads it: 100 occupied, 0 free, -1 unknown.
    size_t unknown = 0, occupied = 0, free = 0, other = 0;
    for (int8_t v : m.data) {
      unknown += v == -1;
      occupied += v == 100;
      free += v == 0;
      other += v != -1 && v != 0 && v != 100;
    }
    EXPECT_EQ(other, 0u) << "map values other than -1, 0 and 100";
    EXPECT_GT(unknown, 0u);
    EXPECT_GT(occupied, 100u);
    EXPECT_GT(free, 1000u);
  }
  EXPECT_TRUE(tf_buffer->canTransform("map", "odom", ros::Time(0), ros::Duration(5.0), &error))
      << error;

  // save_map writes the trajectory; score it like the offline runner does.
  const std::filesystem::path dir =
      std::filesystem::path(param("output_dir")) / ros::this_node::getName().substr(1);
  SaveMap save;
  save.request.directory = dir.string();
  ASSERT_TRUE(ros::service::call("/evidential_slam/save_map", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  for (const char* f :
       {"map.evmap", "layers/pignistic.pgm", "layers/pignistic.yaml",
        "layers/external_conflict.npy", "layers/composite.png", "trajectory.tum", "conflict.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  std::vector<StampedPose> trajectory;
  ASSERT_TRUE(io::readTumTrajectory((dir / "trajectory.tum").string(), &trajectory, &error))
      << error;
  EXPECT_EQ(trajectory.size(), scans);
  AteResult ate;
  ASSERT_TRUE(computeAte(trajectory, truth, 0.05, &ate, &error)) << error;
  EXPECT_EQ(ate.matched, scans);
  // The offline runner's bound for the same log and settings (test/io/offline_e2e_test.cpp).
  EXPECT_LT(ate.rmse, 0.15);
  RecordProperty("ate_rmse_m", std::to_string(ate.rmse));

  // The conflict alarm reported every processed scan (one path message each; a message may miss
  // a connection made late), the open-space part never above the total, and nothing alarmed on
  // this clean log.
  std::lock_guard<std::mutex> lock(observed->mutex);
  const double processed = static_cast<double>(observed->path_sizes.size());
  EXPECT_NEAR(static_cast<double>(observed->conflict_added.size()), processed, 2.0);
  EXPECT_NEAR(static_cast<double>(observed->open_space_added.size()), processed, 2.0);
  EXPECT_NEAR(static_cast<double>(observed->alarm_status.size()), processed, 2.0);
  double total = 0.0, open_space = 0.0;
  for (double v : observed->conflict_added) total += v;
  for (double v : observed->open_space_added) open_space += v;
  EXPECT_GT(total, 0.0);
  EXPECT_LE(open_space, total);
  for (const auto& status : observed->alarm_status) {
    EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK) << status.message;
    bool has_input = false;
    for (const auto& kv : status.values) has_input |= kv.key == "open_space_conflict_added";
    EXPECT_TRUE(has_input);
  }
}

dynamic_reconfigure::Reconfigure::Response reconfigure(
    const std::vector<std::pair<std::string, double>>& values) {
  dynamic_reconfigure::Reconfigure srv;
  for (const auto& [name, value] : values) {
    dynamic_reconfigure::DoubleParameter p;
    p.name = name;
    p.value = value;
    srv.request.config.doubles.push_back(p);
  }
  EXPECT_TRUE(ros::service::call("/evidential_slam/set_parameters", srv));
  return srv.response;
}

double valueOf(const dynamic_reconfigure::Reconfigure::Response& r, const std::string& name) {
  for (const auto& d : r.config.doubles) {
    if (d.name == name) return d.value;
  }
  ADD_FAILURE() << name << " missing from the reconfigure response";
  return -1.0;
}

// A valid change is taken (and lands on the parameter server); an inconsistent one (min_range
// above usable_range, each within its cfg range) is refused and the previous values come back.
TEST(SlamRawlog, DynamicReconfigureChangesParametersLive) {
  ASSERT_TRUE(ros::service::waitForService("/evidential_slam/set_parameters", 10000));
  EXPECT_DOUBLE_EQ(valueOf(reconfigure({{"update_min_distance", 0.2}}), "update_min_distance"),
                   0.2);
  double stored = 0.0;
  EXPECT_TRUE(ros::param::get("/evidential_slam/update_min_distance", stored));
  EXPECT_DOUBLE_EQ(stored, 0.2);
  const auto refused = reconfigure({{"usable_range", 1.0}, {"min_range", 5.0}});
  EXPECT_DOUBLE_EQ(valueOf(refused, "min_range"), 0.05);
  EXPECT_DOUBLE_EQ(valueOf(refused, "usable_range"), 20.0);
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "slam_rawlog_test");
  ros::NodeHandle nh;
  evidential_slam::Observed obs;
  evidential_slam::observed = &obs;
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  evidential_slam::tf_buffer = &buffer;
  auto done = evidential_slam::testing_ros::subscribeLocked<std_msgs::Bool>(
      nh, "/rawlog_player/done", 1, obs.mutex, [&](const auto& m) { obs.done = m->data; });
  auto path = evidential_slam::testing_ros::subscribeLocked<nav_msgs::Path>(
      nh, "/evidential_slam/path", 100, obs.mutex,
      [&](const auto& m) { obs.path_sizes.push_back(m->poses.size()); });
  auto grid = evidential_slam::testing_ros::subscribeLocked<evidential_slam::EvidentialGrid>(
      nh, "/evidential_slam/grid", 1, obs.mutex,
      [&](const evidential_slam::EvidentialGrid::ConstPtr& m) { obs.grid = m; });
  auto map = evidential_slam::testing_ros::subscribeLocked<nav_msgs::OccupancyGrid>(
      nh, "/map", 1, obs.mutex, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) { obs.map = m; });
  auto pose =
      evidential_slam::testing_ros::subscribeLocked<geometry_msgs::PoseWithCovarianceStamped>(
          nh, "/evidential_slam/pose", 10, obs.mutex,
          [&](const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) { obs.pose = m; });
  auto conflict = evidential_slam::testing_ros::subscribeLocked<std_msgs::Float64>(
      nh, "/evidential_slam/conflict_added", 1000, obs.mutex,
      [&](const std_msgs::Float64::ConstPtr& m) { obs.conflict_added.push_back(m->data); });
  auto open_space = evidential_slam::testing_ros::subscribeLocked<std_msgs::Float64>(
      nh, "/evidential_slam/open_space_conflict_added", 1000, obs.mutex,
      [&](const std_msgs::Float64::ConstPtr& m) { obs.open_space_added.push_back(m->data); });
  auto diagnostics =
      evidential_slam::testing_ros::subscribeLocked<diagnostic_msgs::DiagnosticArray>(
          nh, "/diagnostics", 1000, obs.mutex,
          [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
            for (const auto& s : m->status) {
              if (s.name.find("external conflict") != std::string::npos)
                obs.alarm_status.push_back(s);
            }
          });
  return evidential_slam::testing_ros::runAllTestsSpinning();
}
