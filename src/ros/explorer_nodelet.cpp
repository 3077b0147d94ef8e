#include "evidential_slam/ros/explorer_nodelet.h"

#include <exception>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <pluginlib/class_list_macros.hpp>
#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include "evidential_slam/SaveMap.h"
#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/ros/exploration_conversions.h"

namespace evidential_slam {
namespace ros_adapter {

ExplorerNodelet::ExplorerNodelet() = default;

ExplorerNodelet::~ExplorerNodelet() {
  timer_.stop();
  grid_sub_.shutdown();
}

void ExplorerNodelet::onInit() {
  ros::NodeHandle nh = getNodeHandle();
  ros::NodeHandle pnh = getPrivateNodeHandle();
  std::string why;
  const ParameterLookup lookup = [&pnh](const std::string& name, XmlRpc::XmlRpcValue* value) {
    return pnh.getParam(name, *value);
  };
  if (!readExplorerParams(lookup, &params_, &why) || !params_.isValid(&why)) {
    NODELET_FATAL("explorer: invalid parameters: %s; exploration does not start", why.c_str());
    return;
  }
  std::vector<std::string> names, mine;
  const std::string prefix = pnh.getNamespace() + "/";
  if (ros::param::getParamNames(names)) {
    for (const std::string& n : names) {
      if (n.compare(0, prefix.size(), prefix) == 0) mine.push_back(n.substr(prefix.size()));
    }
  }
  for (const std::string& name : unknownExplorerParams(mine)) {
    NODELET_WARN("explorer: '%s' is not a parameter of the explorer (ignored)", name.c_str());
  }
  explorer_ = std::make_unique<exploration::Explorer>(params_.explorer);

  cmd_pub_ = nh.advertise<geometry_msgs::Twist>("cmd_vel", 1);
  goal_pub_ = pnh.advertise<geometry_msgs::PoseStamped>("goal", 1, true);
  path_pub_ = pnh.advertise<nav_msgs::Path>("path", 1, true);
  frontiers_pub_ = pnh.advertise<visualization_msgs::MarkerArray>("frontiers", 1, true);
  exploration_map_pub_ = pnh.advertise<nav_msgs::OccupancyGrid>("exploration_map", 1, true);
  done_pub_ = pnh.advertise<std_msgs::String>("done", 1, true);
  saved_pub_ = pnh.advertise<std_msgs::String>("map_saved", 1, true);

  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh);
  // The grid is converted on the multi-threaded queue: a large map does not hold up cmd_vel.
  grid_sub_ = getMTNodeHandle().subscribe<EvidentialGrid>(
      "grid", 1, [this](const EvidentialGrid::ConstPtr& msg) { onGrid(msg); });
  timer_ = nh.createTimer(ros::Duration(1.0 / params_.control_frequency),
                          &ExplorerNodelet::onTimer, this);
  NODELET_INFO("explorer: strategy %s, goals every %.2f s, cmd_vel at %.1f Hz; map from %s, pose "
               "%s -> %s",
               params_.explorer.frontiers.strategy.c_str(),
               1.0 / params_.explorer.planner_frequency, params_.control_frequency,
               nh.resolveName("grid").c_str(), params_.map_frame.c_str(),
               params_.base_frame.c_str());
}

void ExplorerNodelet::onGrid(const EvidentialGrid::ConstPtr& msg) {
  auto raster = std::make_shared<LayerRaster>();
  std::string why;
  if (!layerRasterFromMsg(*msg, raster.get(), &why)) {
    NODELET_WARN_THROTTLE(5.0, "explorer: grid ignored: %s", why.c_str());
    return;
  }
  if (msg->header.frame_id != params_.map_frame) {
    NODELET_WARN_THROTTLE(5.0, "explorer: grid ignored: its frame is '%s', not map_frame '%s'",
                          msg->header.frame_id.c_str(), params_.map_frame.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(map_mutex_);
  new_map_ = std::move(raster);
}

void ExplorerNodelet::stopRobot() { cmd_pub_.publish(geometry_msgs::Twist()); }

void ExplorerNodelet::onTimer(const ros::TimerEvent&) {
  if (finished_) return;
  const ros::Time now = ros::Time::now();
  geometry_msgs::TransformStamped t;
  try {
    t = tf_buffer_->lookupTransform(params_.map_frame, params_.base_frame, ros::Time(0));
  } catch (const tf2::TransformException& e) {
    NODELET_WARN_THROTTLE(5.0, "explorer: no pose yet (%s)", e.what());
    stopRobot();
    return;
  }
  if ((now - t.header.stamp).toSec() > params_.transform_timeout) {
    NODELET_WARN_THROTTLE(5.0, "explorer: the pose is %.2f s old (transform_timeout %.2f s): "
                          "stopped", (now - t.header.stamp).toSec(), params_.transform_timeout);
    stopRobot();
    return;
  }
  std::shared_ptr<const LayerRaster> fresh;
  {
    std::lock_guard<std::mutex> lock(map_mutex_);
    fresh = std::move(new_map_);
    new_map_.reset();
  }
  if (fresh) map_ = fresh;
  if (!map_) return;
  if (start_time_ < 0.0) start_time_ = now.toSec();
  if (params_.max_time > 0.0 && now.toSec() - start_time_ >= params_.max_time) {
    finish("max_time reached");
    return;
  }
  exploration::VelocityCommand cmd;
  try {
    cmd = explorer_->update(now.toSec(), pose2FromTransform(t.transform), fresh);
  } catch (const std::exception& e) {
    // A planner that throws (out of memory on a huge map, a bug) must not leave the robot
    // driving on its last command.
    NODELET_ERROR("explorer: the planner failed: %s", e.what());
    finish(std::string("planner failed: ") + e.what());
    return;
  }
  if (!explorer_->fault().empty()) {
    NODELET_WARN_THROTTLE(5.0, "explorer: stopped: %s", explorer_->fault().c_str());
  }
  // Goals given up on (no path, no progress): said once in a while, with the count.
  const std::vector<exploration::BlacklistEntry>& blacklist = explorer_->blacklist();
  for (; blacklist_seen_ < blacklist.size(); ++blacklist_seen_) {
    const exploration::BlacklistEntry& b = blacklist[blacklist_seen_];
    if (b.why == "reached") continue;
    NODELET_WARN_THROTTLE(5.0, "explorer: goal (%.2f, %.2f) blacklisted: %s (%lu given up so far)",
                          b.position.x(), b.position.y(), b.why.c_str(),
                          static_cast<unsigned long>(explorer_->stats().goals_no_path +
                                                     explorer_->stats().goals_no_progress));
  }
  geometry_msgs::Twist twist;
  twist.linear.x = cmd.linear;
  twist.angular.z = cmd.angular;
  cmd_pub_.publish(twist);
  if (explorer_->stats().replans != replans_seen_) {
    replans_seen_ = explorer_->stats().replans;
    publishPlan(now);
  }
  if (explorer_->done()) finish(explorer_->stopMessage());
}

void ExplorerNodelet::publishPlan(const ros::Time& stamp) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = params_.map_frame;
  nav_msgs::Path path;
  toPathMsg(explorer_->path(), header, &path);
  path_pub_.publish(path);
  const std::vector<exploration::Frontier>& frontiers = explorer_->frontiers();
  int chosen = -1;
  if (explorer_->hasGoal()) {
    geometry_msgs::PoseStamped goal;
    goal.header = header;
    const Eigen::Vector2d g = explorer_->goal().goal;
    goal.pose = toPoseMsg(Pose2(g.x(), g.y(), 0.0));
    goal_pub_.publish(goal);
    for (size_t k = 0; k < frontiers.size() && chosen < 0; ++k) {
      if (frontiers[k].goal_cell == explorer_->goal().goal_cell) chosen = static_cast<int>(k);
    }
  }
  const exploration::GridGeometry geometry = exploration::GridGeometry::of(*map_);
  if (frontiers_pub_.getNumSubscribers() > 0) {
    visualization_msgs::MarkerArray markers;
    toFrontierMarkers(frontiers, chosen, geometry, header, &markers);
    frontiers_pub_.publish(markers);
  }
  if (exploration_map_pub_.getNumSubscribers() > 0) {
    nav_msgs::OccupancyGrid trinary;
    toTrinaryGrid(*map_, exploration::classifyCells(*map_, params_.explorer.cells), header,
                  &trinary);
    exploration_map_pub_.publish(trinary);
  }
}

void ExplorerNodelet::finish(const std::string& reason) {
  finished_ = true;
  timer_.stop();
  stopRobot();
  const double elapsed = start_time_ < 0.0 ? 0.0 : ros::Time::now().toSec() - start_time_;
  const exploration::ExplorerStats& s = explorer_->stats();
  NODELET_INFO("explorer: %s after %.1f s (%lu goals chosen, %lu reached, %lu without a path, "
               "%lu without progress)",
               reason.c_str(), elapsed, static_cast<unsigned long>(s.goals_chosen),
               static_cast<unsigned long>(s.goals_reached),
               static_cast<unsigned long>(s.goals_no_path),
               static_cast<unsigned long>(s.goals_no_progress));
  std_msgs::String done;
  done.data = reason;
  done_pub_.publish(done);
  if (!params_.save_map_directory.empty()) saveMap();
}

void ExplorerNodelet::saveMap() {
  ros::NodeHandle nh = getNodeHandle();
  const std::string service = nh.resolveName("save_map");
  SaveMap call;
  call.request.directory = params_.save_map_directory;
  std::string answer;
  if (!ros::service::waitForService(service, ros::Duration(10.0))) {
    answer = "save_map failed: no service " + service;
  } else if (!ros::service::call(service, call)) {
    answer = "save_map failed: the call to " + service + " did not go through";
  } else if (!call.response.success) {
    answer = "save_map failed: " + call.response.message;
  } else {
    answer = call.response.message;
  }
  if (answer.rfind("save_map failed", 0) == 0) {
    NODELET_ERROR("explorer: %s", answer.c_str());
  } else {
    NODELET_INFO("explorer: %s", answer.c_str());
  }
  std_msgs::String saved;
  saved.data = answer;
  saved_pub_.publish(saved);
}

}  // namespace ros_adapter
}  // namespace evidential_slam

PLUGINLIB_EXPORT_CLASS(evidential_slam::ros_adapter::ExplorerNodelet, nodelet::Nodelet)
