#include "evidential_slam/core/worker_pool.h"

namespace evidential_slam {

WorkerPool::WorkerPool(int threads) {
  int n = threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency());
  if (n < 1) n = 1;
  for (int i = 1; i < n; ++i) workers_.emplace_back([this, i] { workerLoop(i); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void WorkerPool::drain(int worker) {
  std::unique_lock<std::mutex> lock(mutex_);
  while (job_ != nullptr && next_index_ < job_size_) {
    const size_t index = next_index_++;
    const auto* fn = job_;
    lock.unlock();
    (*fn)(index, worker);
    lock.lock();
    if (++finished_ == job_size_) done_.notify_all();
  }
}

void WorkerPool::workerLoop(int worker) {
  uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      ++busy_;
    }
    drain(worker);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --busy_;
    }
    done_.notify_all();
  }
}

void WorkerPool::run(size_t n, const std::function<void(size_t, int)>& fn) {
  if (n == 0) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    job_size_ = n;
    next_index_ = 0;
    finished_ = 0;
    ++generation_;
  }
  wake_.notify_all();
  drain(0);
  std::unique_lock<std::mutex> lock(mutex_);
  // Wait for every index and for every worker to have left the job before `fn` goes away.
  done_.wait(lock, [&] { return finished_ == job_size_ && busy_ == 0; });
  job_ = nullptr;
}

}  // namespace evidential_slam
