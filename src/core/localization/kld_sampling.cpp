#include "evidential_slam/core/localization/kld_sampling.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {

size_t kldSampleLimit(size_t bins, double err, double z, size_t min_particles,
                      size_t max_particles) {
  if (bins <= 1) return min_particles;
  const double k = static_cast<double>(bins) - 1.0;
  const double b = 2.0 / (9.0 * k);
  const double x = 1.0 - b + std::sqrt(b) * z;
  const double n = std::ceil(k / (2.0 * err) * x * x * x);
  if (!(n < static_cast<double>(max_particles))) return max_particles;
  return std::max(min_particles, static_cast<size_t>(n));
}

uint64_t KldBins::key(const Pose2& pose) const {
  constexpr int64_t kMask = (int64_t{1} << 21) - 1;
  const auto index = [](double v, double size) {
    return static_cast<int64_t>(std::floor(v / size)) & kMask;
  };
  return (static_cast<uint64_t>(index(pose.x, bin_xy_)) << 42) |
         (static_cast<uint64_t>(index(pose.y, bin_xy_)) << 21) |
         static_cast<uint64_t>(index(normalizeAngle(pose.theta), bin_angle_));
}

bool KldBins::insert(const Pose2& pose) { return bins_.insert(key(pose)).second; }

}  // namespace evidential_slam
