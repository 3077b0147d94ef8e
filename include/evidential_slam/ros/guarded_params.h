// The SLAM node's parameters, shared by its parts: scans, timers, services and the worker's
// callbacks run on different threads, so each reads a copy (or one field) under one mutex.
#pragma once

#include <mutex>
#include <utility>

#include "evidential_slam/ros/params.h"

namespace evidential_slam {
namespace ros_adapter {

class GuardedParams {
 public:
  NodeParams get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return params_;
  }
  void set(const NodeParams& params) {
    std::lock_guard<std::mutex> lock(mutex_);
    params_ = params;
  }
  // What `read(params)` returns, e.g. one field, without copying the rest.
  template <typename Read>
  auto read(Read&& read) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::forward<Read>(read)(static_cast<const NodeParams&>(params_));
  }
  template <typename Change>
  void change(Change&& change) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::forward<Change>(change)(params_);
  }

 private:
  mutable std::mutex mutex_;
  NodeParams params_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
