#include "evidential_slam/ros/slam_nodelet.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Path.h>
#include <std_msgs/Float64.h>
#include <pluginlib/class_list_macros.hpp>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/session/map_files.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

constexpr uint32_t kTfFilterQueue = 50;  // scans waiting for their odometry tf, at most

// Maps saved before a restart go under $ROS_HOME/evidential_slam (ROS_HOME: ~/.ros by default).
std::string resetSaveRoot() {
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  std::filesystem::path root;
  if (ros_home != nullptr && *ros_home != 0) {
    root = ros_home;
  } else if (home != nullptr && *home != 0) {
    root = std::filesystem::path(home) / ".ros";
  } else {
    return "";
  }
  return (root / "evidential_slam").string();
}

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

SlamNodelet::SlamNodelet() = default;

SlamNodelet::~SlamNodelet() {
  // Stop the inputs first, then the threads that publish.
  heartbeat_timer_.stop();
  scan_filter_.reset();
  scan_sub_.reset();
  map_timer_.stop();
  map_wall_timer_.stop();
  tf_timer_.stop();
  tf_watchdog_.stop();
  worker_.reset();
  map_publisher_.reset();
}

void SlamNodelet::onInit() {
  nh_ = getNodeHandle();
  private_nh_ = getPrivateNodeHandle();
  std::string why;
  std::vector<std::string> unknown;
  GmappingReport gmapping;
  if (!readParams(private_nh_, &params_, &why, &unknown, &gmapping) || !params_.isValid(&why)) {
    NODELET_FATAL("evidential_slam: invalid parameters: %s; the SLAM does not start", why.c_str());
    return;
  }
  localization_mode_ = params_.mode == "localization";
  for (const std::string& name : unknown) {
    NODELET_WARN("evidential_slam: '%s' is not a parameter of evidential_slam (ignored)",
                 name.c_str());
  }
  logGmappingReport(gmapping);

  SlamWorker::Callbacks callbacks;
  callbacks.on_scan = [this](const MappingSession& session, const SessionScanResult& result) {
    onScanHandled(session, result);
  };
  callbacks.on_warning = [this](const std::string& message, bool restarted) {
    if (restarted) {
      std::lock_guard<std::mutex> lock(transform_mutex_);
      have_transform_ = false;
      NODELET_WARN("%s", message.c_str());
    } else {
      NODELET_WARN_THROTTLE(5.0, "%s", message.c_str());
    }
  };
  try {
    worker_ = std::make_unique<SlamWorker>(params_, static_cast<size_t>(params_.scan_queue_size),
                                           callbacks);
  } catch (const std::exception& e) {
    NODELET_FATAL("evidential_slam: %s", e.what());
    return;
  }
  worker_->setResetSaveRoot(resetSaveRoot());
  worker_->setLive(params_.live);
  if (!startFromParameters(&why)) {
    NODELET_FATAL("evidential_slam: %s; the SLAM does not start", why.c_str());
    worker_.reset();
    return;
  }

  map_publisher_ = std::make_unique<MapPublisher>(nh_, private_nh_, params_.map_frame,
                                                  [this] { return worker_->latestMap(); });
  map_publisher_->setExternalConflictDisplayMax(params_.external_conflict_display_max);
  map_publisher_->setThresholds(params_.session.occupied_thresh, params_.session.free_thresh);
  map_publisher_->requestUpdate();  // a loaded map at once

  pose_pub_ = private_nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 10, true);
  particles_pub_ = private_nh_.advertise<geometry_msgs::PoseArray>("particles", 10);
  path_pub_ = private_nh_.advertise<nav_msgs::Path>("path", 1, true);
  conflict_pub_ = private_nh_.advertise<std_msgs::Float64>("conflict_added", 100);
  open_space_conflict_pub_ =
      private_nh_.advertise<std_msgs::Float64>("open_space_conflict_added", 100);
  diagnostics_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);

  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  // The listener runs on this nodelet's (single-threaded) callback queue, not on a thread of its
  // own: tf2_ros::MessageFilter loses a message for good when a transform lands between its
  // transformable request and its bookkeeping (a race seen under load: a scan vanished without a
  // word). On one queue, the tf callbacks and the filter's never overlap.
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_, false);
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();

  // Services on the multi-threaded handles: a save waits for the filter, scans keep flowing.
  ros::NodeHandle mt_nh = getMTNodeHandle();
  ros::NodeHandle mt_private_nh = getMTPrivateNodeHandle();
  save_map_srv_ = mt_private_nh.advertiseService("save_map", &SlamNodelet::saveMap, this);
  get_map_srv_ = mt_nh.advertiseService("dynamic_map", &SlamNodelet::getMap, this);
  load_map_srv_ = mt_private_nh.advertiseService("load_map", &SlamNodelet::loadMap, this);
  pause_srv_ = mt_private_nh.advertiseService("pause_mapping", &SlamNodelet::pauseMapping, this);
  reset_srv_ = mt_private_nh.advertiseService("reset", &SlamNodelet::resetSlam, this);
  if (localizationMode()) {
    global_localization_srv_ = mt_private_nh.advertiseService(
        "global_localization", &SlamNodelet::globalLocalization, this);
  }

  reconfigure_server_ = std::make_unique<dynamic_reconfigure::Server<EvidentialSlamConfig>>(
      reconfigure_mutex_, private_nh_);
  // The server starts from the parameter server, which lacks what came from gmapping's names:
  // give it the values read, before its first callback applies them.
  reconfigure_server_->updateConfig(toReconfigure(params_));
  reconfigure_server_->setCallback(
      [this](EvidentialSlamConfig& config, uint32_t level) { onReconfigure(config, level); });

  map_timer_ = nh_.createTimer(ros::Duration(params_.map_update_interval),
                               [this](const ros::TimerEvent&) { requestMapUpdate(); });
  // ROS time stops with a bag's /clock while the filter still works through its queue: on wall
  // time, a map at least every map_update_interval (an unchanged map is not sent again).
  map_wall_timer_ =
      nh_.createWallTimer(ros::WallDuration(0.25), [this](const ros::WallTimerEvent&) {
        double interval = 0.0;
        {
          std::lock_guard<std::mutex> lock(params_mutex_);
          interval = params_.map_update_interval;
        }
        if ((ros::WallTime::now() - last_map_request_.load()).toSec() >= interval)
          requestMapUpdate();
      });
  if (params_.transform_publish_period > 0.0) {
    tf_timer_ = nh_.createTimer(ros::Duration(params_.transform_publish_period),
                                &SlamNodelet::publishTransform, this);
  }

  // rviz's "2D Pose Estimate" (amcl's topic).
  initial_pose_sub_ = nh_.subscribe("initialpose", 2, &SlamNodelet::onInitialPose, this);

  scan_sub_ =
      std::make_unique<message_filters::Subscriber<sensor_msgs::LaserScan>>(nh_, "scan", 100);
  scan_filter_ = std::make_unique<tf2_ros::MessageFilter<sensor_msgs::LaserScan>>(
      *scan_sub_, *tf_buffer_, params_.odom_frame, kTfFilterQueue, nh_);
  scan_filter_->registerCallback(&SlamNodelet::onScan, this);
  scan_sub_->registerCallback(&SlamNodelet::onRawScan, this);
  tf_watchdog_ = nh_.createWallTimer(ros::WallDuration(1.0), &SlamNodelet::checkWaitingScans, this);
  scan_filter_->registerFailureCallback(
      [this](const sensor_msgs::LaserScan::ConstPtr& msg,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onScanWithoutTransform(msg, reason);
      });

  updater_ = std::make_unique<diagnostic_updater::Updater>(nh_, private_nh_, getName());
  updater_->setHardwareID("evidential_slam");
  updater_->add("heartbeat", this, &SlamNodelet::heartbeat);
  heartbeat_time_ = ros::WallTime::now();
  heartbeat_timer_ = nh_.createWallTimer(
      ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { updater_->force_update(); });

  if (localizationMode()) {
    NODELET_INFO(
        "evidential_slam: localization, %d-%d particles; frames %s -> %s -> %s; listening on %s",
        params_.localization.min_particles, params_.localization.max_particles,
        params_.map_frame.c_str(), params_.odom_frame.c_str(), params_.base_frame.c_str(),
        nh_.resolveName("scan").c_str());
    return;
  }
  NODELET_INFO(
      "evidential_slam: %d particles, %.3f m cells; frames %s -> %s -> %s; listening on %s",
      params_.slam.particles, params_.slam.resolution, params_.map_frame.c_str(),
      params_.odom_frame.c_str(), params_.base_frame.c_str(), nh_.resolveName("scan").c_str());
}

