// The one policy for the order of time stamps, shared by the rawlog reader (scans and odometry),
// the mapping session and so the node: a stamp a little older than the previous one is dropped; one
// that jumped (back by more than `tolerance`, or ahead by more than `forward`) is an outlier,
// dropped once, and the stream goes on from the previous stamp; only `scans` jumps the same way
// in a row are believed (time jumped back: the caller starts over; ahead: time moves on).
#pragma once

namespace evidential_slam {

struct StampPolicy {
  double tolerance = 1.0;   // s (the session's time_jump_tolerance)
  double forward = 3600.0;  // s (time_jump_forward)
  int scans = 3;            // (time_jump_scans)
};

class StampOrder {
 public:
  enum class Verdict { kInOrder, kDropped, kOutlier, kJumpedBack, kJumpedAhead };

  explicit StampOrder(const StampPolicy& policy = {}) : policy_(policy) {}
  void setPolicy(const StampPolicy& policy) { policy_ = policy; }

  // The verdict on the next stamp (finite). The previous stamp moves to it unless it is dropped
  // or an outlier.
  Verdict next(double stamp);
  // Forgets the previous stamp: the next one is in order.
  void reset();

  bool hasLast() const { return have_last_; }
  double last() const { return last_; }                // the previous stamp kept
  int jumpsInARow() const { return jumps_in_a_row_; }  // after an outlier: 1 .. scans - 1
  const StampPolicy& policy() const { return policy_; }

 private:
  StampPolicy policy_;
  bool have_last_ = false;
  double last_ = 0.0;
  int jumps_in_a_row_ = 0;  // consecutive outlier stamps, all back or all ahead
  bool jump_back_ = false;  // their direction
};

}  // namespace evidential_slam
