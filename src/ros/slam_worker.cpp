#include "evidential_slam/ros/slam_worker.h"

#include <pthread.h>

#include <algorithm>
#include <cstdio>
#include <future>
#include <utility>

namespace evidential_slam {
namespace ros_adapter {

SlamWorker::SlamWorker(const Parameters& params, size_t max_queue, Callbacks callbacks)
    : session_(params),
      max_queue_(max_queue),
      callbacks_(std::move(callbacks)),
      thread_([this] { run(); }) {}

SlamWorker::~SlamWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
  // Tasks queued while stopping still run, so nobody waits on them forever.
  for (auto& task : tasks_) task();
}

bool SlamWorker::push(const Pose2& odometry, const LaserScan& scan) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.size() >= max_queue_) {
      ++stats_.queue_full_drops;
      return false;
    }
    queue_.push_back(Item{odometry, scan, std::chrono::steady_clock::now(), std::string()});
  }
  wake_.notify_one();
  return true;
}

void SlamWorker::setLive(bool live) {
  std::lock_guard<std::mutex> lock(mutex_);
  live_ = live;
}

bool SlamWorker::reconfigure(const Parameters& params, std::string* why) {
  if (!params.isValid(why)) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_params_ = std::make_unique<Parameters>(params);
  }
  wake_.notify_one();
  return true;
}

void SlamWorker::requestRestart(const std::string& reason) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Item item;
    item.restart = reason;
    queue_.push_back(std::move(item));  // in order with the scans, whatever the queue's size
  }
  wake_.notify_one();
}

void SlamWorker::setResetSaveRoot(const std::string& root) {
  std::lock_guard<std::mutex> lock(mutex_);
  reset_save_root_ = root;
}

void SlamWorker::runTask(const std::function<void()>& task) {
  auto done = std::make_shared<std::promise<void>>();
  std::future<void> finished = done->get_future();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tasks_.push_back([&task, done] {
      task();
      done->set_value();
    });
  }
  wake_.notify_one();
  finished.wait();
}

void SlamWorker::runOnWorker(const std::function<void(const MappingSession& session)>& task) {
  runTask([&] { task(session_); });
}

void SlamWorker::changeOnWorker(const std::function<void(MappingSession& session)>& change,
                                bool map_changed) {
  runTask([&] {
    change(session_);
    if (map_changed) updateSnapshot(nullptr);
  });
}

namespace {

// True when `a` and `b` are copies of one map: the same resolution and the same tiles (copies
// share them until one is written: evidential_grid.h), so the same cells.
bool sameTiles(const EvidentialGridMap& a, const EvidentialGridMap& b) {
  if (a.resolution() != b.resolution() || a.allocatedTiles() != b.allocatedTiles()) return false;
  bool same = true;
  a.forEachTile([&](int tx, int ty, const auto& tile) { same = same && b.tile(tx, ty) == &tile; });
  return same;
}

}  // namespace

void SlamWorker::updateSnapshot(const double* stamp) {
  std::shared_ptr<const EvidentialGridMap> grid;
  std::shared_ptr<const AnomalyNode> anomaly;
  std::shared_ptr<const AnomalyGrid> anomaly_grid;
  std::shared_ptr<const EvidentialGridMap> previous;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    previous = map_.grid;
  }
  if (session_.localizing()) {
    // The stored map changes only when another one is loaded: keep the snapshot's copy (and its
    // version) while it is the same map, so /map is not sent again for every scan.
    const EvidentialGridMap& stored = session_.localizer().map();
    grid = previous && sameTiles(*previous, stored)
               ? previous
               : std::make_shared<const EvidentialGridMap>(stored);
    anomaly_grid = std::make_shared<const AnomalyGrid>(session_.localizer().anomaly());
  } else if (!session_.engine().filter().particles().empty()) {
    grid = std::make_shared<const EvidentialGridMap>(session_.engine().bestMap());
    anomaly = session_.engine().bestAnomalyLineage();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (grid != map_.grid) ++map_.version;
  ++map_.anomaly_version;
  map_.grid = std::move(grid);
  map_.anomaly = std::move(anomaly);
  map_.anomaly_grid = std::move(anomaly_grid);
  if (stamp != nullptr) map_.stamp = *stamp;
}