void SlamNodelet::requestMapUpdate() {
  last_map_request_ = ros::WallTime::now();
  map_publisher_->requestUpdate();
}

void SlamNodelet::logGmappingReport(const GmappingReport& report) {
  auto joined = [](const std::vector<std::string>& items) {
    std::string text;
    for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
    return text;
  };
  if (!report.used.empty()) {
    NODELET_INFO("evidential_slam: slam_gmapping's names read: %s", joined(report.used).c_str());
  }
  if (!report.shadowed.empty()) {
    NODELET_WARN("evidential_slam: our name wins where both are given; ignored: %s",
                 joined(report.shadowed).c_str());
  }
  if (!report.ignored.empty()) {
    NODELET_WARN(
        "evidential_slam: slam_gmapping parameters without a counterpart here, ignored "
        "(docs/ros.md, gmapping's parameters, says why): %s",
        joined(report.ignored).c_str());
  }
  for (const std::string& line : report.refused) NODELET_WARN("evidential_slam: %s", line.c_str());
}

void SlamNodelet::onScanWithoutTransform(
    const sensor_msgs::LaserScan::ConstPtr& msg,
    tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  {
    std::lock_guard<std::mutex> lock(watchdog_mutex_);
    in_filter_.erase(msg);
  }
  std::string odom_frame;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    odom_frame = params_.odom_frame;
  }
  std::string tf_error;
  tf_buffer_->canTransform(odom_frame, msg->header.frame_id, msg->header.stamp, &tf_error);
  ++scans_without_tf_;
  NODELET_WARN_THROTTLE(5.0, "scan dropped: no transform from '%s' to '%s' at t = %.3f (%s)%s%s",
                        msg->header.frame_id.c_str(), odom_frame.c_str(), msg->header.stamp.toSec(),
                        failureName(reason), tf_error.empty() ? "" : ": ", tf_error.c_str());
}

