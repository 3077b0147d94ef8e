// KLD-sampling (Fox, "Adapting the sample size in particle filters through KLD-sampling", IJRR
// 2003): as particles are drawn, count the histogram bins of (x, y, heading) they fall in; k
// occupied bins ask for n(k) = (k - 1) / (2 err) · (1 - 2/(9(k - 1)) + sqrt(2/(9(k - 1))) z)³
// particles, so a spread cloud gets many and a converged one few.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_set>

#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

// n(k) of the formula above, clamped to [min_particles, max_particles]; min_particles for k <= 1,
// where the formula gives 0. (amcl asks for max_particles there; a cloud the scan matcher has
// pulled into one bin would then be the largest.)
size_t kldSampleLimit(size_t bins, double err, double z, size_t min_particles,
                      size_t max_particles);

// The bins a growing particle set occupies.
class KldBins {
 public:
  KldBins(double bin_xy, double bin_angle) : bin_xy_(bin_xy), bin_angle_(bin_angle) {}
  // Counts the bin of `pose`; true when it was not occupied yet.
  bool insert(const Pose2& pose);
  size_t count() const { return bins_.size(); }
  void clear() { bins_.clear(); }
  // The bin of `pose` as three 21-bit signed indices packed into one key.
  uint64_t key(const Pose2& pose) const;

 private:
  double bin_xy_;
  double bin_angle_;
  std::unordered_set<uint64_t> bins_;
};

}  // namespace evidential_slam
