// gridmap_simulator: io::GridmapSimulator on ROS, in the spirit of MRPT's GridmapNavSimul. It is
// the clock source (run everything with use_sim_time): /clock advances at ~rate times real time,
// and at each scan it publishes `scan` (sensor_msgs/LaserScan), the noisy odometry as tf
// odom -> base_link, the true pose as `ground_truth_pose` (PoseStamped) and the true path as
// `ground_truth` (Path), both in `map` moved so that the true start pose is the map origin (the
// SLAM's map frame starts at the first odometry pose, as with rawlog_player). The laser's mounting
// is a static tf. The robot follows ~waypoints, or `cmd_vel` (geometry_msgs/Twist) when no
// waypoint file is given. When the route ends (or ~duration passes) the latched `~done`
// (std_msgs/Bool) turns true and the clock keeps running so timers downstream still fire. The
// robot is a disc of ~robot_radius: driving into a wall stops it at contact, and each collision
// is logged and counted on the latched `~collisions` (std_msgs/UInt32).
// Parameters: every GridmapSimulatorConfig field under its own name (docs/simulator.md).
#include <algorithm>
#include <cmath>
#include <string>
#include <variant>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/Bool.h>
#include <std_msgs/UInt32.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/ros/conversions.h"

namespace es = evidential_slam;

namespace {

// The node's own parameters (the simulation's are GridmapSimulatorConfig's).
struct NodeParams {
  double rate = 1.0;                  // sim-time speed factor (sim s per wall s)
  double start_delay = 1.0;           // wall s before the first scan (subscribers connect)
  double wait_for_subscriber = 10.0;  // then wall s to wait for a subscriber on `scan`; 0 = none
  double clock_step = 0.01;           // sim s between /clock messages
  double cmd_vel_timeout = 0.5;       // sim s after which an old cmd_vel counts as a stop
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  std::string laser_frame = "laser";
  std::string map_frame = "map";  // of ground_truth and ground_truth_pose
};

// Reads every config field from ~<name> (unset ones keep their defaults) and the node's own
// parameters. False with `why` on a wrongly typed parameter or a bad value.
bool readParams(const ros::NodeHandle& pnh, es::io::GridmapSimulatorConfig* config,
                NodeParams* node, std::string* why) {
  bool centered_given = false, origin_given = false;
  for (const auto& field : es::io::gridmapSimulatorFields(config)) {
    const std::string name = field.name;
    if (!pnh.hasParam(name)) continue;
    const bool ok =
        std::visit([&](auto* value) { return pnh.getParam(name, *value); }, field.value);
    if (!ok) {
      *why = "parameter ~" + name + " has the wrong type (" + field.help + ")";
      return false;
    }
    centered_given = centered_given || name == "map_centered";
    origin_given = origin_given || name == "origin_x" || name == "origin_y";
  }
  // As on the command line: an explicit origin means the image is not centred.
  if (origin_given && !centered_given) config->map_centered = false;
  pnh.param("rate", node->rate, node->rate);
  pnh.param("start_delay", node->start_delay, node->start_delay);
  pnh.param("wait_for_subscriber", node->wait_for_subscriber, node->wait_for_subscriber);
  pnh.param("clock_step", node->clock_step, node->clock_step);
  pnh.param("cmd_vel_timeout", node->cmd_vel_timeout, node->cmd_vel_timeout);
  pnh.param("odom_frame", node->odom_frame, node->odom_frame);
  pnh.param("base_frame", node->base_frame, node->base_frame);
  pnh.param("laser_frame", node->laser_frame, node->laser_frame);
  pnh.param("map_frame", node->map_frame, node->map_frame);
  if (config->map.empty()) {
    *why = "parameter ~map (the map image or map_server .yaml) is not set";
  } else if (!(node->rate > 0.0) || !std::isfinite(node->rate)) {
    *why = "~rate must be > 0";
  } else if (!(node->clock_step > 0.0)) {
    *why = "~clock_step must be > 0";
  } else if (!(node->start_delay >= 0.0)) {
    *why = "~start_delay must be >= 0";
  } else if (!(node->cmd_vel_timeout > 0.0)) {
    *why = "~cmd_vel_timeout must be > 0";
  } else {
    return config->isValid(why);
  }
  return false;
}

class SimulatorNode {
 public:
  SimulatorNode(ros::NodeHandle nh, ros::NodeHandle pnh, const es::io::GridmapSimulatorConfig& c,
                NodeParams params)
      : params_(std::move(params)), simulator_(c) {
    scan_pub_ = nh.advertise<sensor_msgs::LaserScan>("scan", 100);
    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    truth_path_pub_ = nh.advertise<nav_msgs::Path>("ground_truth", 1, true);
    truth_pose_pub_ = nh.advertise<geometry_msgs::PoseStamped>("ground_truth_pose", 10);
    done_pub_ = pnh.advertise<std_msgs::Bool>("done", 1, true);
    collisions_pub_ = pnh.advertise<std_msgs::UInt32>("collisions", 1, true);
    if (c.waypoints.empty()) {
      cmd_vel_sub_ = nh.subscribe<geometry_msgs::Twist>(
          "cmd_vel", 10, [this](const geometry_msgs::Twist::ConstPtr& m) {
            command_ = *m;  // spinOnce() runs this on the simulation thread
            command_time_ = clock_;
            have_command_ = true;
          });
    }
    publishDone(false);
    publishCollisions(0);
  }