void SlamNodelet::onRawScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
  ++scans_received_;
  std::lock_guard<std::mutex> lock(watchdog_mutex_);
  // ROS time going back is a real restart (a looping bag's /clock), not a stamp outlier.
  const ros::Time now = ros::Time::now();
  SessionConfig session_params;
  {
    std::lock_guard<std::mutex> params_lock(params_mutex_);
    session_params = params_.session;
  }
  const double tolerance = session_params.time_jump_tolerance;
  if (!last_arrival_ros_time_.isZero() && (last_arrival_ros_time_ - now).toSec() > tolerance) {
    char reason[160];
    std::snprintf(reason, sizeof(reason), "ROS time jumped back by %.3f s (%.3f -> %.3f)",
                  (last_arrival_ros_time_ - now).toSec(), last_arrival_ros_time_.toSec(),
                  now.toSec());
    worker_->requestRestart(reason);
    // tf2's listener clears its buffer at the jump, but a /tf of the previous loop still queued
    // behind /clock can land after that clear and make every new transform "too old" for
    // cache_time; clearing again at the new loop's first scan drops it.
    tf_buffer_->clear();
    scan_stamps_.reset();
  }
  // The scans' stamps jumped back (the session's policy) while ROS time did not: a burst of
  // future stamps, then normal ones. tf2's buffer holds that future and refuses every later
  // transform as too old (TF_OLD_DATA) until the clock catches up: cleared, and said.
  scan_stamps_.setPolicy(stampPolicy(session_params));
  const double previous_stamp = scan_stamps_.last();
  if (scan_stamps_.next(msg->header.stamp.toSec()) == StampOrder::Verdict::kJumpedBack) {
    tf_buffer_->clear();
    NODELET_WARN_THROTTLE(10.0,
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

void SlamNodelet::checkWaitingScans(const ros::WallTimerEvent&) {
  sensor_msgs::LaserScan::ConstPtr waiting;
  {
    std::lock_guard<std::mutex> lock(watchdog_mutex_);
    const ros::WallTime now = ros::WallTime::now();
    // A scan waiting for more than 3 s while later scans went through is lost.
    for (auto it = in_filter_.begin(); it != in_filter_.end();) {
      if ((now - it->second).toSec() > 3.0 && last_passed_arrival_ > it->second) {
        NODELET_WARN_THROTTLE(5.0,
                              "scan at t = %.3f lost: it still waits for its transform to the "
                              "odometry frame while later scans went through",
                              it->first->header.stamp.toSec());
        ++scans_without_tf_;
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
  std::string odom_frame;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    odom_frame = params_.odom_frame;
  }
  std::string tf_error;
  if (tf_buffer_->canTransform(odom_frame, waiting->header.frame_id, waiting->header.stamp,
                               &tf_error)) {
    return;
  }
  NODELET_WARN_THROTTLE(5.0, "scans are waiting: no transform from '%s' to '%s' at t = %.3f: %s",
                        waiting->header.frame_id.c_str(), odom_frame.c_str(),
                        waiting->header.stamp.toSec(), tf_error.c_str());
}

void SlamNodelet::onScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(watchdog_mutex_);
    last_passed_arrival_ = ros::WallTime::now();
    in_filter_.erase(msg);
  }
  NodeParams params;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params = params_;
  }
  geometry_msgs::TransformStamped odom_base, base_laser;
  try {
    odom_base =
        tf_buffer_->lookupTransform(params.odom_frame, params.base_frame, msg->header.stamp);
    base_laser =
        tf_buffer_->lookupTransform(params.base_frame, msg->header.frame_id, msg->header.stamp);
  } catch (const tf2::TransformException& e) {
    ++scans_without_tf_;
    NODELET_WARN_THROTTLE(5.0, "scan dropped: transform '%s' -> '%s' -> '%s' unavailable: %s",
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
    ++scans_malformed_;
    NODELET_WARN_THROTTLE(5.0, "malformed LaserScan at t = %.3f dropped: %s",
                          msg->header.stamp.toSec(), why.c_str());
    return;
  }
  if (!worker_->push(pose2FromTransform(odom_base.transform), scan)) {
    NODELET_WARN_THROTTLE(
        5.0,
        "scan dropped: %zu scans are waiting for the filter, which is slower than "
        "the laser (fewer particles or a coarser resolution would help)",
        worker_->queued());
  }
}

void SlamNodelet::onScanHandled(const MappingSession& session, const SessionScanResult& result) {
  const SlamEngine& engine = session.engine();
  const bool localizing = session.localizing();
  const ScanUpdate& update = result.update;
  std::string map_frame;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    map_frame = params_.map_frame;
  }
  if (localizing && !session.localizer().initialized()) return;
  {
    std::lock_guard<std::mutex> lock(transform_mutex_);
    map_to_odom_ = localizing ? session.localizer().mapToOdom() : engine.mapToOdom();
    have_transform_ = true;
  }
  ros::Time ros_stamp;
  ros_stamp.fromSec(result.stamp);
  // A paused scan adds no conflict: the alarm did not see it.
  if (update.processed && !session.mappingPaused()) reportConflict(result, ros_stamp);

  publishEstimate(session, ros_stamp);
  if (result.processed() && path_pub_.getNumSubscribers() > 0) {
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

void SlamNodelet::publishEstimate(const MappingSession& session, const ros::Time& stamp) {
  const bool localizing = session.localizing();
  const SlamEngine& engine = session.engine();
  const PoseEstimate estimate = localizing ? session.localizer().estimate() : engine.poseEstimate();
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = stamp;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    pose.header.frame_id = params_.map_frame;
  }
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

void SlamNodelet::reportConflict(const SessionScanResult& result, const ros::Time& stamp) {
  const ScanUpdate& update = result.update;
  const ConflictAlarmState& state = result.alarm;
  std_msgs::Float64 added;
  added.data = update.conflict_mass_added;
  conflict_pub_.publish(added);
  added.data = state.added;
  open_space_conflict_pub_.publish(added);

  char message[256];
  if (state.alarm) {
    std::snprintf(message, sizeof(message),
                  "localisation failure or environment change: the scan added %.1f of conflict "
                  "mass in the map's open space (running baseline %.2f; %.1f in all, %.1f bits of "
                  "external conflict)",
                  state.added, state.baseline, update.conflict_mass_added,
                  update.external_conflict_added);
  } else {
    std::snprintf(message, sizeof(message), "external conflict as usual");
  }
  if (state.rising) NODELET_WARN("%s (t = %.3f)", message, stamp.toSec());

  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = stamp;
  diagnostic_msgs::DiagnosticStatus status;
  status.name = getName() + ": external conflict";
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
  value("open_space_conflict_added", state.added);
  value("ec_added_bits", update.external_conflict_added);
  value("baseline", state.baseline);
  value("ratio", state.ratio);
  array.status.push_back(status);
  diagnostics_pub_.publish(array);
}

void SlamNodelet::publishTransform(const ros::TimerEvent&) {
  Pose2 map_to_odom;
  {
    std::lock_guard<std::mutex> lock(transform_mutex_);
    if (!have_transform_) return;
    map_to_odom = map_to_odom_;
  }
  geometry_msgs::TransformStamped t;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    t.header.frame_id = params_.map_frame;
    t.child_frame_id = params_.odom_frame;
    // Post-dated like gmapping's, so consumers can transform data up to the next broadcast.
    t.header.stamp = ros::Time::now() + ros::Duration(params_.transform_tolerance);
  }
  // tf refuses (and warns about) a second transform with the same stamp: simulated time may not
  // have advanced since the last broadcast.
  if (t.header.stamp == last_tf_stamp_) return;
  last_tf_stamp_ = t.header.stamp;
  t.transform = toTransformMsg(map_to_odom);
  tf_broadcaster_->sendTransform(t);
}

void SlamNodelet::onReconfigure(EvidentialSlamConfig& config, uint32_t) {
  NodeParams next;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    next = params_;
  }
  applyReconfigure(config, &next);
  std::string why;
  if (!next.isValid(&why) || !worker_->reconfigure(next, &why)) {
    NODELET_ERROR("dynamic_reconfigure: parameters refused (%s); keeping the previous ones",
                  why.c_str());
    std::lock_guard<std::mutex> lock(params_mutex_);
    config = toReconfigure(params_);
    return;
  }
  const bool interval_changed = next.map_update_interval != params_.map_update_interval;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params_ = next;
  }
  map_publisher_->setExternalConflictDisplayMax(next.external_conflict_display_max);
  map_publisher_->setThresholds(next.session.occupied_thresh, next.session.free_thresh);
  if (interval_changed && map_timer_.isValid()) {
    map_timer_.setPeriod(ros::Duration(next.map_update_interval));
  }
}

