// A fixed set of worker threads that run an indexed loop; the caller's thread takes part.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace evidential_slam {

class WorkerPool {
 public:
  // threads <= 0: one per hardware core.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()) + 1; }
  // Calls fn(index, worker) for index in [0, n), spread over the workers; blocks until all are
  // done. `worker` is in [0, size()) and identifies per-thread scratch.
  void run(size_t n, const std::function<void(size_t, int)>& fn);

 private:
  void workerLoop(int worker);
  void drain(int worker);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(size_t, int)>* job_ = nullptr;
  size_t job_size_ = 0;
  size_t next_index_ = 0;
  size_t finished_ = 0;
  uint64_t generation_ = 0;
  int busy_ = 0;
  bool stop_ = false;
};

}  // namespace evidential_slam
