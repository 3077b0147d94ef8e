// Runs a MappingSession (session/session.h: scan order, engine, conflict alarm) on its own
// thread, so ROS callbacks only convert and enqueue. No ROS in here: the nodelet wires the
// callbacks to publishers.
#pragma once

#include <chrono>
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
  // Changes whenever the anomaly may have: every processed scan, and with `version`. In
  // localization mode the map stays as it is while this moves on.
  uint64_t anomaly_version = 0;
  std::shared_ptr<const AnomalyNode> anomaly;  // the best particle's (core/anomaly.h)
  // Localization mode: the anomaly against the stored map (`grid`), instead of `anomaly`.
  std::shared_ptr<const AnomalyGrid> anomaly_grid;
};

// What the worker has done so far (the node's heartbeat on /diagnostics).
struct WorkerStats {
  uint64_t handled = 0;           // scans taken off the queue
  uint64_t dropped = 0;           // ... older than the previous one (MappingSession::scansDropped)
  uint64_t stamp_outliers = 0;    // ... with an outlier stamp
  uint64_t refused = 0;           // ... beyond a limit
  uint64_t restarts = 0;          // times the SLAM started over
  uint64_t queue_full_drops = 0;  // scans push() refused
  uint64_t skipped = 0;           // scans passed over for a newer one (live mode)
  double last_latency_s = 0.0;    // from push() to the end of the scan's processing (wall time)
  double max_latency_s = 0.0;
  bool conflict_alarm = false;  // the alarm's verdict on the last processed scan
  std::string last_reset_save;  // where the map went before the last restart (empty: none)
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

  // Live mode: when several scans wait, the worker takes the newest and skips the others (the
  // odometry of the newest spans the gap, as GMapping does). Off: every scan, in order.
  void setLive(bool live);
  // Queues a scan with the odometry pose at its stamp. False (nothing queued) when the queue is
  // full: the filter is slower than the sensor.
  bool push(const Pose2& odometry, const LaserScan& scan);

  // Starts the SLAM over, for `reason` (the clock jumped back), after the scans already queued
  // and before those pushed later, saving the map first (MappingSession::restart); the message
  // goes to on_warning as a restart.
  void requestRestart(const std::string& reason);
  // Where the session saves maps before a restart (MappingSession::setResetSaveRoot).
  void setResetSaveRoot(const std::string& root);

  // New run-time parameters, applied before the next scan. False (and `why`) when invalid.
  bool reconfigure(const Parameters& params, std::string* why);

  // Runs `task` on the worker thread between two scans and waits for it: the way to read the
  // session (trajectory, stats, the conflict log) from another thread.
  void runOnWorker(const std::function<void(const MappingSession& session)>& task);
  // Runs `change` on the worker thread between two scans and waits for it: the way to start the
  // session over (on a map, at a pose) or pause it. With `map_changed` the map snapshot becomes
  // the session's current map (none when it holds no particle yet).
  void changeOnWorker(const std::function<void(MappingSession& session)>& change, bool map_changed);

  MapSnapshot latestMap() const;
  // Blocks until every queued scan has been handled (tests, shutdown of a player run).
  void waitIdle();
  size_t queued() const;
  uint64_t resets() const;
  WorkerStats stats() const;

 private:
  void run();
  // Queues `task` for the worker thread and waits until it ran.
  void runTask(const std::function<void()>& task);
  void afterRestart();  // on the worker thread, after the session started over
  // On the worker thread: the snapshot becomes the session's current map and anomaly (none
  // before the first particle in SLAM mode; the stored map in localization mode), at `stamp`
  // when given.
  void updateSnapshot(const double* stamp);

  MappingSession session_;
  const size_t max_queue_;
  Callbacks callbacks_;

  struct Item {
    Pose2 odometry;
    LaserScan scan;
    std::chrono::steady_clock::time_point pushed;
    std::string restart;  // not a scan: start over for this reason (requestRestart)
  };
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Item> queue_;
  std::deque<std::function<void()>> tasks_;
  std::unique_ptr<Parameters> pending_params_;
  std::string reset_save_root_;  // for the session, handed over on the worker thread
  bool busy_ = false;
  bool stop_ = false;
  bool live_ = false;
  MapSnapshot map_;
  uint64_t resets_ = 0;
  WorkerStats stats_;
  std::thread thread_;  // last: starts after everything above exists
};

}  // namespace ros_adapter
}  // namespace evidential_slam