bool SlamNodelet::saveMap(SaveMap::Request& request, SaveMap::Response& response) {
  response.success = false;
  auto fail = [&response](const std::string& message) {
    response.message = message;
    ROS_ERROR("save_map: %s", message.c_str());
    return true;  // the call itself worked; `success` says the save did not
  };
  if (request.directory.empty()) return fail("no directory given");

  MapSave save;
  SessionConfig config;
  bool have_map = false;
  worker_->runOnWorker([&](const MappingSession& session) {
    have_map = session.localizing() || !session.engine().filter().particles().empty();
    if (!have_map) return;
    save = captureMapSave(session);
    config = session.parameters().session;
  });
  if (!have_map) return fail("no map yet: no scan has been processed and no map loaded");
  save.info.metadata["source"] = "ros:" + nh_.resolveName("scan");
  save.info.metadata["node"] = getName();

  MapFilesReport report;
  std::string error;
  if (!writeMapFiles(request.directory, save, config, &report, &error)) return fail(error);
  response.files = report.files;
  response.success = true;
  response.message =
      "saved " + std::to_string(response.files.size()) + " files to " + request.directory;
  if (!report.layers_skipped.empty()) response.message += "; " + report.layers_skipped;
  NODELET_INFO("save_map: %s", response.message.c_str());
  return true;
}

