#include "evidential_slam/ros/slam_outputs.h"

#include <cstdio>
#include <utility>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Path.h>
#include <std_msgs/Float64.h>
#include <tf2/buffer_core.h>

#include "evidential_slam/ros/conversions.h"

namespace evidential_slam {
namespace ros_adapter {

SlamOutputs::SlamOutputs(std::string name, ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                         GuardedParams& params)
    : name_(std::move(name)),
      params_(params),
      tf_guard_(ros::Duration(tf2::BufferCore::DEFAULT_CACHE_TIME).toNSec()) {
  pose_pub_ = private_nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 10, true);
  particles_pub_ = private_nh.advertise<geometry_msgs::PoseArray>("particles", 10);
  path_pub_ = private_nh.advertise<nav_msgs::Path>("path", 1, true);
  conflict_pub_ = private_nh.advertise<std_msgs::Float64>("conflict_added", 100);
  open_space_conflict_pub_ =
      private_nh.advertise<std_msgs::Float64>("open_space_conflict_added", 100);
  diagnostics_pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
  const double period =
      params_.read([](const NodeParams& p) { return p.transform_publish_period; });
  if (period > 0.0) {
    tf_timer_ = nh.createTimer(ros::Duration(period), &SlamOutputs::publishTransform, this);
  }
}

void SlamOutputs::setMapToOdom(const Pose2& map_to_odom) {
  std::lock_guard<std::mutex> lock(transform_mutex_);
  map_to_odom_ = map_to_odom;
  have_transform_ = true;
}

void SlamOutputs::forgetMapToOdom() {
  std::lock_guard<std::mutex> lock(transform_mutex_);
  have_transform_ = false;
}

void SlamOutputs::onScanHandled(const MappingSession& session, const SessionScanResult& result) {
  const SlamEngine& engine = session.engine();
  const bool localizing = session.localizing();
  if (localizing && !session.localizer().initialized()) return;
  const Pose2 map_to_odom = localizing ? session.localizer().mapToOdom() : engine.mapToOdom();
  setMapToOdom(map_to_odom);
  ros::Time ros_stamp;
  ros_stamp.fromSec(result.stamp);
  // The correction changes with each scan (mapping and localizing): tf gets it at the scan's own
  // stamp, so a lookup there (a consumer of that scan) does not mix in the correction from before.
  scan_stamped_ = true;
  if (tf_timer_.isValid()) sendMapToOdom(map_to_odom, ros_stamp);
  // A paused scan adds no conflict: the alarm did not see it.
  if (result.update.processed && !session.mappingPaused()) reportConflict(result, ros_stamp);

  publishEstimate(session, ros_stamp);
  if (result.processed() && path_pub_.getNumSubscribers() > 0) {
    const std::string map_frame = params_.read([](const NodeParams& p) { return p.map_frame; });
    nav_msgs::Path path;
    path.header.stamp = ros_stamp;
    path.header.frame_id = map_frame;
    for (const StampedPose& p :
         localizing ? session.localizer().trajectory() : engine.bestTrajectory()) {
      geometry_msgs::PoseStamped ps;
      ps.header.stamp.fromSec(p.stamp);
      ps.header.frame_id = map_frame;
      ps.pose = toPoseMsg(p.pose);
      path.poses.push_back(ps);
    }
    path_pub_.publish(path);
  }
}

void SlamOutputs::publishEstimate(const MappingSession& session, const ros::Time& stamp) {
  const bool localizing = session.localizing();
  const SlamEngine& engine = session.engine();
  const PoseEstimate estimate = localizing ? session.localizer().estimate() : engine.poseEstimate();
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = stamp;
  pose.header.frame_id = params_.read([](const NodeParams& p) { return p.map_frame; });
  pose.pose.pose = toPoseMsg(estimate.mean);
  // Row-major 6x6 over (x, y, z, roll, pitch, yaw); the planar entries are the particles'.
  const int index[3] = {0, 1, 5};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      pose.pose.covariance[index[r] * 6 + index[c]] = estimate.covariance(r, c);
  }
  pose_pub_.publish(pose);