MapSnapshot SlamWorker::latestMap() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return map_;
}

void SlamWorker::waitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return (queue_.empty() && tasks_.empty() && !busy_) || stop_; });
}

size_t SlamWorker::queued() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return queue_.size();
}

uint64_t SlamWorker::resets() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return resets_;
}

WorkerStats SlamWorker::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void SlamWorker::afterRestart() {
  updateSnapshot(nullptr);  // no map in SLAM mode; the stored one in localization mode
  std::lock_guard<std::mutex> lock(mutex_);
  ++resets_;
  stats_.restarts = session_.restarts();
  stats_.last_reset_save = session_.lastResetSave();
  stats_.conflict_alarm = false;
}

void SlamWorker::run() {
  // Named for top and /proc/<pid>/task/*/comm (scripts/soak reads the filter's CPU time there).
  pthread_setname_np(pthread_self(), "slam_worker");
  auto warn = [this](const std::string& message, bool restarted = false) {
    if (callbacks_.on_warning) callbacks_.on_warning(message, restarted);
  };
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] {
      return stop_ || !queue_.empty() || !tasks_.empty() || pending_params_ != nullptr;
    });
    if (stop_) break;
    busy_ = true;
    if (pending_params_) {
      std::unique_ptr<Parameters> params = std::move(pending_params_);
      lock.unlock();
      std::string why;
      if (!session_.reconfigure(*params, &why)) warn("new parameters refused: " + why);
      lock.lock();
    }
    if (!reset_save_root_.empty()) {
      session_.setResetSaveRoot(reset_save_root_);
      reset_save_root_.clear();
    }
    if (!tasks_.empty()) {
      std::function<void()> task = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      task();
      lock.lock();
    } else if (!queue_.empty()) {
      // Live: skip to the newest of the scans waiting before the next restart request.
      while (live_ && queue_.size() > 1 && queue_[0].restart.empty() && queue_[1].restart.empty()) {
        queue_.pop_front();
        ++stats_.skipped;
      }
      Item item = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      if (!item.restart.empty()) {
        std::string message;
        session_.restart(item.restart, &message);
        afterRestart();
        warn(message, true);
        lock.lock();
        busy_ = false;
        if (queue_.empty() && tasks_.empty()) idle_.notify_all();
        continue;
      }

      const SessionScanResult result = session_.processScan(item.odometry, item.scan);
      const bool restarted = result.order == SessionScanResult::Order::kRestarted;
      if (restarted) afterRestart();
      if (!result.message.empty()) warn(result.message, restarted);
      {
        std::lock_guard<std::mutex> relock(mutex_);
        ++stats_.handled;
        stats_.dropped = session_.scansDropped();
        stats_.stamp_outliers = session_.stampOutliers();
        stats_.refused = session_.scansRefused();
        stats_.last_latency_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - item.pushed).count();
        stats_.max_latency_s = std::max(stats_.max_latency_s, stats_.last_latency_s);
        if (result.update.processed) stats_.conflict_alarm = result.alarm.alarm;
      }
      if (result.used()) {
        const double stamp = item.scan.stamp;
        if (result.rejected()) {
          warn("scan at " + std::to_string(stamp) + " unusable: " + result.rejectionReason());
        }
        if (result.processed()) updateSnapshot(&stamp);
        if (callbacks_.on_scan) callbacks_.on_scan(session_, result);
      }
      lock.lock();
    }
    busy_ = false;
    if (queue_.empty() && tasks_.empty()) idle_.notify_all();
  }
  busy_ = false;
  idle_.notify_all();
}

}  // namespace ros_adapter
}  // namespace evidential_slam