void SlamNodelet::heartbeat(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const WorkerStats w = worker_->stats();
  const size_t queued = worker_->queued();
  size_t capacity = 0;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    capacity = static_cast<size_t>(params_.scan_queue_size);
  }
  const uint64_t received = scans_received_;
  const ros::WallTime now = ros::WallTime::now();
  const double period = std::max(1e-3, (now - heartbeat_time_).toSec());
  const double rate = static_cast<double>(received - heartbeat_received_) / period;
  heartbeat_received_ = received;
  heartbeat_time_ = now;
  const uint64_t malformed = scans_malformed_, without_tf = scans_without_tf_;

  if (w.conflict_alarm) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "conflict alarm");
  } else if (queued * 5 >= capacity * 4) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "scan queue nearly full");
  } else if (received == 0 || rate == 0.0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scans");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   localizationMode() ? "localizing" : "mapping");
  }
  status.add("scan rate (Hz)", rate);
  status.add("scans received", received);
  status.add("scans handled", w.handled);
  status.add("queue length", queued);
  status.add("queue capacity", capacity);
  status.add("latency last (s)", w.last_latency_s);
  status.add("latency max (s)", w.max_latency_s);
  status.add("dropped: queue full", w.queue_full_drops);
  status.add("skipped: live mode", w.skipped);
  status.add("dropped: malformed", malformed);
  status.add("dropped: no transform", without_tf);
  status.add("dropped: older stamp", w.dropped);
  status.add("dropped: stamp outlier", w.stamp_outliers);
  status.add("refused: limits", w.refused);
  status.add("restarts", w.restarts);
  status.add("map saved before the last restart", w.last_reset_save);
  status.add("conflict alarm", w.conflict_alarm);
}