  if (particles_pub_.getNumSubscribers() > 0) {
    std::vector<Pose2> poses;
    std::vector<double> weights;
    if (localizing) {
      for (const LocalizationParticle& p : session.localizer().particles()) poses.push_back(p.pose);
    } else {
      engine.particlePoses(&poses, &weights);
    }
    geometry_msgs::PoseArray array;
    array.header = pose.header;
    for (const Pose2& p : poses) array.poses.push_back(toPoseMsg(p));
    particles_pub_.publish(array);
  }
}

void SlamOutputs::reportConflict(const SessionScanResult& result, const ros::Time& stamp) {
  const ScanUpdate& update = result.update;
  const ConflictAlarmState& state = result.alarm;
  std_msgs::Float64 added;
  added.data = update.conflict_mass_added;
  conflict_pub_.publish(added);
  added.data = update.open_space_conflict_added;
  open_space_conflict_pub_.publish(added);

  char message[256];
  if (state.alarm) {
    std::snprintf(message, sizeof(message),
                  "localisation failure or environment change: the scan contradicted %.1f cells "
                  "of the map's confident evidence (recent quiet scans at most %.2f; it added "
                  "%.1f of conflict mass, %.1f bits of external conflict)",
                  state.added, state.baseline, update.conflict_mass_added,
                  update.external_conflict_added);
  } else {
    std::snprintf(message, sizeof(message), "external conflict as usual");
  }
  if (state.rising) ROS_WARN_NAMED(name_, "%s (t = %.3f)", message, stamp.toSec());

  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = stamp;
  diagnostic_msgs::DiagnosticStatus status;
  status.name = name_ + ": external conflict";
  status.hardware_id = "evidential_slam";
  status.level =
      state.alarm ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK;
  status.message = message;
  auto value = [&status](const std::string& key, double v) {
    diagnostic_msgs::KeyValue kv;
    kv.key = key;
    kv.value = std::to_string(v);
    status.values.push_back(kv);
  };
  value("conflict_mass_added", update.conflict_mass_added);
  value("open_space_conflict_added", update.open_space_conflict_added);
  value("contradiction_added", state.added);
  value("ec_added_bits", update.external_conflict_added);
  value("baseline", state.baseline);
  value("ratio", state.ratio);
  array.status.push_back(status);
  diagnostics_pub_.publish(array);
}

void SlamOutputs::publishTransform(const ros::TimerEvent&) {
  Pose2 map_to_odom;
  {
    std::lock_guard<std::mutex> lock(transform_mutex_);
    if (!have_transform_) return;
    map_to_odom = map_to_odom_;
  }
  // Post-dated like gmapping's, so consumers can transform data up to the next broadcast.
  const double tolerance = params_.read([](const NodeParams& p) { return p.transform_tolerance; });
  const ros::Time now = ros::Time::now();
  if (now < last_timer_now_) {
    // Time jumped back (a bag played again): tf listeners clear their buffers, so does the guard.
    std::lock_guard<std::mutex> lock(tf_mutex_);
    tf_guard_.clear();
  }
  last_timer_now_ = now;
  ros::Time stamp = now + ros::Duration(tolerance);
  // tf keeps the first transform at a stamp. On a simulated clock a post-dated stamp often is a
  // later scan's: 1 ns after it, the scan's own correction can still go in at the scan's stamp.
  if (scan_stamped_) stamp += ros::Duration(0, 1);
  sendMapToOdom(map_to_odom, stamp);
}

void SlamOutputs::sendMapToOdom(const Pose2& map_to_odom, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  params_.read([&t](const NodeParams& p) {
    t.header.frame_id = p.map_frame;
    t.child_frame_id = p.odom_frame;
    return 0;
  });
  t.header.stamp = stamp;
  t.transform = toTransformMsg(map_to_odom);
  std::lock_guard<std::mutex> lock(tf_mutex_);
  // A stamp tf already holds (simulated time may not have advanced since the last broadcast) or a
  // scan older than the listeners' buffer (a filter far behind a bag) would only warn there.
  if (!tf_guard_.admit(static_cast<int64_t>(stamp.toNSec()))) return;
  tf_broadcaster_.sendTransform(t);
}

}  // namespace ros_adapter
}  // namespace evidential_slam
