// exploration_monitor: watches a simulated exploration from outside and writes what
// io/exploration_run measures offline into <out>/exploration.json. It loads the simulator's world
// with the simulator's own parameters (~simulator names its node), and takes the true path from
// `ground_truth_pose`, collisions from `<simulator>/collisions`, the map from `grid`
// (EvidentialGrid) every coverage_period s of simulated time, the end from the explorer's
// `explorer/done` and, when the explorer saves the map, waits for `explorer/map_saved`. Then it
// writes the file and, unless ~exit_when_done is false, shuts down (explore.launch marks it
// required: the launch ends with it).
#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <std_msgs/UInt32.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/config.h"
#include "evidential_slam/core/exploration/coverage.h"
#include "evidential_slam/io/exploration_run.h"
#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/ros/exploration_conversions.h"
#include "evidential_slam/ros/explorer_params.h"

namespace es = evidential_slam;

namespace {

// The simulator's config from its private parameters, as gridmap_simulator reads them.
bool readSimulatorConfig(const ros::NodeHandle& nh, es::io::GridmapSimulatorConfig* config,
                         std::string* why) {
  bool centered_given = false, origin_given = false;
  for (const auto& field : es::io::gridmapSimulatorFields(config)) {
    const std::string name = field.name;
    if (!nh.hasParam(name)) continue;
    if (!std::visit([&](auto* value) { return nh.getParam(name, *value); }, field.value)) {
      *why = nh.resolveName(name) + " has the wrong type (" + field.help + ")";
      return false;
    }
    centered_given = centered_given || name == "map_centered";
    origin_given = origin_given || name == "origin_x" || name == "origin_y";
  }
  if (origin_given && !centered_given) config->map_centered = false;
  return true;
}

class Monitor {
 public:
  bool init(std::string* why) {
    ros::NodeHandle nh, pnh("~");
    es::ros_adapter::ExplorationMonitorParams params;
    const es::ros_adapter::ParameterLookup lookup = [&pnh](const std::string& name,
                                                           XmlRpc::XmlRpcValue* value) {
      return pnh.getParam(name, *value);
    };
    if (!es::ros_adapter::readExplorationMonitorParams(lookup, &params, why) ||
        !params.isValid(why)) {
      *why = "~" + *why;
      return false;
    }
    const std::string& simulator = params.simulator;
    out_ = params.out;
    coverage_period_ = params.coverage_period;
    wait_for_map_ = params.wait_for_saved_map;
    exit_when_done_ = params.exit_when_done;
    es::io::GridmapSimulatorConfig config;
    if (!readSimulatorConfig(ros::NodeHandle(simulator), &config, why)) return false;
    config.waypoints.clear();
    sim_ = std::make_unique<es::io::GridmapSimulator>(config);
    if (!sim_->load(why)) return false;
    start_ = sim_->truePose();  // the SLAM's map frame is the robot's start pose
    reachable_ = es::exploration::reachableFreeCells(sim_->obstacles(), start_.translation());
    for (uint8_t cell : reachable_) r_.reachable_cells += cell;
    // The Θ-gap band from the SLAM's sensor model as the SLAM node reads it (~slam: its node).
    const ros::NodeHandle slam(params.slam);
    const es::SlamConfig defaults;
    const double sigma = std::max(slam.param("hit_sigma", defaults.sensor.hit_sigma),
                                  slam.param("laser_range_sigma", 0.0));
    r_.gap_band_m = es::exploration::thetaGapBand(slam.param("free_gap", defaults.sensor.free_gap),
                                                  sigma,
                                                  slam.param("resolution", defaults.resolution));
    beyond_gap_ = es::exploration::cellsBeyondBand(sim_->obstacles(), reachable_, r_.gap_band_m);
    for (uint8_t cell : beyond_gap_) r_.reachable_cells_beyond_gap += cell;
    r_.min_wall_distance_m = 1.0;
    r_.internals_measured = false;
    r_.start_pose = start_;

    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
    truth_sub_ = nh.subscribe("ground_truth_pose", 100, &Monitor::onTruth, this);
    collisions_sub_ = nh.subscribe(simulator + "/collisions", 1, &Monitor::onCollisions, this);
    grid_sub_ = nh.subscribe("grid", 1, &Monitor::onGrid, this);
    done_sub_ = nh.subscribe("explorer/done", 1, &Monitor::onDone, this);
    saved_sub_ = nh.subscribe("explorer/map_saved", 1, &Monitor::onSaved, this);
    ROS_INFO("exploration_monitor: %lu reachable free cells from the start (%.2f, %.2f); %s",
             static_cast<unsigned long>(r_.reachable_cells), start_.x, start_.y,
             out_.empty() ? "no ~out: nothing written" : ("writing " + out_).c_str());
    wall_start_ = ros::WallTime::now();
    return true;
  }

 private:
  // Simulated seconds since the first true pose (the first scan).
  double elapsed(const ros::Time& stamp) const { return (stamp - first_stamp_).toSec(); }

