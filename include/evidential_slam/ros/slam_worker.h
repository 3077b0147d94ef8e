// Runs a MappingSession (session/session.h: scan order, engine, conflict alarm) on its own
// thread, so ROS callbacks only convert and enqueue. No ROS in here: the nodelet wires the
// callbacks to publishers.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "evidential_slam/session/session.h"

namespace evidential_slam {
namespace ros_adapter {

// The latest map, shared copy-on-write with the engine's best particle (copying it is cheap;
// the engine clones a tile before writing to one the snapshot still holds).
struct MapSnapshot {
  std::shared_ptr<const EvidentialGridMap> grid;  // null before the first processed scan
  double stamp = 0.0;                             // of the scan that last changed it
  uint64_t version = 0;                           // changes whenever the map does (0: no map)
  std::shared_ptr<const AnomalyNode> anomaly;      // the best particle's (core/anomaly.h)
};

class SlamWorker {
 public:
  struct Callbacks {
    // After every scan the session handed to the engine (processed or gated), on the worker
    // thread. The session may be read inside; it is not changed while the callback runs.
    std::function<void(const MappingSession& session, const SessionScanResult& result)> on_scan;
    // Something the user should know, one line: a restart after a time jump (`restarted`), or a
    // scan dropped or refused (frequent; worth throttling).
    std::function<void(const std::string& message, bool restarted)> on_warning;
  };

  SlamWorker(const Parameters& params, size_t max_queue, Callbacks callbacks);
  ~SlamWorker();  // finishes the scan in progress, drops the queue, joins the thread
  SlamWorker(const SlamWorker&) = delete;
  SlamWorker& operator=(const SlamWorker&) = delete;

  // Queues a scan with the odometry pose at its stamp. False (nothing queued) when the queue is
  // full: the filter is slower than the sensor.
  bool push(const Pose2& odometry, const LaserScan& scan);

  // New run-time parameters, applied before the next scan. False (and `why`) when invalid.
  bool reconfigure(const Parameters& params, std::string* why);

  // Runs `task` on the worker thread between two scans and waits for it: the way to read the
  // session (trajectory, stats, the conflict log) from another thread.
  void runOnWorker(const std::function<void(const MappingSession& session)>& task);
  // Runs `change` on the worker thread between two scans and waits for it: the way to start the
  // session over (on a map, at a pose) or pause it. With `map_changed` the map snapshot becomes
  // the session's current map (none when it holds no particle yet).
  void changeOnWorker(const std::function<void(MappingSession& session)>& change,
                      bool map_changed);

  MapSnapshot latestMap() const;
  // Blocks until every queued scan has been handled (tests, shutdown of a player run).
  void waitIdle();
  size_t queued() const;
  uint64_t resets() const;

 private:
  void run();
  // Queues `task` for the worker thread and waits until it ran.
  void runTask(const std::function<void()>& task);

  MappingSession session_;
  const size_t max_queue_;
  Callbacks callbacks_;

  struct Item {
    Pose2 odometry;
    LaserScan scan;
  };
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Item> queue_;
  std::deque<std::function<void()>> tasks_;
  std::unique_ptr<Parameters> pending_params_;
  bool busy_ = false;
  bool stop_ = false;
  MapSnapshot map_;
  uint64_t resets_ = 0;
  std::thread thread_;  // last: starts after everything above exists
};

}  // namespace ros_adapter
}  // namespace evidential_slam
