// When to subscribe again to a robot's map that has not arrived: on a busy machine a latched map
// was seen never to reach a subscription whose publisher was connected, and a new subscription
// gets it. The map fusion nodelet makes it again after a wait that doubles each time (a robot that
// has not published yet costs a few warnings, not one a second). ROS-free: seconds on any clock.
#pragma once

#include <algorithm>

namespace evidential_slam {
namespace ros_adapter {

class MapWait {
 public:
  MapWait(double first_wait_s, double max_wait_s)
      : wait_s_(first_wait_s), max_wait_s_(max_wait_s) {}

  // A subscription was made at `now_s`.
  void subscribed(double now_s) { subscribed_s_ = now_s; }

  // Whether to subscribe again at `now_s`: no map yet and more than the wait since subscribing.
  // When it is, the next wait is twice this one (at most max_wait_s).
  bool resubscribeDue(double now_s, bool has_map) {
    if (has_map || now_s - subscribed_s_ <= wait_s_) return false;
    wait_s_ = std::min(2.0 * wait_s_, max_wait_s_);
    return true;
  }

  double waitedSince(double now_s) const { return now_s - subscribed_s_; }

 private:
  double wait_s_;
  double max_wait_s_;
  double subscribed_s_ = 0.0;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