  // Runs until shutdown; returns the process exit code.
  int run() {
    std::string error;
    if (!simulator_.load(&error)) {
      ROS_FATAL("gridmap_simulator: %s", error.c_str());
      return 1;
    }
    const auto& c = simulator_.config();
    const Eigen::Vector4d b = simulator_.mapBounds();
    const std::string driver = c.waypoints.empty() ? "driven by cmd_vel" : "route " + c.waypoints;
    ROS_INFO(
        "gridmap_simulator: map %s (%.3f m/cell, x %.1f..%.1f m, y %.1f..%.1f m), %s; laser %d "
        "rays, range noise %.3f m (give the SLAM laser_range_sigma:=%.3f)",
        c.map.c_str(), simulator_.mapResolution(), b[0], b[2], b[1], b[3], driver.c_str(),
        c.laser_rays, c.range_noise, c.range_noise);
    clock_ = c.start_time;
    publishClock();
    static_broadcaster_.sendTransform(es::ros_adapter::toTransformStamped(
        simulator_.laserPose(), ros::Time(clock_), params_.base_frame, params_.laser_frame));
    waitForListeners();

    double next_scan = c.start_time;
    while (ros::ok()) {
      advanceClockTo(next_scan);
      if (finished_) {
        next_scan = clock_ + params_.clock_step;  // the clock keeps running
        continue;
      }
      applyCommand();
      es::io::SimulatedScan s;
      if (!simulator_.step(&s)) {
        finish();
        continue;
      }
      publish(s);
      next_scan = s.stamp + c.scan_period;
    }
    return 0;
  }

 private:
  void waitForListeners() {
    const ros::WallTime start = ros::WallTime::now();
    const ros::WallTime stop_delay = start + ros::WallDuration(params_.start_delay);
    while (ros::ok() && ros::WallTime::now() < stop_delay) idle();
    const ros::WallTime give_up =
        ros::WallTime::now() + ros::WallDuration(params_.wait_for_subscriber);
    while (ros::ok() && scan_pub_.getNumSubscribers() == 0 && ros::WallTime::now() < give_up) {
      idle();
    }
  }

  // Before the first scan: keep the clock visible to late joiners and serve callbacks.
  void idle() {
    publishClock();
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
  }

  void applyCommand() {
    if (simulator_.followsWaypoints()) return;
    const bool fresh = have_command_ && clock_ - command_time_ <= params_.cmd_vel_timeout;
    simulator_.setVelocityCommand(fresh ? command_.linear.x : 0.0,
                                  fresh ? command_.angular.z : 0.0);
  }

  // Sleeps in clock steps up to `stamp`, publishing /clock and serving callbacks on the way.
  void advanceClockTo(double stamp) {
    while (ros::ok() && clock_ < stamp - 1e-9) {
      const double step = std::min(params_.clock_step, stamp - clock_);
      ros::WallDuration(step / params_.rate).sleep();
      clock_ = std::min(clock_ + step, stamp);
      if (stamp - clock_ < 1e-9) clock_ = stamp;
      publishClock();
      ros::spinOnce();
    }
  }