bool SlamNodelet::getMap(nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& response) {
  const MapSnapshot snapshot = worker_->latestMap();
  if (!snapshot.grid) return false;
  std_msgs::Header header;
  header.stamp.fromSec(snapshot.stamp);
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    header.frame_id = params_.map_frame;
  }
  double occupied = 0.0, free = 0.0;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    occupied = params_.session.occupied_thresh;
    free = params_.session.free_thresh;
  }
  toTrinaryOccupancyGrid(extractLayers(*snapshot.grid), occupied, free, header, &response.map);
  return true;
}

bool SlamNodelet::startFromParameters(std::string* why) {
  // amcl's names; any of the three set on the parameter server counts as given.
  const bool pose_given = private_nh_.hasParam("initial_pose_x") ||
                          private_nh_.hasParam("initial_pose_y") ||
                          private_nh_.hasParam("initial_pose_a");
  const Pose2 initial_pose(params_.initial_pose_x, params_.initial_pose_y, params_.initial_pose_a);
  if (localizationMode()) {
    LoadedMap loaded;
    if (!loadMapFile(params_.map_file, &loaded, why)) {
      *why = "map_file: " + *why;
      return false;
    }
    const Pose2 start = pose_given ? initial_pose : loaded.info.robot_pose;
    if (!localizeOn(loaded.map, startAt(start), why)) {
      *why = "map_file: " + *why;
      return false;
    }
    NODELET_INFO("evidential_slam: localizing on %s (%zu tiles) from (%.3f, %.3f, %.3f), %s",
                 loaded.path.c_str(), loaded.map.allocatedTiles(), start.x, start.y, start.theta,
                 pose_given ? "initial_pose_*" : "the pose saved in the file");
    return true;
  }
  if (params_.map_file.empty()) {
    if (!pose_given) return true;
    if (startOnMap(EvidentialGridMap(params_.slam.resolution), initial_pose, nullptr, why)) {
      return true;
    }
    *why = "initial_pose_*: " + *why;
    return false;
  }
  LoadedMap loaded;
  if (!loadMapFile(params_.map_file, &loaded, why)) {
    *why = "map_file: " + *why;
    return false;
  }
  const Pose2 start = pose_given ? initial_pose : loaded.info.robot_pose;
  if (!startOnMap(loaded.map, start, nullptr, why)) {
    *why = "map_file: " + *why;
    return false;
  }
  NODELET_INFO("evidential_slam: continuing on %s (%zu tiles) at (%.3f, %.3f, %.3f), %s",
               loaded.path.c_str(), loaded.map.allocatedTiles(), start.x, start.y, start.theta,
               pose_given ? "initial_pose_*" : "the pose saved in the file");
  return true;
}

