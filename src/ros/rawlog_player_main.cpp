// rawlog_player: plays an MRPT rawlog (GridmapNavSimul and friends) on ROS as a robot would
// publish it: sensor_msgs/LaserScan on `scan`, the odometry as tf odom -> base_link at each scan's
// stamp, the laser's mounting as a static tf, and /clock (run the rest with use_sim_time). With a
// ground-truth file (`t x y phi` lines) the true path grows on `ground_truth` (nav_msgs/Path).
// When the log ends, `~done` (latched std_msgs/Bool) turns true and the clock keeps running, so
// map timers downstream still fire.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/Bool.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/ros/conversions.h"

namespace es = evidential_slam;

namespace {

struct PlayerParams {
  std::string rawlog;
  std::string ground_truth;  // optional
  std::string laser_label;   // optional: only this sensor
  double rate = 1.0;         // playback speed factor (sim time / wall time)
  double start_delay = 1.0;  // wall s before the first scan (subscribers connect)
  // Wall s to wait, after start_delay, for subscribers on `scan` and `/tf` (a SLAM still loading
  // must not miss the first scans); 0 = do not wait.
  double wait_for_subscriber = 10.0;
  double clock_step = 0.01;  // sim s between /clock messages
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  std::string laser_frame = "laser";
  std::string ground_truth_frame = "map";
  // Express the ground truth in the SLAM's map frame: the map frame starts at the first odometry
  // pose, so the true path is moved to start there too.
  bool align_ground_truth = true;
};

bool readPlayerParams(const ros::NodeHandle& nh, PlayerParams* p, std::string* why) {
  nh.param("rawlog", p->rawlog, p->rawlog);
  nh.param("ground_truth", p->ground_truth, p->ground_truth);
  nh.param("laser_label", p->laser_label, p->laser_label);
  nh.param("rate", p->rate, p->rate);
  nh.param("start_delay", p->start_delay, p->start_delay);
  nh.param("clock_step", p->clock_step, p->clock_step);
  nh.param("wait_for_subscriber", p->wait_for_subscriber, p->wait_for_subscriber);
  nh.param("odom_frame", p->odom_frame, p->odom_frame);
  nh.param("base_frame", p->base_frame, p->base_frame);
  nh.param("laser_frame", p->laser_frame, p->laser_frame);
  nh.param("ground_truth_frame", p->ground_truth_frame, p->ground_truth_frame);
  nh.param("align_ground_truth", p->align_ground_truth, p->align_ground_truth);
  if (p->rawlog.empty())
    *why = "parameter ~rawlog (the .rawlog file to play) is not set";
  else if (!(p->rate > 0.0) || !std::isfinite(p->rate))
    *why = "~rate must be > 0";
  else if (!(p->clock_step > 0.0))
    *why = "~clock_step must be > 0";
  else if (!(p->start_delay >= 0.0))
    *why = "~start_delay must be >= 0";
  else
    return true;
  return false;
}

class RawlogPlayer {
 public:
  RawlogPlayer(ros::NodeHandle nh, ros::NodeHandle pnh, PlayerParams params)
      : params_(std::move(params)) {
    scan_pub_ = nh.advertise<sensor_msgs::LaserScan>("scan", 100);
    // The odometry tf, published here rather than through a TransformBroadcaster so that the
    // player can wait for its subscribers too.
    tf_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    truth_pub_ = nh.advertise<nav_msgs::Path>("ground_truth", 1, true);
    done_pub_ = pnh.advertise<std_msgs::Bool>("done", 1, true);
    std_msgs::Bool done;
    done.data = false;
    done_pub_.publish(done);
  }

  // Plays the whole log; returns the process exit code.
  int run() {
    std::string error;
    if (!params_.ground_truth.empty() &&
        !es::io::readGroundTruth(params_.ground_truth, &truth_, &error)) {
      ROS_FATAL("rawlog_player: %s", error.c_str());
      return 1;
    }
    es::io::RawlogReaderConfig reader_config;
    reader_config.laser_label = params_.laser_label;
    es::io::RawlogReader reader(reader_config);
    if (!reader.open(params_.rawlog, &error)) {
      ROS_FATAL("rawlog_player: %s", error.c_str());
      return 1;
    }
    ros::WallDuration(params_.start_delay).sleep();
    const ros::WallTime give_up =
        ros::WallTime::now() + ros::WallDuration(params_.wait_for_subscriber);
    while (ros::ok() && (scan_pub_.getNumSubscribers() == 0 || tf_pub_.getNumSubscribers() == 0) &&
           ros::WallTime::now() < give_up) {
      ros::WallDuration(0.05).sleep();
    }
    // A subscriber on /tf may be another node's (a test's, rviz's): give the SLAM's own /tf
    // subscription, requested with its scan subscription, a moment to connect too. A lost first
    // odometry transform would hold the first scan in the SLAM's tf filter for good.
    if (params_.wait_for_subscriber > 0.0) ros::WallDuration(1.0).sleep();

    es::io::RawlogScan item;
    uint64_t published = 0;
    while (ros::ok()) {
      const es::io::RawlogReader::Status status = reader.next(&item);
      if (status == es::io::RawlogReader::Status::kError) {
        ROS_FATAL("rawlog_player: %s: %s", params_.rawlog.c_str(), reader.message().c_str());
        return 1;
      }
      if (status != es::io::RawlogReader::Status::kScan) {
        if (status == es::io::RawlogReader::Status::kTruncated) {
          ROS_WARN("rawlog_player: %s", reader.message().c_str());
        }
        break;
      }
      if (published == 0) announce(item);
      if (!play(item)) continue;
      ++published;
    }
    for (const std::string& w : reader.warnings()) ROS_WARN("rawlog_player: %s", w.c_str());
    ROS_INFO("rawlog_player: played %lu scans of %s", static_cast<unsigned long>(published),
             params_.rawlog.c_str());
    if (!truth_path_.poses.empty()) truth_pub_.publish(truth_path_);  // latched: the whole path
    std_msgs::Bool done;
    done.data = true;
    done_pub_.publish(done);
    // The clock keeps running (at the same rate) so that timers downstream still fire.
    while (ros::ok()) advanceClockTo(clock_ + params_.clock_step);
    return 0;
  }

