#include "evidential_slam/ros/slam_services.h"

#include <cstdio>
#include <utility>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/session/map_files.h"

namespace evidential_slam {
namespace ros_adapter {

SlamServices::SlamServices(std::string name, ros::NodeHandle& nh, ros::NodeHandle& mt_nh,
                           ros::NodeHandle& mt_private_nh, GuardedParams& params,
                           SlamWorker& worker, SlamControl& control, SlamOutputs& outputs,
                           ScanInput& scans)
    : name_(std::move(name)),
      scan_topic_(nh.resolveName("scan")),
      params_(params),
      worker_(worker),
      control_(control),
      outputs_(outputs),
      scans_(scans) {
  save_map_srv_ = mt_private_nh.advertiseService("save_map", &SlamServices::saveMap, this);
  get_map_srv_ = mt_nh.advertiseService("dynamic_map", &SlamServices::getMap, this);
  load_map_srv_ = mt_private_nh.advertiseService("load_map", &SlamServices::loadMap, this);
  pause_srv_ = mt_private_nh.advertiseService("pause_mapping", &SlamServices::pauseMapping, this);
  reset_srv_ = mt_private_nh.advertiseService("reset", &SlamServices::resetSlam, this);
  if (control_.localizationMode()) {
    global_localization_srv_ = mt_private_nh.advertiseService(
        "global_localization", &SlamServices::globalLocalization, this);
  }
  // rviz's "2D Pose Estimate" (amcl's topic).
  initial_pose_sub_ = nh.subscribe("initialpose", 2, &SlamControl::onInitialPose, &control_);
}

bool SlamServices::saveMap(SaveMap::Request& request, SaveMap::Response& response) {
  response.success = false;
  auto fail = [this, &response](const std::string& message) {
    response.message = message;
    ROS_ERROR_NAMED(name_, "save_map: %s", message.c_str());
    return true;  // the call itself worked; `success` says the save did not
  };
  if (request.directory.empty()) return fail("no directory given");

  // Captured between two scans (a copy sharing the map's tiles), written on this thread.
  MapSave save;
  SessionConfig config;
  bool have_map = false;
  worker_.runOnWorker([&](const MappingSession& session) {
    have_map = session.localizing() || !session.engine().filter().particles().empty();
    if (!have_map) return;
    save = captureMapSave(session);
    config = session.parameters().session;
  });
  if (!have_map) return fail("no map yet: no scan has been processed and no map loaded");
  save.info.metadata["source"] = "ros:" + scan_topic_;
  save.info.metadata["node"] = name_;

  MapFilesReport report;
  std::string error;
  if (!writeMapFiles(request.directory, save, config, &report, &error)) return fail(error);
  response.files = report.files;
  response.success = true;
  response.message =
      "saved " + std::to_string(response.files.size()) + " files to " + request.directory;
  if (!report.layers_skipped.empty()) response.message += "; " + report.layers_skipped;
  ROS_INFO_NAMED(name_, "save_map: %s", response.message.c_str());
  return true;
}

bool SlamServices::getMap(nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& response) {
  const MapSnapshot snapshot = worker_.latestMap();
  if (!snapshot.grid) return false;
  std_msgs::Header header;
  header.stamp.fromSec(snapshot.stamp);
  const NodeParams params = params_.get();
  header.frame_id = params.map_frame;
  toTrinaryOccupancyGrid(extractLayers(*snapshot.grid), params.session.occupied_thresh,
                         params.session.free_thresh, header, &response.map);
  return true;
}

bool SlamServices::loadMap(LoadMap::Request& request, LoadMap::Response& response) {
  response.success = false;
  LoadedMap loaded;
  std::string why;
  const bool localizing = control_.localizationMode();
  if (request.path.empty()) {
    why = "no path given";
  } else if (loadMapFile(request.path, &loaded, &why)) {
    const Pose2 pose = request.use_pose ? Pose2(request.pose.x, request.pose.y, request.pose.theta)
                                        : loaded.info.robot_pose;
    Pose2 odometry;
    const bool have_odometry = control_.currentOdometry(&odometry);
    const bool started =
        localizing
            ? control_.localizeOn(loaded.map, control_.startAt(pose), &why)
            : control_.startOnMap(loaded.map, pose, have_odometry ? &odometry : nullptr, &why);
    if (started) {
      scans_.clearTransforms();
      char text[256];
      std::snprintf(text, sizeof(text), "%s on %s (%zu tiles, %g m cells) at (%.3f, %.3f, %.3f)%s",
                    localizing ? "localizing" : "continuing", loaded.path.c_str(),
                    loaded.map.allocatedTiles(), loaded.map.resolution(), pose.x, pose.y,
                    pose.theta, request.use_pose ? "" : " (the pose saved in the file)");
      response.success = true;
      response.message = text;
      ROS_INFO_NAMED(name_, "load_map: %s", text);
      return true;
    }
  }
  response.message = why;
  ROS_ERROR_NAMED(name_, "load_map: %s", why.c_str());
  return true;  // the call itself worked; `success` says the load did not
}

bool SlamServices::pauseMapping(std_srvs::SetBool::Request& request,
                                std_srvs::SetBool::Response& response) {
  if (control_.localizationMode()) {
    response.success = false;
    response.message = "localization mode: the map is never changed";
    return true;
  }
  const bool pause = request.data;
  worker_.changeOnWorker([pause](MappingSession& session) { session.setMappingPaused(pause); },
                         false);
  response.success = true;
  response.message =
      pause ? "mapping paused: scans localize on the map, which stays as it is" : "mapping resumed";
  ROS_INFO_NAMED(name_, "pause_mapping: %s", response.message.c_str());
  return true;
}

bool SlamServices::resetSlam(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  if (control_.localizationMode()) {
    worker_.changeOnWorker([](MappingSession& session) { session.reset(); }, true);
    scans_.clearTransforms();
    ROS_INFO_NAMED(name_, "reset: the particles start again as they did on the map");
    return true;
  }
  std::string message;
  worker_.changeOnWorker(
      [&message](MappingSession& session) {
        session.setMappingPaused(false);
        session.startOver("reset", &message);
      },
      true);
  outputs_.forgetMapToOdom();
  scans_.clearTransforms();
  ROS_INFO_NAMED(name_, "%s", message.c_str());
  return true;
}

bool SlamServices::globalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  LocalizationStart start;
  start.global = true;
  std::string why;
  if (!control_.restartLocalization(start, &why)) {
    ROS_ERROR_NAMED(name_, "global_localization: %s", why.c_str());
    return false;
  }
  ROS_INFO_NAMED(name_, "global_localization: the particles are spread over the map's free space");
  return true;
}

}  // namespace ros_adapter
}  // namespace evidential_slam
