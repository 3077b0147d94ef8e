// Turns map snapshots into messages on its own thread: the latched `map` (trinary, as gmapping's:
// toTrinaryOccupancyGrid) and `map_metadata`, `~grid` (every layer as floats) and one latched
// OccupancyGrid per layer under `~layers/<name>`. A layer topic is rendered only while someone
// subscribes to it (and at once for a new subscriber); `~grid` likewise. `map`, `map_metadata`,
// `~grid` and the mass layers are sent when the map changes (MapSnapshot::version), the anomaly
// layer also when only the anomaly does (anomaly_version: localization mode, where the map stays).
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <ros/ros.h>

#include "evidential_slam/core/measures.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class MapPublisher {
 public:
  // `nh` for `map`/`map_metadata`, `private_nh` for `~grid` and `~layers/*`. `source` returns the
  // latest snapshot (called on the publisher's thread).
  MapPublisher(ros::NodeHandle nh, ros::NodeHandle private_nh, std::string map_frame,
               std::function<MapSnapshot()> source);
  ~MapPublisher();

  // Publishes what changed in the latest snapshot since the last publication (call every
  // map_update_interval). Returns at once; the work happens on the publisher's thread.
  void requestUpdate();
  void setExternalConflictDisplayMax(double bits) { ec_display_max_ = bits; }
  // BetP(o) thresholds of the trinary `map` (occupied_thresh, free_thresh), from the next update.
  void setThresholds(double occupied, double free) {
    occupied_thresh_ = occupied;
    free_thresh_ = free;
  }

 private:
  void run();
  void publish(const MapSnapshot& snapshot, bool map_changed, bool anomaly_changed);

  ros::Publisher map_pub_, metadata_pub_, grid_pub_;
  std::array<ros::Publisher, kLayerCount> layer_pubs_;
  std::array<std::atomic<bool>, kLayerCount> layer_wanted_{};  // new subscriber waiting
  std::atomic<bool> grid_wanted_{false};                        // ... on ~grid
  std::string map_frame_;
  std::function<MapSnapshot()> source_;
  std::atomic<double> ec_display_max_{2.0};
  std::atomic<double> occupied_thresh_{0.65};
  std::atomic<double> free_thresh_{0.196};

  std::mutex mutex_;
  std::condition_variable wake_;
  bool update_requested_ = false;
  bool stop_ = false;
  uint64_t published_version_ = 0;
  uint64_t published_anomaly_version_ = 0;
  std::thread thread_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