  void onTruth(const geometry_msgs::PoseStamped& msg) {
    // In the truth's start-centred frame, as the SLAM's map: back into the image's frame.
    const es::Pose2 in_start = es::ros_adapter::pose2FromPoseMsg(msg.pose);
    const Eigen::Vector2d p = start_.compose(in_start).translation();
    if (r_.scans == 0) {
      first_stamp_ = msg.header.stamp;
      last_position_ = p;
    }
    ++r_.scans;
    r_.distance_m += (p - last_position_).norm();
    last_position_ = p;
    last_truth_ = in_start;
    r_.sim_time_s = elapsed(msg.header.stamp);
    r_.min_wall_distance_m = std::min(
        r_.min_wall_distance_m, es::exploration::distanceToObstacle(sim_->obstacles(), p, 1.0));
  }

  void onCollisions(const std_msgs::UInt32& msg) { r_.collisions = msg.data; }

  void onGrid(const es::EvidentialGrid::ConstPtr& msg) {
    if (written_ || r_.scans == 0) return;
    auto raster = std::make_shared<es::LayerRaster>();
    std::string why;
    if (!es::ros_adapter::layerRasterFromMsg(*msg, raster.get(), &why)) {
      ROS_WARN_THROTTLE(5.0, "exploration_monitor: grid ignored: %s", why.c_str());
      return;
    }
    map_ = raster;
    if (r_.coverage.empty() || r_.sim_time_s >= next_sample_) {
      sample();
      next_sample_ = r_.sim_time_s + coverage_period_;
    }
  }

  void sample() {
    const double covered =
        es::exploration::knownFraction(sim_->obstacles(), reachable_, *map_, start_);
    const double t = r_.sim_time_s;
    r_.coverage.push_back({t, r_.distance_m, covered});
    if (r_.time_to_90_s < 0.0 && covered >= 0.90) r_.time_to_90_s = t;
    if (r_.time_to_99_s < 0.0 && covered >= 0.99) r_.time_to_99_s = t;
    r_.final_coverage = covered;
    r_.final_coverage_beyond_gap =
        es::exploration::knownFraction(sim_->obstacles(), beyond_gap_, *map_, start_);
  }

  void onDone(const std_msgs::String& msg) {
    if (stop_reason_given_) return;
    stop_reason_given_ = true;
    r_.stop_reason = msg.data;
    r_.done = msg.data != "max_time reached";
    if (map_) sample();  // the map as it is at the stop
    try {
      const auto t = tf_buffer_.lookupTransform("map", "base_link", ros::Time(0));
      const es::Pose2 slam = es::ros_adapter::pose2FromTransform(t.transform);
      r_.final_position_error_m = (slam.translation() - last_truth_.translation()).norm();
    } catch (const tf2::TransformException& e) {
      ROS_WARN("exploration_monitor: no SLAM pose at the end (%s)", e.what());
    }
    if (!wait_for_map_) finish();
  }

  void onSaved(const std_msgs::String& msg) {
    ROS_INFO("exploration_monitor: map: %s", msg.data.c_str());
    if (stop_reason_given_) finish();
  }

  void finish() {
    if (written_) return;
    written_ = true;
    r_.wall_time_s = (ros::WallTime::now() - wall_start_).toSec();
    ROS_INFO("exploration_monitor: coverage %.4f (%.4f beyond the %.3f m gap band) after %.1f m "
             "in %.1f s simulated, %lu collision(s), to 90 %%: %.0f s; %s",
             r_.final_coverage, r_.final_coverage_beyond_gap, r_.gap_band_m, r_.distance_m,
             r_.sim_time_s, static_cast<unsigned long>(r_.collisions), r_.time_to_90_s,
             r_.stop_reason.c_str());
    std::string error;
    std::error_code ec;
    if (!out_.empty()) std::filesystem::create_directories(out_, ec);
    if (!out_.empty() && !es::io::writeExplorationJson(out_ + "/exploration.json", r_, &error)) {
      ROS_ERROR("exploration_monitor: %s", error.c_str());
    }
    if (exit_when_done_) ros::shutdown();
  }

  std::unique_ptr<es::io::GridmapSimulator> sim_;
  es::Pose2 start_;
  std::vector<uint8_t> reachable_, beyond_gap_;
  std::string out_;
  double coverage_period_ = 5.0;
  bool wait_for_map_ = true;
  bool exit_when_done_ = true;
  es::io::ExplorationRunResult r_;
  std::shared_ptr<const es::LayerRaster> map_;
  ros::Time first_stamp_;
  Eigen::Vector2d last_position_ = Eigen::Vector2d::Zero();
  es::Pose2 last_truth_;
  double next_sample_ = 0.0;
  bool stop_reason_given_ = false, written_ = false;
  ros::WallTime wall_start_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Subscriber truth_sub_, collisions_sub_, grid_sub_, done_sub_, saved_sub_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "exploration_monitor");
  Monitor monitor;
  std::string why;
  if (!monitor.init(&why)) {
    ROS_FATAL("exploration_monitor: %s", why.c_str());
    return 1;
  }
  ros::spin();
  return 0;
}
