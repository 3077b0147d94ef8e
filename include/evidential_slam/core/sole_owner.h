// Copy-on-write writes an object in place when its shared_ptr is the only owner left. That test
// needs an order shared_ptr::use_count() does not give: the count is read relaxed, so nothing
// orders our writes after what other threads read of the object before they released it.
#pragma once

#include <atomic>
#include <memory>

#if defined(__SANITIZE_THREAD__)
#define EVIDENTIAL_SLAM_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define EVIDENTIAL_SLAM_THREAD_SANITIZER 1
#endif
#endif

namespace evidential_slam {

// True when `p` owns its object alone; the caller's later writes to it are then ordered after
// every other owner's use of it (each release is an acquire-release decrement of the count, which
// the acquire below pairs with).
template <typename T>
bool isSoleOwner(const std::shared_ptr<T>& p) {
  if (!p || p.use_count() != 1) return false;
#ifdef EVIDENTIAL_SLAM_THREAD_SANITIZER
  // ThreadSanitizer does not model fences: a copy's acquire-release increment of the same count
  // gives the same order in a form it sees.
  const std::shared_ptr<T> probe(p);
#else
  std::atomic_thread_fence(std::memory_order_acquire);
#endif
  return true;
}

}  // namespace evidential_slam
