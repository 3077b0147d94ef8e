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

// Odometry drift as a random walk: each part's variance grows linearly with the motion (per
// radian turned, per metre driven), so a motion sampled in n steps spreads as much as in one, the
// way wheel slip accumulates; sampleMotion's variances grow with the square of each step, so its
// spread per metre shrinks with the update gate. Used to sample raw odometry (localization).
struct OdometryDrift {
  double rot_rot = 0.0;      // rad^2 of heading per rad turned
  double rot_trans = 0.0;    // rad^2 of heading per m driven
  double trans_trans = 0.0;  // m^2 along the track per m driven
  double trans_rot = 0.0;    // m^2 along the track per rad turned
  double min_sigma_xy = 0.0;
  double min_sigma_theta = 0.0;
};
// The standard deviations of rot1, trans and rot2 for `increment` (rotate-translate-rotate):
// rot_i: rot_rot |rot_i| + rot_trans |trans| / 2, trans: trans_trans |trans| + trans_rot (|rot1| +
// |rot2|), each with its floor squared added.
void driftSigmas(const Pose2& increment, const OdometryDrift& drift, double* sd_rot1,
                 double* sd_trans, double* sd_rot2);
Pose2 sampleDrift(const Pose2& previous, const Pose2& increment, const OdometryDrift& drift,
                  Rng* rng);

}  // namespace evidential_slam
