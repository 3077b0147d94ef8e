#include "evidential_slam/core/motion_model.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {

Rng Rng::forStream(uint64_t seed, uint64_t a, uint64_t b) {
  Rng mix(seed ^ 0x9E3779B97F4A7C15ull);
  const uint64_t s1 = mix() ^ (a * 0xBF58476D1CE4E5B9ull);
  Rng mix2(s1);
  return Rng(mix2() ^ (b * 0x94D049BB133111EBull));
}

Rng::result_type Rng::operator()() {
  uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double Rng::uniform() { return static_cast<double>((*this)() >> 11) * 0x1.0p-53; }

double Rng::gaussian() {
  // Box-Muller; one value per call keeps the stream simple to reason about.
  double u1 = uniform();
  while (u1 <= 0.0) u1 = uniform();
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

namespace {

// The increment as rotate-translate-rotate; driving backwards is a negative translation, not a
// half turn.
struct OdometrySplit {
  double rot1, trans, rot2;
};
OdometrySplit split(const Pose2& increment) {
  double trans = std::hypot(increment.x, increment.y);
  double rot1 = trans > 1e-3 ? std::atan2(increment.y, increment.x) : 0.0;
  if (std::abs(rot1) > M_PI_2) {
    rot1 = normalizeAngle(rot1 + M_PI);
    trans = -trans;
  }
  return {rot1, trans, normalizeAngle(increment.theta - rot1)};
}

double translationSigma(const OdometrySplit& s, const MotionModelConfig& c) {
  return std::sqrt(c.alpha_trans_trans * s.trans * s.trans +
                   c.alpha_trans_rot * (s.rot1 * s.rot1 + s.rot2 * s.rot2) +
                   c.min_sigma_xy * c.min_sigma_xy);
}

}  // namespace

double alongTrackLogPrior(const Pose2& previous, const Pose2& reached, const Pose2& increment,
                          const MotionModelConfig& config, double floor_nats) {
  const double length = std::hypot(increment.x, increment.y);
  if (length <= 1e-3) return 0.0;
  const Pose2 moved = previous.between(reached);
  const double along =
      ((moved.x - increment.x) * increment.x + (moved.y - increment.y) * increment.y) / length;
  const double sigma = translationSigma(split(increment), config);
  return -std::min(0.5 * along * along / (sigma * sigma), floor_nats);
}

Pose2 sampleMotion(const Pose2& previous, const Pose2& increment, const MotionModelConfig& c,
                   Rng* rng) {
  const OdometrySplit s = split(increment);
  const double t2 = s.trans * s.trans, r1 = s.rot1 * s.rot1, r2 = s.rot2 * s.rot2;
  const double sd_rot1 = std::sqrt(c.alpha_rot_rot * r1 + c.alpha_rot_trans * t2 +
                                   c.min_sigma_theta * c.min_sigma_theta);
  const double sd_trans = translationSigma(s, c);
  const double sd_rot2 = std::sqrt(c.alpha_rot_rot * r2 + c.alpha_rot_trans * t2 +
                                   c.min_sigma_theta * c.min_sigma_theta);
  const double rot1_hat = s.rot1 + sd_rot1 * rng->gaussian();
  const double trans_hat = s.trans + sd_trans * rng->gaussian();
  const double rot2_hat = s.rot2 + sd_rot2 * rng->gaussian();
  const Pose2 noisy(trans_hat * std::cos(rot1_hat), trans_hat * std::sin(rot1_hat),
                    rot1_hat + rot2_hat);
  return previous.compose(noisy);
}

void driftSigmas(const Pose2& increment, const OdometryDrift& d, double* sd_rot1, double* sd_trans,
                 double* sd_rot2) {
  const OdometrySplit s = split(increment);
  const double t = std::abs(s.trans), r1 = std::abs(s.rot1), r2 = std::abs(s.rot2);
  const double floor_a = d.min_sigma_theta * d.min_sigma_theta;
  *sd_rot1 = std::sqrt(d.rot_rot * r1 + 0.5 * d.rot_trans * t + floor_a);
  *sd_trans =
      std::sqrt(d.trans_trans * t + d.trans_rot * (r1 + r2) + d.min_sigma_xy * d.min_sigma_xy);
  *sd_rot2 = std::sqrt(d.rot_rot * r2 + 0.5 * d.rot_trans * t + floor_a);
}

Pose2 sampleDrift(const Pose2& previous, const Pose2& increment, const OdometryDrift& d, Rng* rng) {
  const OdometrySplit s = split(increment);
  double sd_rot1, sd_trans, sd_rot2;
  driftSigmas(increment, d, &sd_rot1, &sd_trans, &sd_rot2);
  const double rot1_hat = s.rot1 + sd_rot1 * rng->gaussian();
  const double trans_hat = s.trans + sd_trans * rng->gaussian();
  const double rot2_hat = s.rot2 + sd_rot2 * rng->gaussian();
  return previous.compose(
      Pose2(trans_hat * std::cos(rot1_hat), trans_hat * std::sin(rot1_hat), rot1_hat + rot2_hat));
}

}  // namespace evidential_slam
