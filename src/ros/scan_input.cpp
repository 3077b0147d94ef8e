#include "evidential_slam/ros/scan_input.h"

#include <cstdio>
#include <utility>

#include <geometry_msgs/TransformStamped.h>

#include "evidential_slam/ros/conversions.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

constexpr uint32_t kTfFilterQueue = 50;  // scans waiting for their odometry tf, at most

const char* failureName(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "the scan is older than the tf buffer";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "the scan has no frame_id";
    default:
      return "no transform arrived while the scan waited";
  }
}

}  // namespace

ScanInput::ScanInput(std::string name, GuardedParams& params, tf2_ros::Buffer& tf_buffer,
                     SlamWorker& worker)
    : name_(std::move(name)), params_(params), tf_buffer_(tf_buffer), worker_(worker) {}

ScanInput::~ScanInput() {
  scan_filter_.reset();
  scan_sub_.reset();
  watchdog_.stop();
}

void ScanInput::start(ros::NodeHandle& nh) {
  const std::string odom_frame = params_.read([](const NodeParams& p) { return p.odom_frame; });
  scan_sub_ =
      std::make_unique<message_filters::Subscriber<sensor_msgs::LaserScan>>(nh, "scan", 100);
  scan_filter_ = std::make_unique<tf2_ros::MessageFilter<sensor_msgs::LaserScan>>(
      *scan_sub_, tf_buffer_, odom_frame, kTfFilterQueue, nh);
  scan_filter_->registerCallback(&ScanInput::onScan, this);
  scan_sub_->registerCallback(&ScanInput::onRawScan, this);
  watchdog_ = nh.createWallTimer(ros::WallDuration(1.0), &ScanInput::checkWaitingScans, this);
  scan_filter_->registerFailureCallback(
      [this](const sensor_msgs::LaserScan::ConstPtr& msg,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onScanWithoutTransform(msg, reason);
      });
}

ScanInput::Counters ScanInput::counters() const {
  Counters c;
  c.received = received_;
  c.malformed = malformed_;
  c.without_tf = without_tf_;
  return c;
}

void ScanInput::clearTransforms() {
  std::lock_guard<std::mutex> lock(mutex_);
  tf_buffer_.clear();  // static transforms stay (tf2's static cache ignores clear)
  scan_stamps_.reset();
}

void ScanInput::onScanWithoutTransform(
    const sensor_msgs::LaserScan::ConstPtr& msg,
    tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    in_filter_.erase(msg);
  }
  const std::string odom_frame = params_.read([](const NodeParams& p) { return p.odom_frame; });
  std::string tf_error;
  tf_buffer_.canTransform(odom_frame, msg->header.frame_id, msg->header.stamp, &tf_error);
  ++without_tf_;
  ROS_WARN_THROTTLE_NAMED(
      5.0, name_, "scan dropped: no transform from '%s' to '%s' at t = %.3f (%s)%s%s",
      msg->header.frame_id.c_str(), odom_frame.c_str(), msg->header.stamp.toSec(),
      failureName(reason), tf_error.empty() ? "" : ": ", tf_error.c_str());
}

void ScanInput::onRawScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
  ++received_;
  std::lock_guard<std::mutex> lock(mutex_);
  // ROS time going back is a real restart (a looping bag's /clock), not a stamp outlier.
  const ros::Time now = ros::Time::now();
  const SessionConfig session_params = params_.read([](const NodeParams& p) { return p.session; });
  const double tolerance = session_params.time_jump_tolerance;
  if (!last_arrival_ros_time_.isZero() && (last_arrival_ros_time_ - now).toSec() > tolerance) {
    char reason[160];
    std::snprintf(reason, sizeof(reason), "ROS time jumped back by %.3f s (%.3f -> %.3f)",
                  (last_arrival_ros_time_ - now).toSec(), last_arrival_ros_time_.toSec(),
                  now.toSec());
    worker_.requestRestart(reason);
    // tf2's listener clears its buffer at the jump, but a /tf of the previous loop still queued
    // behind /clock can land after that clear and make every new transform "too old" for
    // cache_time; clearing again at the new loop's first scan drops it.
    tf_buffer_.clear();
    scan_stamps_.reset();
  }
  // The scans' stamps jumped back (the session's policy) while ROS time did not: a burst of
  // future stamps, then normal ones. tf2's buffer holds that future and refuses every later
  // transform as too old (TF_OLD_DATA) until the clock catches up: cleared, and said.
  scan_stamps_.setPolicy(stampPolicy(session_params));
  const double previous_stamp = scan_stamps_.last();
  if (scan_stamps_.next(msg->header.stamp.toSec()) == StampOrder::Verdict::kJumpedBack) {
    tf_buffer_.clear();
    ROS_WARN_THROTTLE_NAMED(10.0, name_,
                            "scan stamps jumped back by %.3f s (%.3f -> %.3f) for %d scans in a "
                            "row: the transform buffer is cleared",
                            previous_stamp - msg->header.stamp.toSec(), previous_stamp,
                            msg->header.stamp.toSec(), session_params.time_jump_scans);
  }
  last_arrival_ros_time_ = now;
  last_raw_scan_ = msg;
  last_raw_arrival_ = ros::WallTime::now();
  in_filter_[msg] = last_raw_arrival_;
}

