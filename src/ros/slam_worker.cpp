#include "evidential_slam/ros/slam_worker.h"

#include <cstdio>
#include <future>
#include <utility>

namespace evidential_slam {
namespace ros_adapter {

SlamWorker::SlamWorker(const SlamConfig& config, double time_jump_tolerance, size_t max_queue,
                       Callbacks callbacks)
    : engine_(config),
      time_jump_tolerance_(time_jump_tolerance),
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
    if (queue_.size() >= max_queue_) return false;
    queue_.push_back(Item{odometry, scan});
  }
  wake_.notify_one();
  return true;
}

bool SlamWorker::reconfigure(const SlamConfig& config, std::string* why) {
  if (!config.isValid(why)) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_config_ = std::make_unique<SlamConfig>(config);
  }
  wake_.notify_one();
  return true;
}

void SlamWorker::runOnWorker(const std::function<void(const SlamEngine& engine)>& task) {
  auto done = std::make_shared<std::promise<void>>();
  std::future<void> finished = done->get_future();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tasks_.push_back([this, &task, done] {
      task(engine_);
      done->set_value();
    });
  }
  wake_.notify_one();
  finished.wait();
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

void SlamWorker::run() {
  auto warn = [this](const std::string& message, bool restarted = false) {
    if (callbacks_.on_warning) callbacks_.on_warning(message, restarted);
  };
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] {
      return stop_ || !queue_.empty() || !tasks_.empty() || pending_config_ != nullptr;
    });
    if (stop_) break;
    busy_ = true;
    if (pending_config_) {
      std::unique_ptr<SlamConfig> config = std::move(pending_config_);
      lock.unlock();
      std::string why;
      if (!engine_.reconfigure(*config, &why)) warn("new parameters refused: " + why);
      lock.lock();
    }
    if (!tasks_.empty()) {
      std::function<void()> task = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      task();
      lock.lock();
    } else if (!queue_.empty()) {
      Item item = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();

      const double stamp = item.scan.stamp;
      bool handle = true;
      if (have_last_stamp_ && stamp < last_stamp_) {
        char buf[160];
        if (last_stamp_ - stamp > time_jump_tolerance_) {
          std::snprintf(buf, sizeof(buf),
                        "time jumped back by %.3f s (%.3f -> %.3f): the SLAM starts over",
                        last_stamp_ - stamp, last_stamp_, stamp);
          engine_.reset();
          warn(buf, true);
          std::lock_guard<std::mutex> relock(mutex_);
          map_.grid.reset();
          ++map_.version;
          ++resets_;
        } else {
          std::snprintf(buf, sizeof(buf),
                        "scan at %.3f is older than the previous one (%.3f): dropped", stamp,
                        last_stamp_);
          warn(buf);
          handle = false;
        }
      }
      if (handle) {
        have_last_stamp_ = true;
        last_stamp_ = stamp;
        const ScanUpdate update = engine_.processScan(item.odometry, item.scan);
        if (update.rejected) warn("scan at " + std::to_string(stamp) + " unusable: " + update.why);
        if (update.processed) {
          auto grid = std::make_shared<const EvidentialGridMap>(engine_.bestMap());
          std::lock_guard<std::mutex> relock(mutex_);
          map_.grid = std::move(grid);
          map_.stamp = stamp;
          ++map_.version;
        }
        if (callbacks_.on_scan) callbacks_.on_scan(engine_, update, stamp);
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