bool SlamNodelet::currentOdometry(Pose2* odometry) {
  std::string odom_frame, base_frame;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    odom_frame = params_.odom_frame;
    base_frame = params_.base_frame;
  }
  try {
    *odometry = pose2FromTransform(
        tf_buffer_->lookupTransform(odom_frame, base_frame, ros::Time(0)).transform);
    return true;
  } catch (const tf2::TransformException&) {
    return false;
  }
}

bool SlamNodelet::startOnMap(const EvidentialGridMap& map, const Pose2& pose,
                             const Pose2* odometry, std::string* why) {
  bool ok = false;
  double resolution = 0.0;
  worker_->changeOnWorker(
      [&](MappingSession& session) {
        ok = session.startFromMap(map, pose, why, odometry);
        resolution = session.parameters().slam.resolution;
      },
      true);
  if (!ok) return false;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params_.slam.resolution = resolution;
  }
  std::lock_guard<std::mutex> lock(transform_mutex_);
  have_transform_ = odometry != nullptr;
  if (have_transform_) map_to_odom_ = pose.compose(odometry->inverse());
  if (map_publisher_) map_publisher_->requestUpdate();
  return true;
}

void SlamNodelet::onInitialPose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg) {
  std::string map_frame;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    map_frame = params_.map_frame;
  }
  // rviz sends it in its fixed frame: anything but the map frame is brought into it through tf.
  Pose2 pose = pose2FromPoseMsg(msg->pose.pose);
  const std::string& frame = msg->header.frame_id;
  if (!frame.empty() && frame != map_frame) {
    try {
      const Pose2 frame_in_map =
          pose2FromTransform(tf_buffer_->lookupTransform(map_frame, frame, ros::Time(0)).transform);
      pose = frame_in_map.compose(pose);
    } catch (const tf2::TransformException& e) {
      NODELET_WARN("initialpose in frame '%s' ignored: no transform to '%s' (%s)", frame.c_str(),
                   map_frame.c_str(), e.what());
      return;
    }
  }
  std::string why;
  if (localizationMode()) {
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
      NODELET_WARN("initialpose (%.3f, %.3f, %.3f) ignored: %s", pose.x, pose.y, pose.theta,
                   why.c_str());
      return;
    }
    NODELET_INFO("initialpose: the particles start again around (%.3f, %.3f, %.3f)", pose.x, pose.y,
                 pose.theta);
    return;
  }
  Pose2 odometry;
  const bool have_odometry = currentOdometry(&odometry);
  bool ok = false;
  EvidentialGridMap map;
  worker_->runOnWorker([&](const MappingSession& session) { map = session.currentMap(); });
  ok = startOnMap(map, pose, have_odometry ? &odometry : nullptr, &why);
  if (!ok) {
    NODELET_WARN("initialpose (%.3f, %.3f, %.3f) ignored: %s", pose.x, pose.y, pose.theta,
                 why.c_str());
    return;
  }
  NODELET_INFO("initialpose: the SLAM starts over on its current map (%zu tiles) at (%.3f, %.3f, "
               "%.3f)",
               map.allocatedTiles(), pose.x, pose.y, pose.theta);
}