void ScanInput::checkWaitingScans(const ros::WallTimerEvent&) {
  sensor_msgs::LaserScan::ConstPtr waiting;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    // A scan waiting for more than 3 s while later scans went through is lost.
    for (auto it = in_filter_.begin(); it != in_filter_.end();) {
      if ((now - it->second).toSec() > 3.0 && last_passed_arrival_ > it->second) {
        ROS_WARN_THROTTLE_NAMED(5.0, name_,
                                "scan at t = %.3f lost: it still waits for its transform to the "
                                "odometry frame while later scans went through",
                                it->first->header.stamp.toSec());
        ++without_tf_;
        it = in_filter_.erase(it);
      } else {
        ++it;
      }
    }
    // Scans came in during the last two seconds, and none passed in the last second.
    if (!last_raw_scan_ || (now - last_raw_arrival_).toSec() > 2.0 ||
        (now - last_passed_arrival_).toSec() < 1.0) {
      return;
    }
    waiting = last_raw_scan_;
  }
  const std::string odom_frame = params_.read([](const NodeParams& p) { return p.odom_frame; });
  std::string tf_error;
  if (tf_buffer_.canTransform(odom_frame, waiting->header.frame_id, waiting->header.stamp,
                              &tf_error)) {
    return;
  }
  ROS_WARN_THROTTLE_NAMED(5.0, name_,
                          "scans are waiting: no transform from '%s' to '%s' at t = %.3f: %s",
                          waiting->header.frame_id.c_str(), odom_frame.c_str(),
                          waiting->header.stamp.toSec(), tf_error.c_str());
}

void ScanInput::onScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last_passed_arrival_ = ros::WallTime::now();
    in_filter_.erase(msg);
  }
  const NodeParams params = params_.get();
  geometry_msgs::TransformStamped odom_base, base_laser;
  try {
    odom_base = tf_buffer_.lookupTransform(params.odom_frame, params.base_frame, msg->header.stamp);
    base_laser =
        tf_buffer_.lookupTransform(params.base_frame, msg->header.frame_id, msg->header.stamp);
  } catch (const tf2::TransformException& e) {
    ++without_tf_;
    ROS_WARN_THROTTLE_NAMED(5.0, name_,
                            "scan dropped: transform '%s' -> '%s' -> '%s' unavailable: %s",
                            params.odom_frame.c_str(), params.base_frame.c_str(),
                            msg->header.frame_id.c_str(), e.what());
    return;
  }
  bool upside_down = false;
  const Pose2 laser_in_base = pose2FromTransform(base_laser.transform, &upside_down);
  LaserScan scan;
  std::string why;
  if (!scanFromRos(*msg, laser_in_base, upside_down, static_cast<float>(params.laser_range_sigma),
                   &scan, &why, params.session.max_scan_rays)) {
    ++malformed_;
    ROS_WARN_THROTTLE_NAMED(5.0, name_, "malformed LaserScan at t = %.3f dropped: %s",
                            msg->header.stamp.toSec(), why.c_str());
    return;
  }
  if (!worker_.push(pose2FromTransform(odom_base.transform), scan)) {
    ROS_WARN_THROTTLE_NAMED(
        5.0, name_,
        "scan dropped: %zu scans are waiting for the filter, which is slower than "
        "the laser (fewer particles or a coarser resolution would help)",
        worker_.queued());
  }
}

}  // namespace ros_adapter
}  // namespace evidential_slam