 private:
  void announce(const es::io::RawlogScan& first) {
    ROS_INFO(
        "rawlog_player: laser '%s': %zu rays, max range %.1f m, declared range noise %.3f m "
        "(give the SLAM laser_range_sigma:=%.3f for the same model as the offline runner)",
        first.label.c_str(), first.scan.size(), first.scan.max_range, first.scan.range_sigma,
        first.scan.range_sigma);
    static_broadcaster_.sendTransform(
        es::ros_adapter::toTransformStamped(first.scan.sensor_pose, ros::Time(first.scan.stamp),
                                            params_.base_frame, params_.laser_frame));
    clock_ = first.scan.stamp;
    publishClock();
  }

  // Sleeps in clock steps up to `stamp`, publishing /clock on the way.
  void advanceClockTo(double stamp) {
    while (ros::ok() && clock_ < stamp) {
      const double step = std::min(params_.clock_step, stamp - clock_);
      ros::WallDuration(step / params_.rate).sleep();
      clock_ += step;
      publishClock();
    }
  }

  void publishClock() {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(clock_);
    clock_pub_.publish(c);
  }

  bool play(const es::io::RawlogScan& item) {
    if (item.scan.stamp < clock_) {
      ROS_WARN_THROTTLE(5.0, "rawlog_player: scan at %.3f is older than the clock (%.3f): skipped",
                        item.scan.stamp, clock_);
      return false;
    }
    sensor_msgs::LaserScan msg;
    std::string why;
    if (!es::ros_adapter::scanToRos(item.scan, params_.laser_frame, &msg, &why)) {
      ROS_WARN_THROTTLE(5.0, "rawlog_player: scan at %.3f skipped: %s", item.scan.stamp,
                        why.c_str());
      return false;
    }
    advanceClockTo(item.scan.stamp);
    const ros::Time stamp(item.scan.stamp);
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(es::ros_adapter::toTransformStamped(
        item.odometry, stamp, params_.odom_frame, params_.base_frame));
    tf_pub_.publish(tf);
    scan_pub_.publish(msg);
    publishTruth(item.scan.stamp, item.odometry);
    return true;
  }

  void publishTruth(double stamp, const es::Pose2& odometry) {
    if (truth_.empty()) return;
    // The sample nearest to the scan (GridmapNavSimul writes one per scan, same stamps).
    auto it = std::lower_bound(truth_.begin(), truth_.end(), stamp,
                               [](const es::StampedPose& p, double t) { return p.stamp < t; });
    if (it == truth_.end() ||
        (it != truth_.begin() && stamp - (it - 1)->stamp < it->stamp - stamp)) {
      --it;
    }
    if (std::abs(it->stamp - stamp) > 0.05) return;
    if (!have_alignment_) {
      // map frame = odometry frame at the first scan: truth ⊕ first_truth⁻¹ ⊕ first_odometry.
      alignment_ = params_.align_ground_truth ? odometry.compose(it->pose.inverse()) : es::Pose2();
      have_alignment_ = true;
    }
    geometry_msgs::PoseStamped p;
    p.header.stamp = ros::Time(stamp);
    p.header.frame_id = params_.ground_truth_frame;
    p.pose = es::ros_adapter::toPoseMsg(alignment_.compose(it->pose));
    truth_path_.header = p.header;
    truth_path_.poses.push_back(p);
    if (truth_pub_.getNumSubscribers() > 0) truth_pub_.publish(truth_path_);
  }

  PlayerParams params_;
  ros::Publisher scan_pub_, clock_pub_, truth_pub_, done_pub_, tf_pub_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::vector<es::StampedPose> truth_;
  nav_msgs::Path truth_path_;
  bool have_alignment_ = false;
  es::Pose2 alignment_;
  double clock_ = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "rawlog_player");
  ros::NodeHandle nh, pnh("~");
  PlayerParams params;
  std::string why;
  if (!readPlayerParams(pnh, &params, &why)) {
    ROS_FATAL("rawlog_player: %s", why.c_str());
    return 1;
  }
  RawlogPlayer player(nh, pnh, params);
  return player.run();
}
