// Which map -> odom stamps may still go to tf. A listener's buffer keeps a frame's transforms for
// its cache time after the newest (tf2's default: 10 s) and drops, each with a warning, one older
// than that (TF_OLD_DATA) and a second one at a stamp it holds (TF_REPEATED_DATA). The node sends
// map -> odom at each handled scan's stamp and, post-dated, on a timer: both go through one guard.
#pragma once

#include <cstdint>
#include <set>

namespace evidential_slam {
namespace ros_adapter {

class TfStampGuard {
 public:
  explicit TfStampGuard(int64_t cache_ns) : cache_ns_(cache_ns) {}

  // True (and remembered) when a transform stamped `stamp_ns` would be kept by a listener that
  // received every admitted one: not older than the newest admitted minus the cache time, and
  // not at an admitted stamp.
  bool admit(int64_t stamp_ns) {
    if (!sent_.empty() && stamp_ns < *sent_.rbegin() - cache_ns_) return false;
    if (!sent_.insert(stamp_ns).second) return false;
    const int64_t oldest = *sent_.rbegin() - cache_ns_;
    sent_.erase(sent_.begin(), sent_.lower_bound(oldest));
    return true;
  }

  // Forgets every stamp (time jumped back: listeners cleared their buffers).
  void clear() { sent_.clear(); }

 private:
  int64_t cache_ns_;
  std::set<int64_t> sent_;  // admitted stamps within the cache time of the newest
};

}  // namespace ros_adapter
}  // namespace evidential_slam