bool SlamNodelet::loadMap(LoadMap::Request& request, LoadMap::Response& response) {
  response.success = false;
  LoadedMap loaded;
  std::string why;
  if (request.path.empty()) {
    why = "no path given";
  } else if (loadMapFile(request.path, &loaded, &why)) {
    const Pose2 pose = request.use_pose
                           ? Pose2(request.pose.x, request.pose.y, request.pose.theta)
                           : loaded.info.robot_pose;
    Pose2 odometry;
    const bool have_odometry = currentOdometry(&odometry);
    const bool started = localizationMode()
                             ? localizeOn(loaded.map, startAt(pose), &why)
                             : startOnMap(loaded.map, pose, have_odometry ? &odometry : nullptr,
                                          &why);
    if (started) {
      clearTransforms();
      char text[256];
      std::snprintf(text, sizeof(text), "%s on %s (%zu tiles, %g m cells) at (%.3f, %.3f, "
                    "%.3f)%s",
                    localizationMode() ? "localizing" : "continuing",
                    loaded.path.c_str(), loaded.map.allocatedTiles(), loaded.map.resolution(),
                    pose.x, pose.y, pose.theta,
                    request.use_pose ? "" : " (the pose saved in the file)");
      response.success = true;
      response.message = text;
      NODELET_INFO("load_map: %s", text);
      return true;
    }
  }
  response.message = why;
  NODELET_ERROR("load_map: %s", why.c_str());
  return true;  // the call itself worked; `success` says the load did not
}

bool SlamNodelet::pauseMapping(std_srvs::SetBool::Request& request,
                               std_srvs::SetBool::Response& response) {
  if (localizationMode()) {
    response.success = false;
    response.message = "localization mode: the map is never changed";
    return true;
  }
  const bool pause = request.data;
  worker_->changeOnWorker([pause](MappingSession& session) { session.setMappingPaused(pause); },
                          false);
  response.success = true;
  response.message = pause ? "mapping paused: scans localize on the map, which stays as it is"
                           : "mapping resumed";
  NODELET_INFO("pause_mapping: %s", response.message.c_str());
  return true;
}

bool SlamNodelet::resetSlam(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  if (localizationMode()) {
    worker_->changeOnWorker([](MappingSession& session) { session.reset(); }, true);
    clearTransforms();
    NODELET_INFO("reset: the particles start again as they did on the map");
    return true;
  }
  std::string message;
  worker_->changeOnWorker(
      [&message](MappingSession& session) {
        session.setMappingPaused(false);
        session.startOver("reset", &message);
      },
      true);
  {
    std::lock_guard<std::mutex> lock(transform_mutex_);
    have_transform_ = false;
  }
  clearTransforms();
  NODELET_INFO("%s", message.c_str());
  return true;
}

void SlamNodelet::clearTransforms() {
  std::lock_guard<std::mutex> lock(watchdog_mutex_);
  tf_buffer_->clear();  // static transforms stay (tf2's static cache ignores clear)
  scan_stamps_.reset();
}

bool SlamNodelet::globalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  LocalizationStart start;
  start.global = true;
  std::string why;
  if (!restartLocalization(start, &why)) {
    NODELET_ERROR("global_localization: %s", why.c_str());
    return false;
  }
  NODELET_INFO("global_localization: the particles are spread over the map's free space");
  return true;
}

LocalizationStart SlamNodelet::startAt(const Pose2& pose) {
  LocalizationStart start;
  start.pose = pose;
  std::lock_guard<std::mutex> lock(params_mutex_);
  const LocalizationConfig& c = params_.localization;
  start.covariance.diagonal() << c.initial_cov_xx, c.initial_cov_yy, c.initial_cov_aa;
  return start;
}

bool SlamNodelet::localizeOn(const EvidentialGridMap& map, const LocalizationStart& start,
                             std::string* why) {
  bool ok = false;
  worker_->changeOnWorker(
      [&](MappingSession& session) { ok = session.startLocalization(map, start, why); }, true);
  if (!ok) return false;
  {
    std::lock_guard<std::mutex> lock(transform_mutex_);
    have_transform_ = false;  // known at the next scan
  }
  if (map_publisher_) map_publisher_->requestUpdate();
  return true;
}

bool SlamNodelet::restartLocalization(const LocalizationStart& start, std::string* why) {
  bool ok = false;
  worker_->changeOnWorker(
      [&](MappingSession& session) {
        ok = session.restartLocalization(start, why);
        // The new cloud at once (rviz; amcl publishes it at the next update).
        if (ok) publishEstimate(session, ros::Time::now());
      },
      false);
  return ok;
}

}  // namespace ros_adapter
}  // namespace evidential_slam

PLUGINLIB_EXPORT_CLASS(evidential_slam::ros_adapter::SlamNodelet, nodelet::Nodelet)
