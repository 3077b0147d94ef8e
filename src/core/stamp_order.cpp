#include "evidential_slam/core/stamp_order.h"

namespace evidential_slam {

StampOrder::Verdict StampOrder::next(double stamp) {
  Verdict verdict = Verdict::kInOrder;
  if (have_last_) {
    const double step = stamp - last_;
    const bool back = step < -policy_.tolerance;
    const bool ahead = step > policy_.forward;
    if (back || ahead) {
      if (jumps_in_a_row_ == 0 || jump_back_ != back) jumps_in_a_row_ = 0;
      jump_back_ = back;
      ++jumps_in_a_row_;
      if (jumps_in_a_row_ < policy_.scans) return Verdict::kOutlier;
      verdict = back ? Verdict::kJumpedBack : Verdict::kJumpedAhead;
    } else if (step < 0.0) {
      jumps_in_a_row_ = 0;
      return Verdict::kDropped;
    }
  }
  jumps_in_a_row_ = 0;
  have_last_ = true;
  last_ = stamp;
  return verdict;
}

void StampOrder::reset() {
  have_last_ = false;
  jumps_in_a_row_ = 0;
}

}  // namespace evidential_slam
