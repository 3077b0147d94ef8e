#include "evidential_slam/ros/slam_heartbeat.h"

#include <algorithm>

namespace evidential_slam {
namespace ros_adapter {

SlamHeartbeat::SlamHeartbeat(const std::string& name, ros::NodeHandle& nh,
                             ros::NodeHandle& private_nh, GuardedParams& params,
                             const SlamWorker& worker, const ScanInput& scans,
                             bool localization_mode)
    : params_(params),
      worker_(worker),
      scans_(scans),
      localization_mode_(localization_mode),
      updater_(nh, private_nh, name) {
  updater_.setHardwareID("evidential_slam");
  updater_.add("heartbeat", this, &SlamHeartbeat::heartbeat);
  last_time_ = ros::WallTime::now();
  timer_ = nh.createWallTimer(ros::WallDuration(1.0),
                              [this](const ros::WallTimerEvent&) { updater_.force_update(); });
}

void SlamHeartbeat::heartbeat(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const WorkerStats w = worker_.stats();
  const size_t queued = worker_.queued();
  const size_t capacity =
      static_cast<size_t>(params_.read([](const NodeParams& p) { return p.scan_queue_size; }));
  const ScanInput::Counters scans = scans_.counters();
  const ros::WallTime now = ros::WallTime::now();
  const double period = std::max(1e-3, (now - last_time_).toSec());
  const double rate = static_cast<double>(scans.received - last_received_) / period;
  last_received_ = scans.received;
  last_time_ = now;

  if (w.conflict_alarm) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "conflict alarm");
  } else if (queued * 5 >= capacity * 4) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "scan queue nearly full");
  } else if (scans.received == 0 || rate == 0.0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scans");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   localization_mode_ ? "localizing" : "mapping");
  }
  status.add("scan rate (Hz)", rate);
  status.add("scans received", scans.received);
  status.add("scans handled", w.handled);
  status.add("queue length", queued);
  status.add("queue capacity", capacity);
  status.add("latency last (s)", w.last_latency_s);
  status.add("latency max (s)", w.max_latency_s);
  status.add("dropped: queue full", w.queue_full_drops);
  status.add("skipped: live mode", w.skipped);
  status.add("dropped: malformed", scans.malformed);
  status.add("dropped: no transform", scans.without_tf);
  status.add("dropped: older stamp", w.dropped);
  status.add("dropped: stamp outlier", w.stamp_outliers);
  status.add("refused: limits", w.refused);
  status.add("restarts", w.restarts);
  status.add("map saved before the last restart", w.last_reset_save);
  status.add("conflict alarm", w.conflict_alarm);
}

}  // namespace ros_adapter
}  // namespace evidential_slam