  void publishClock() {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(clock_);
    clock_pub_.publish(c);
  }

  void publishDone(bool done) {
    std_msgs::Bool msg;
    msg.data = done;
    done_pub_.publish(msg);
  }

  void publishCollisions(uint64_t count) {
    std_msgs::UInt32 msg;
    msg.data = static_cast<uint32_t>(count);
    collisions_pub_.publish(msg);
  }

  void publish(const es::io::SimulatedScan& s) {
    const ros::Time stamp(s.stamp);
    sensor_msgs::LaserScan msg;
    std::string why;
    if (!es::ros_adapter::scanToRos(s.scan, params_.laser_frame, &msg, &why)) {
      ROS_ERROR_THROTTLE(5.0, "gridmap_simulator: scan at %.3f not published: %s", s.stamp,
                         why.c_str());
      return;
    }
    tf_broadcaster_.sendTransform(es::ros_adapter::toTransformStamped(
        s.odometry, stamp, params_.odom_frame, params_.base_frame));
    scan_pub_.publish(msg);
    ++scans_;
    if (s.kidnapped) ROS_WARN("gridmap_simulator: kidnap at %.2f s", s.stamp);
    if (s.collisions > collisions_) {
      collisions_ = s.collisions;
      const Eigen::Vector2d at = simulator_.lastCollisionPosition();
      ROS_WARN(
          "gridmap_simulator: collision %lu: the robot (radius %.2f m) ran into a wall at "
          "(%.2f, %.2f) in the image's frame at %.2f s",
          static_cast<unsigned long>(collisions_), simulator_.config().robot_radius, at.x(),
          at.y(), simulator_.lastCollisionTime());
      publishCollisions(collisions_);
    }

    if (scans_ == 1) {
      // The map frame is the odometry frame at the first scan: truth ⊕ first_truth⁻¹ ⊕ odometry.
      alignment_ = s.odometry.compose(s.true_pose.inverse());
    }
    geometry_msgs::PoseStamped pose;
    pose.header.stamp = stamp;
    pose.header.frame_id = params_.map_frame;
    pose.pose = es::ros_adapter::toPoseMsg(alignment_.compose(s.true_pose));
    truth_pose_pub_.publish(pose);
    truth_path_.header = pose.header;
    truth_path_.poses.push_back(pose);
    if (truth_path_pub_.getNumSubscribers() > 0) truth_path_pub_.publish(truth_path_);
  }

  void finish() {
    finished_ = true;
    truth_path_pub_.publish(truth_path_);  // latched: the whole path
    publishDone(true);
    if (simulator_.stuck()) {
      ROS_WARN("gridmap_simulator: the route ends early: a wall has held the robot for 5 s");
    }
    ROS_INFO(
        "gridmap_simulator: done after %lu scans at %.2f s, %lu collision(s) (the clock keeps "
        "running)",
        static_cast<unsigned long>(scans_), clock_, static_cast<unsigned long>(collisions_));
  }

  NodeParams params_;
  es::io::GridmapSimulator simulator_;
  ros::Publisher scan_pub_, clock_pub_, truth_path_pub_, truth_pose_pub_, done_pub_,
      collisions_pub_;
  ros::Subscriber cmd_vel_sub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  geometry_msgs::Twist command_;
  double command_time_ = 0.0;
  bool have_command_ = false;
  double clock_ = 0.0;
  bool finished_ = false;
  uint64_t scans_ = 0;
  uint64_t collisions_ = 0;
  es::Pose2 alignment_;
  nav_msgs::Path truth_path_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "gridmap_simulator");
  ros::NodeHandle nh, pnh("~");
  es::io::GridmapSimulatorConfig config;
  NodeParams params;
  std::string why;
  if (!readParams(pnh, &config, &params, &why)) {
    ROS_FATAL("gridmap_simulator: %s", why.c_str());
    return 1;
  }
  SimulatorNode node(nh, pnh, config, params);
  return node.run();
}
