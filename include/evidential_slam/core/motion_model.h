// Odometry motion model: the increment is split into rotate-translate-rotate and each part gets
// Gaussian noise scaled by the motion (Probabilistic Robotics, sample_motion_model_odometry).
#pragma once

#include <cstdint>
#include <limits>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

// SplitMix64: small, fast, seedable; one stream per particle and step keeps runs reproducible
// whatever the thread scheduling.
class Rng {
 public:
  using result_type = uint64_t;
  explicit Rng(uint64_t seed) : state_(seed) {}
  static Rng forStream(uint64_t seed, uint64_t a, uint64_t b);
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<uint64_t>::max(); }
  result_type operator()();
  double uniform();   // [0, 1)
  double gaussian();  // N(0, 1)

 private:
  uint64_t state_;
};

// Log prior (up to a constant) of how far along the odometry's direction of travel a particle
// went from `previous` to `reached`: the motion model's translation Gaussian, floored at
// -floor_nats, where the odometry counts as failed (a missed or reversed translation). Across-track
// and heading deviations are not scored: the scan constrains those, and real odometry's heading
// is biased. 0 for an increment without translation.
double alongTrackLogPrior(const Pose2& previous, const Pose2& reached, const Pose2& increment,
                          const MotionModelConfig& config, double floor_nats);

// Samples x_t ~ p(x_t | x_{t-1}, u) for the odometry increment u (in the previous robot frame).
Pose2 sampleMotion(const Pose2& previous, const Pose2& increment, const MotionModelConfig& config,
                   Rng* rng);

}  // namespace evidential_slam
