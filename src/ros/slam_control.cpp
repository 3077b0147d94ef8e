#include "evidential_slam/ros/slam_control.h"

#include <utility>

#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/session/map_files.h"

namespace evidential_slam {
namespace ros_adapter {

SlamControl::SlamControl(std::string name, ros::NodeHandle& private_nh, GuardedParams& params,
                         SlamWorker& worker, SlamOutputs& outputs, tf2_ros::Buffer& tf_buffer)
    : name_(std::move(name)),
      private_nh_(private_nh),
      params_(params),
      worker_(worker),
      outputs_(outputs),
      tf_buffer_(tf_buffer),
      localization_mode_(params.read([](const NodeParams& p) { return p.mode; }) ==
                         "localization") {}

bool SlamControl::startFromParameters(std::string* why) {
  const NodeParams params = params_.get();
  // amcl's names; any of the three set on the parameter server counts as given.
  const bool pose_given = private_nh_.hasParam("initial_pose_x") ||
                          private_nh_.hasParam("initial_pose_y") ||
                          private_nh_.hasParam("initial_pose_a");
  const Pose2 initial_pose(params.initial_pose_x, params.initial_pose_y, params.initial_pose_a);
  if (params.map_file.empty() && !localization_mode_) {
    if (!pose_given) return true;
    if (startOnMap(EvidentialGridMap(params.slam.resolution), initial_pose, nullptr, why)) {
      return true;
    }
    *why = "initial_pose_*: " + *why;
    return false;
  }
  LoadedMap loaded;
  if (!loadMapFile(params.map_file, &loaded, why)) {
    *why = "map_file: " + *why;
    return false;
  }
  const Pose2 start = pose_given ? initial_pose : loaded.info.robot_pose;
  const bool started = localization_mode_ ? localizeOn(loaded.map, startAt(start), why)
                                          : startOnMap(loaded.map, start, nullptr, why);
  if (!started) {
    *why = "map_file: " + *why;
    return false;
  }
  ROS_INFO_NAMED(name_, "evidential_slam: %s on %s (%zu tiles) %s (%.3f, %.3f, %.3f), %s",
                 localization_mode_ ? "localizing" : "continuing", loaded.path.c_str(),
                 loaded.map.allocatedTiles(), localization_mode_ ? "from" : "at", start.x, start.y,
                 start.theta, pose_given ? "initial_pose_*" : "the pose saved in the file");
  return true;
}

bool SlamControl::currentOdometry(Pose2* odometry) const {
  const auto [odom_frame, base_frame] =
      params_.read([](const NodeParams& p) { return std::make_pair(p.odom_frame, p.base_frame); });
  try {
    *odometry = pose2FromTransform(
        tf_buffer_.lookupTransform(odom_frame, base_frame, ros::Time(0)).transform);
    return true;
  } catch (const tf2::TransformException&) {
    return false;
  }
}

bool SlamControl::startOnMap(const EvidentialGridMap& map, const Pose2& pose, const Pose2* odometry,
                             std::string* why) {
  bool ok = false;
  double resolution = 0.0;
  worker_.changeOnWorker(
      [&](MappingSession& session) {
        ok = session.startFromMap(map, pose, why, odometry);
        resolution = session.parameters().slam.resolution;
      },
      true);
  if (!ok) return false;
  params_.change([resolution](NodeParams& p) { p.slam.resolution = resolution; });
  if (odometry != nullptr) {
    outputs_.setMapToOdom(pose.compose(odometry->inverse()));
  } else {
    outputs_.forgetMapToOdom();
  }
  if (MapPublisher* publisher = map_publisher_) publisher->requestUpdate();
  return true;
}

void SlamControl::onInitialPose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg) {
  const std::string map_frame = params_.read([](const NodeParams& p) { return p.map_frame; });
  // rviz sends it in its fixed frame: anything but the map frame is brought into it through tf.
  Pose2 pose = pose2FromPoseMsg(msg->pose.pose);
  const std::string& frame = msg->header.frame_id;
  if (!frame.empty() && frame != map_frame) {
    try {
      const Pose2 frame_in_map =
          pose2FromTransform(tf_buffer_.lookupTransform(map_frame, frame, ros::Time(0)).transform);
      pose = frame_in_map.compose(pose);
    } catch (const tf2::TransformException& e) {
      ROS_WARN_NAMED(name_, "initialpose in frame '%s' ignored: no transform to '%s' (%s)",
                     frame.c_str(), map_frame.c_str(), e.what());
      return;
    }
  }
  std::string why;
  if (localization_mode_) {
    // amcl's use: the particles are drawn from the message's covariance (x, y, yaw entries).
    LocalizationStart start;
    start.pose = pose;
    const int index[3] = {0, 1, 5};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        start.covariance(r, c) = msg->pose.covariance[index[r] * 6 + index[c]];
      }
    }
    if (!restartLocalization(start, &why)) {
      ROS_WARN_NAMED(name_, "initialpose (%.3f, %.3f, %.3f) ignored: %s", pose.x, pose.y,
                     pose.theta, why.c_str());
      return;
    }
    ROS_INFO_NAMED(name_, "initialpose: the particles start again around (%.3f, %.3f, %.3f)",
                   pose.x, pose.y, pose.theta);
    return;
  }
  Pose2 odometry;
  const bool have_odometry = currentOdometry(&odometry);
  EvidentialGridMap map;
  worker_.runOnWorker([&](const MappingSession& session) { map = session.currentMap(); });
  if (!startOnMap(map, pose, have_odometry ? &odometry : nullptr, &why)) {
    ROS_WARN_NAMED(name_, "initialpose (%.3f, %.3f, %.3f) ignored: %s", pose.x, pose.y, pose.theta,
                   why.c_str());
    return;
  }
  ROS_INFO_NAMED(name_,
                 "initialpose: the SLAM starts over on its current map (%zu tiles) at (%.3f, "
                 "%.3f, %.3f)",
                 map.allocatedTiles(), pose.x, pose.y, pose.theta);
}

LocalizationStart SlamControl::startAt(const Pose2& pose) const {
  LocalizationStart start;
  start.pose = pose;
  params_.read([&start](const NodeParams& p) {
    const LocalizationConfig& c = p.localization;
    start.covariance.diagonal() << c.initial_cov_xx, c.initial_cov_yy, c.initial_cov_aa;
  });
  return start;
}

bool SlamControl::localizeOn(const EvidentialGridMap& map, const LocalizationStart& start,
                             std::string* why) {
  bool ok = false;
  worker_.changeOnWorker(
      [&](MappingSession& session) { ok = session.startLocalization(map, start, why); }, true);
  if (!ok) return false;
  outputs_.forgetMapToOdom();  // known at the next scan
  if (MapPublisher* publisher = map_publisher_) publisher->requestUpdate();
  return true;
}

bool SlamControl::restartLocalization(const LocalizationStart& start, std::string* why) {
  bool ok = false;
  worker_.changeOnWorker(
      [&](MappingSession& session) {
        ok = session.restartLocalization(start, why);
        // The new cloud at once (rviz; amcl publishes it at the next update).
        if (ok) outputs_.publishEstimate(session, ros::Time::now());
      },
      false);
  return ok;
}

}  // namespace ros_adapter
}  // namespace evidential_slam
