#include "evidential_slam/ros/slam_nodelet.h"
#include "evidential_slam/EvidentialSlamConfig.h"

#include <cstdlib>
#include <filesystem>

#include <pluginlib/class_list_macros.hpp>

namespace evidential_slam {
namespace ros_adapter {
namespace {

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

}  // namespace

SlamNodelet::SlamNodelet() = default;

SlamNodelet::~SlamNodelet() {
  // Inputs first, then the threads that publish, then what they publish through.
  heartbeat_.reset();
  services_.reset();
  scans_.reset();
  map_timer_.stop();
  map_wall_timer_.stop();
  worker_.reset();
  map_publisher_.reset();
  control_.reset();
  outputs_.reset();
}

void SlamNodelet::onInit() {
  nh_ = getNodeHandle();
  private_nh_ = getPrivateNodeHandle();
  std::string why;
  std::vector<std::string> unknown;
  GmappingReport gmapping;
  NodeParams params;
  if (!readParams(private_nh_, &params, &why, &unknown, &gmapping) || !params.isValid(&why)) {
    NODELET_FATAL("evidential_slam: invalid parameters: %s; the SLAM does not start", why.c_str());
    return;
  }
  params_.set(params);
  for (const std::string& name : unknown) {
    NODELET_WARN("evidential_slam: '%s' is not a parameter of evidential_slam (ignored)",
                 name.c_str());
  }
  logGmappingReport(gmapping);

  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  outputs_ = std::make_unique<SlamOutputs>(getName(), nh_, private_nh_, params_);
  SlamWorker::Callbacks callbacks;
  callbacks.on_scan = [this](const MappingSession& session, const SessionScanResult& result) {
    outputs_->onScanHandled(session, result);
  };
  callbacks.on_warning = [this](const std::string& message, bool restarted) {
    if (restarted) {
      outputs_->forgetMapToOdom();
      NODELET_WARN("%s", message.c_str());
    } else {
      NODELET_WARN_THROTTLE(5.0, "%s", message.c_str());
    }
  };
  try {
    worker_ = std::make_unique<SlamWorker>(params, static_cast<size_t>(params.scan_queue_size),
                                           callbacks);
  } catch (const std::exception& e) {
    NODELET_FATAL("evidential_slam: %s", e.what());
    return;
  }
  worker_->setResetSaveRoot(resetSaveRoot());
  worker_->setLive(params.live);
  control_ = std::make_unique<SlamControl>(getName(), private_nh_, params_, *worker_, *outputs_,
                                           *tf_buffer_);
  if (!control_->startFromParameters(&why)) {
    NODELET_FATAL("evidential_slam: %s; the SLAM does not start", why.c_str());
    worker_.reset();
    return;
  }

  map_publisher_ = std::make_unique<MapPublisher>(nh_, private_nh_, params.map_frame,
                                                  [this] { return worker_->latestMap(); });
  map_publisher_->setExternalConflictDisplayMax(params.external_conflict_display_max);
  map_publisher_->setThresholds(params.session.occupied_thresh, params.session.free_thresh);
  map_publisher_->requestUpdate();  // a loaded map at once
  control_->setMapPublisher(map_publisher_.get());

  // The listener runs on this nodelet's (single-threaded) callback queue, not on a thread of its
  // own: tf2_ros::MessageFilter loses a message for good when a transform lands between its
  // transformable request and its bookkeeping (a race seen under load: a scan vanished without a
  // word). On one queue, the tf callbacks and the filter's never overlap.
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_, false);
  scans_ = std::make_unique<ScanInput>(getName(), params_, *tf_buffer_, *worker_);
  ros::NodeHandle mt_nh = getMTNodeHandle();
  ros::NodeHandle mt_private_nh = getMTPrivateNodeHandle();
  services_ = std::make_unique<SlamServices>(getName(), nh_, mt_nh, mt_private_nh, params_,
                                             *worker_, *control_, *outputs_, *scans_);

  reconfigure_server_ = std::make_unique<dynamic_reconfigure::Server<EvidentialSlamConfig>>(
      reconfigure_mutex_, private_nh_);
  // The server starts from the parameter server, which lacks what came from gmapping's names:
  // give it the values read, before its first callback applies them.
  reconfigure_server_->updateConfig(toReconfigure(params));
  reconfigure_server_->setCallback(
      [this](EvidentialSlamConfig& config, uint32_t level) { onReconfigure(config, level); });
  startMapTimers();
  scans_->start(nh_);
  heartbeat_ = std::make_unique<SlamHeartbeat>(getName(), nh_, private_nh_, params_, *worker_,
                                               *scans_, control_->localizationMode());

  if (control_->localizationMode()) {
    NODELET_INFO(
        "evidential_slam: localization, %d-%d particles; frames %s -> %s -> %s; listening on %s",
        params.localization.min_particles, params.localization.max_particles,
        params.map_frame.c_str(), params.odom_frame.c_str(), params.base_frame.c_str(),
        nh_.resolveName("scan").c_str());
    return;
  }
  NODELET_INFO(
      "evidential_slam: %d particles, %.3f m cells; frames %s -> %s -> %s; listening on %s",
      params.slam.particles, params.slam.resolution, params.map_frame.c_str(),
      params.odom_frame.c_str(), params.base_frame.c_str(), nh_.resolveName("scan").c_str());
}

void SlamNodelet::startMapTimers() {
  const double interval = params_.read([](const NodeParams& p) { return p.map_update_interval; });
  map_timer_ = nh_.createTimer(ros::Duration(interval),
                               [this](const ros::TimerEvent&) { requestMapUpdate(); });
  // ROS time stops with a bag's /clock while the filter still works through its queue: on wall
  // time, a map at least every map_update_interval (an unchanged map is not sent again).
  map_wall_timer_ =
      nh_.createWallTimer(ros::WallDuration(0.25), [this](const ros::WallTimerEvent&) {
        const double interval =
            params_.read([](const NodeParams& p) { return p.map_update_interval; });
        if ((ros::WallTime::now() - last_map_request_.load()).toSec() >= interval)
          requestMapUpdate();
      });
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

void SlamNodelet::onReconfigure(EvidentialSlamConfig& config, uint32_t) {
  const NodeParams previous = params_.get();
  NodeParams next = previous;
  applyReconfigure(config, &next);
  std::string why;
  if (!next.isValid(&why) || !worker_->reconfigure(next, &why)) {
    NODELET_ERROR("dynamic_reconfigure: parameters refused (%s); keeping the previous ones",
                  why.c_str());
    config = toReconfigure(previous);
    return;
  }
  params_.set(next);
  map_publisher_->setExternalConflictDisplayMax(next.external_conflict_display_max);
  map_publisher_->setThresholds(next.session.occupied_thresh, next.session.free_thresh);
  if (next.map_update_interval != previous.map_update_interval && map_timer_.isValid()) {
    map_timer_.setPeriod(ros::Duration(next.map_update_interval));
  }
}

}  // namespace ros_adapter
}  // namespace evidential_slam

PLUGINLIB_EXPORT_CLASS(evidential_slam::ros_adapter::SlamNodelet, nodelet::Nodelet)
