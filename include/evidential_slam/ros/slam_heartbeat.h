// The SLAM node's heartbeat on /diagnostics, once a second on wall time (also while nothing
// moves): scan rate, queue, latency, every kind of drop, restarts and the conflict alarm.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "evidential_slam/ros/guarded_params.h"
#include "evidential_slam/ros/scan_input.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class SlamHeartbeat {
 public:
  SlamHeartbeat(const std::string& name, ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                GuardedParams& params, const SlamWorker& worker, const ScanInput& scans,
                bool localization_mode);
  ~SlamHeartbeat() { timer_.stop(); }

 private:
  void heartbeat(diagnostic_updater::DiagnosticStatusWrapper& status);

  GuardedParams& params_;
  const SlamWorker& worker_;
  const ScanInput& scans_;
  const bool localization_mode_;
  diagnostic_updater::Updater updater_;
  ros::WallTimer timer_;
  uint64_t last_received_ = 0;  // scans received at the last heartbeat
  ros::WallTime last_time_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
