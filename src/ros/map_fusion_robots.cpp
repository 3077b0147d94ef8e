// The map fusion nodelet's robots: finding their maps on the master, subscribing, receiving.
#include <ros/master.h>

#include "evidential_slam/core/fusion/layer_map.h"
#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/ros/map_fusion_nodelet.h"

namespace evidential_slam {
namespace ros_adapter {
void MapFusionNodelet::discover() {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return;
  const std::string own_grid = private_nh_.resolveName("grid");
  for (const ros::master::TopicInfo& t : topics) {
    if (t.datatype != "evidential_slam/EvidentialGrid" || t.name == own_grid) continue;
    if (t.name.find(params_.robot_namespace) == std::string::npos) continue;
    // <robot>/<robot_map_topic>: the robot is what precedes the suffix.
    const std::string suffix = "/" + params_.robot_map_topic;
    if (t.name.size() <= suffix.size() ||
        t.name.compare(t.name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    const std::string robot = t.name.substr(0, t.name.size() - suffix.size());
    {
      std::unique_lock<std::mutex> lock(mutex_);
      auto known = robots_.find(robot);
      if (known != robots_.end()) {
        // No map yet from a publisher the master lists: its latched map may have been lost on the
        // way (seen on a busy machine: a subscription that never delivers); subscribing again
        // gets it (map_wait.h).
        Robot& r = known->second;
        const double now = ros::WallTime::now().toSec();
        const bool stalled = r.map_wait.resubscribeDue(now, r.map != nullptr);
        const double waited = r.map_wait.waitedSince(now);
        const int publishers = stalled ? static_cast<int>(r.sub.getNumPublishers()) : 0;
        lock.unlock();
        if (stalled) {
          NODELET_WARN(
              "map_fusion: robot %s: no map on %s after %.0f s (%d publisher%s "
              "connected); subscribing again",
              robot.c_str(), t.name.c_str(), waited, publishers, publishers == 1 ? "" : "s");
          subscribe(robot, t.name);
        }
        continue;
      }
    }
    Pose2 pose;
    const bool has_init_pose = readInitPose(robot, &pose);
    const bool has_pose = params_.known_init_poses && has_init_pose;
    if (params_.known_init_poses && !has_pose) {
      NODELET_WARN_THROTTLE(10.0,
                            "map_fusion: no initial pose for robot %s: set %s/map_merge/"
                            "init_pose_x, _y, _z and _yaw (or known_init_poses: false)",
                            robot.c_str(), robot.c_str());
      continue;
    }
    Robot r;
    r.name = robot;
    r.has_pose = has_pose;
    r.pose = pose;
    r.has_prior = !params_.known_init_poses && has_init_pose;
    r.prior = pose;
    NODELET_INFO("map_fusion: robot %s (map %s)%s", robot.c_str(), t.name.c_str(),
                 has_pose      ? ""
                 : r.has_prior ? ", pose to be estimated near its init_pose_*"
                               : ", pose to be estimated");
    {
      std::lock_guard<std::mutex> lock(mutex_);
      robots_.emplace(robot, std::move(r));
    }
    // Subscribed once the robot is known: its latched map may arrive at once, on a worker thread
    // while discover() still runs in onInit, and onGrid drops a map of an unknown robot.
    subscribe(robot, t.name);
  }
}

void MapFusionNodelet::subscribe(const std::string& robot, const std::string& topic) {
  // The old subscription goes first: a second subscriber of a topic would share its connections.
  ros::Subscriber old;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    old = std::move(robots_.at(robot).sub);
  }
  old.shutdown();  // outside the lock onGrid takes
  ros::Subscriber sub = nh_.subscribe<EvidentialGrid>(
      topic, 1, [this, robot](const EvidentialGrid::ConstPtr& msg) { onGrid(robot, msg); });
  std::lock_guard<std::mutex> lock(mutex_);
  robots_.at(robot).sub = std::move(sub);
  robots_.at(robot).map_wait.subscribed(ros::WallTime::now().toSec());
}

void MapFusionNodelet::onGrid(const std::string& robot, const EvidentialGrid::ConstPtr& msg) {
  LayerRaster raster;
  Pose2 frame, offset;
  std::string why;
  auto map = std::make_shared<EvidentialGridMap>();
  if (!layerRasterFromMsg(*msg, &raster, &frame, &why) ||
      !fusion::mapFromLayers(raster, map.get(), &offset, &why)) {
    NODELET_WARN_THROTTLE(5.0, "map_fusion: robot %s: map ignored: %s", robot.c_str(), why.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = robots_.find(robot);
  if (it == robots_.end()) return;
  if (it->second.map && std::abs(map->resolution() - it->second.map->resolution()) > 1e-9) {
    it->second.has_pose = it->second.has_pose && params_.known_init_poses;
  }
  it->second.map = std::move(map);
  it->second.grid_frame = frame.compose(offset);
  it->second.stamp = msg->header.stamp.toSec();
  ++it->second.version;
  ++changes_;
}

}  // namespace ros_adapter
}  // namespace evidential_slam
