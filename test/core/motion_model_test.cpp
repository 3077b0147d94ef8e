// Tests of the random stream and the odometry motion model (motion_model.h). The model is
// Probabilistic Robotics' sample_motion_model_odometry: the increment is split into
// rot1 = atan2(dy, dx), trans = |(dx, dy)|, rot2 = dθ - rot1, with noise variances
//   rot1: α_rr rot1² + α_rt trans²,  trans: α_tt trans² + α_tr (rot1² + rot2²),
//   rot2: α_rr rot2² + α_rt trans²  (plus the small min_sigma floors).
// Expected moments below are derived by hand from that model, with the α values set explicitly
// (kAlphas) so that retuning the shipped defaults does not change the test.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "evidential_slam/core/motion_model.h"

namespace evidential_slam {
namespace {

constexpr double kPi = 3.14159265358979323846;

// α_rr = 0.05, α_rt = 0.02, α_tt = 0.05, α_tr = 0.02, floors 0.005 m / 0.002 rad.
MotionModelConfig kAlphas() {
  MotionModelConfig c;
  c.alpha_rot_rot = 0.05;
  c.alpha_rot_trans = 0.02;
  c.alpha_trans_trans = 0.05;
  c.alpha_trans_rot = 0.02;
  c.min_sigma_xy = 0.005;
  c.min_sigma_theta = 0.002;
  return c;
}

// Same seed, same stream; different streams differ.
TEST(RngTest, Deterministic) {
  Rng a(42), b(42), c(43);
  bool all_equal_c = true;
  for (int i = 0; i < 100; ++i) {
    const uint64_t va = a(), vb = b(), vc = c();
    EXPECT_EQ(va, vb);
    all_equal_c = all_equal_c && (va == vc);
  }
  EXPECT_FALSE(all_equal_c);
  Rng s1 = Rng::forStream(1, 2, 3), s2 = Rng::forStream(1, 2, 3), s3 = Rng::forStream(1, 2, 4);
  const uint64_t v1 = s1(), v2 = s2(), v3 = s3();
  EXPECT_EQ(v1, v2);
  EXPECT_NE(v1, v3);
}

// uniform() lies in [0, 1) with mean 1/2 and variance 1/12; gaussian() has mean 0 and variance 1.
// With N = 200000 the standard error of the mean is 0.289/447 = 6.5e-4 (uniform) and
// 1/447 = 2.2e-3 (gaussian); tolerances are > 4 standard errors.
TEST(RngTest, Moments) {
  Rng rng(7);
  const int n = 200000;
  double su = 0, suu = 0, sg = 0, sgg = 0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    su += u;
    suu += u * u;
    const double g = rng.gaussian();
    ASSERT_TRUE(std::isfinite(g));
    sg += g;
    sgg += g * g;
  }
  EXPECT_NEAR(su / n, 0.5, 3e-3);
  EXPECT_NEAR(suu / n - (su / n) * (su / n), 1.0 / 12.0, 1e-3);
  EXPECT_NEAR(sg / n, 0.0, 1e-2);
  EXPECT_NEAR(sgg / n - (sg / n) * (sg / n), 1.0, 1.5e-2);
}

// Without noise (all α and floors 0) the sample is exactly previous ⊕ increment, also driving
// backwards: (1,2,90°) ⊕ (1,0,0) = (1,3,90°); (1,2,90°) ⊕ (-1,0,0) = (1,1,90°);
// (0,0,0) ⊕ (1,1,90°) = (1,1,90°).
TEST(MotionModelTest, NoNoiseIsComposition) {
  MotionModelConfig c;
  c.alpha_rot_rot = c.alpha_rot_trans = c.alpha_trans_trans = c.alpha_trans_rot = 0.0;
  c.min_sigma_xy = c.min_sigma_theta = 0.0;
  Rng rng(3);
  Pose2 p = sampleMotion(Pose2(1, 2, kPi / 2), Pose2(1, 0, 0), c, &rng);
  EXPECT_NEAR(p.x, 1.0, 1e-12);
  EXPECT_NEAR(p.y, 3.0, 1e-12);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-12);
  p = sampleMotion(Pose2(1, 2, kPi / 2), Pose2(-1, 0, 0), c, &rng);
  EXPECT_NEAR(p.x, 1.0, 1e-12);
  EXPECT_NEAR(p.y, 1.0, 1e-12);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-12);
  p = sampleMotion(Pose2(0, 0, 0), Pose2(1, 1, kPi / 2), c, &rng);
  EXPECT_NEAR(p.x, 1.0, 1e-12);
  EXPECT_NEAR(p.y, 1.0, 1e-12);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-12);
}

// kAlphas noise, 1 m straight ahead from (0,0,90°): rot1 = rot2 = 0, trans = 1, so
// σ_rot1 = σ_rot2 = sqrt(0.02 + 0.002²) = 0.14143550, σ_trans = sqrt(0.05 + 0.005²) = 0.22366269.
// Heading = rot1 + rot2 noise: σ_θ = sqrt(2) * 0.14143550 = 0.20002000, mean 90°.
// Along track (world y) = (1 + n_t) cos n_r1: mean = exp(-σ_rot1²/2) = 0.99004785.
// Across track (world -x) = (1 + n_t) sin n_r1: mean 0, σ = sqrt((1 + σ_t²)(1 - e^{-2σ_r1²})/2)
// = 0.14349240. N = 40000: tolerances > 4 standard errors.
TEST(MotionModelTest, NoiseMomentsForStraightMotion) {
  const MotionModelConfig c = kAlphas();
  Rng rng(11);
  const int n = 40000;
  double sx = 0, sxx = 0, sy = 0, sth = 0, sthth = 0;
  for (int i = 0; i < n; ++i) {
    const Pose2 p = sampleMotion(Pose2(0, 0, kPi / 2), Pose2(1, 0, 0), c, &rng);
    sx += p.x;
    sxx += p.x * p.x;
    sy += p.y;
    const double dth = p.theta - kPi / 2;
    sth += dth;
    sthth += dth * dth;
  }
  const double mx = sx / n, my = sy / n, mth = sth / n;
  EXPECT_NEAR(my, 0.99004785, 5e-3);
  EXPECT_NEAR(mx, 0.0, 3e-3);
  EXPECT_NEAR(std::sqrt(sxx / n - mx * mx), 0.14349240, 5e-3);
  EXPECT_NEAR(mth, 0.0, 5e-3);
  EXPECT_NEAR(std::sqrt(sthth / n - mth * mth), 0.20002000, 6e-3);
}

// Pure rotation of 90° in place: trans = 0, rot1 = 0 (no direction), rot2 = 90°:
// σ_rot2 = sqrt(0.05 (π/2)² + 0.002²) = 0.35124, σ_trans = sqrt(0.02 (π/2)² + 0.005²) = 0.22220;
// heading mean 90°, heading σ = sqrt(σ_rot1² + σ_rot2²) = sqrt(0.002² + 0.35124²) = 0.35125.
TEST(MotionModelTest, NoiseMomentsForPureRotation) {
  const MotionModelConfig c = kAlphas();
  Rng rng(5);
  const int n = 40000;
  double sth = 0, sthth = 0, sr2 = 0;
  for (int i = 0; i < n; ++i) {
    const Pose2 p = sampleMotion(Pose2(0, 0, 0), Pose2(0, 0, kPi / 2), c, &rng);
    const double dth = p.theta - kPi / 2;  // no wrap: |dth| stays far below π
    sth += dth;
    sthth += dth * dth;
    sr2 += p.x * p.x + p.y * p.y;
  }
  EXPECT_NEAR(sth / n, 0.0, 8e-3);
  EXPECT_NEAR(std::sqrt(sthth / n - (sth / n) * (sth / n)), 0.35125, 0.012);
  // E[x² + y²] = E[trans_hat²] = σ_trans² = 0.02 (π/2)² + 0.005² = 0.04937;
  EXPECT_NEAR(sr2 / n, 0.04937, 2.5e-3);
}

// The weights' along-track prior: -½ (e/σ_trans)² for the deviation e along the odometry's
// direction of travel, floored. kAlphas, 1 m straight: σ² = α_tt · 1² + 0.005² = 0.050025.
TEST(MotionModelTest, AlongTrackLogPrior) {
  const MotionModelConfig c = kAlphas();
  const double var = 0.05 + 0.005 * 0.005;
  const Pose2 start(2.0, 1.0, kPi / 2);  // facing +y: "along" is +y in the world
  const Pose2 ahead(1.0, 0.0, 0.0);
  // 0.1 m further than the odometry said, 0.3 m off to the side, turned: only the 0.1 counts.
  EXPECT_NEAR(alongTrackLogPrior(start, Pose2(1.7, 2.1, 1.0), ahead, c, 3.0), -0.5 * 0.01 / var,
              1e-12);
  EXPECT_NEAR(alongTrackLogPrior(start, start.compose(ahead), ahead, c, 3.0), 0.0, 1e-12);
  // 1 m short (no translation at all): -½ · 1 / 0.050025 = -9.99, floored at -3.
  EXPECT_DOUBLE_EQ(alongTrackLogPrior(start, start, ahead, c, 3.0), -3.0);
  EXPECT_NEAR(alongTrackLogPrior(start, start, ahead, c, 100.0), -0.5 / var, 1e-9);
  // Backwards 1 m, reached 1.1 m back: 0.1 m along the reversed direction. The split makes this a
  // translation of -1 with no rotation, so σ is the same.
  EXPECT_NEAR(alongTrackLogPrior(Pose2(), Pose2(-1.1, 0.0, 0.0), Pose2(-1.0, 0.0, 0.0), c, 3.0),
              -0.5 * 0.01 / var, 1e-12);
  // A turn on the spot has no direction of travel: nothing to score.
  EXPECT_EQ(alongTrackLogPrior(Pose2(), Pose2(0.5, 0.0, 0.3), Pose2(0.0, 0.0, 0.3), c, 3.0), 0.0);
}

// The localizer's drift (sampleDrift): variances linear in the motion. rot_rot 0.04 rad²/rad,
// rot_trans 0.02 rad²/m, trans_trans 0.01 m²/m, trans_rot 0.03 m²/rad, no floors.
OdometryDrift kDrift() {
  OdometryDrift d;
  d.rot_rot = 0.04;
  d.rot_trans = 0.02;
  d.trans_trans = 0.01;
  d.trans_rot = 0.03;
  return d;
}

// By hand: 1 m straight (rot1 = rot2 = 0, trans = 1): σ_rot1 = σ_rot2 = √(0.02 · 1 / 2) = 0.1,
// σ_trans = √(0.01 · 1) = 0.1. A quarter turn on the spot (rot1 = 0, trans = 0, rot2 = π/2):
// σ_rot1 = 0, σ_rot2 = √(0.04 · π/2) = 0.250663, σ_trans = √(0.03 · π/2) = 0.217080. Floors add
// in quadrature: σ_rot1 = √(0 + 0.002²) = 0.002.
TEST(MotionModelTest, DriftSigmasByHand) {
  double r1, t, r2;
  driftSigmas(Pose2(1.0, 0.0, 0.0), kDrift(), &r1, &t, &r2);
  EXPECT_NEAR(r1, 0.1, 1e-12);
  EXPECT_NEAR(t, 0.1, 1e-12);
  EXPECT_NEAR(r2, 0.1, 1e-12);
  driftSigmas(Pose2(0.0, 0.0, kPi / 2), kDrift(), &r1, &t, &r2);
  EXPECT_NEAR(r1, 0.0, 1e-12);
  EXPECT_NEAR(t, 0.217080, 1e-6);
  EXPECT_NEAR(r2, 0.250663, 1e-6);
  OdometryDrift floored = kDrift();
  floored.min_sigma_theta = 0.002;
  driftSigmas(Pose2(0.0, 0.0, kPi / 2), floored, &r1, &t, &r2);
  EXPECT_NEAR(r1, 0.002, 1e-12);
}

// A motion sampled in two halves spreads as much as in one step: the heading's variance after
// 1 m straight is σ_rot1² + σ_rot2² = 0.02 either way (two halves: 2 · 0.02 · 0.5 = 0.02). The
// square-law model (sampleMotion, α_rt = 0.02 rad²/m²) gives 2 · 0.02 · 1² = 0.04 in one step and
// 2 · 2 · 0.02 · 0.5² = 0.02 in two: its spread per metre halves when the steps do. N = 40000:
// the variance's standard error is 0.02 · √(2/N) = 1.4e-4; tolerance 7e-4.
TEST(MotionModelTest, DriftSpreadsTheSameWhateverTheStep) {
  const int n = 40000;
  const auto headingVariance = [&](int steps, bool drift) {
    MotionModelConfig square;
    square.alpha_rot_rot = square.alpha_trans_trans = square.alpha_trans_rot = 0.0;
    square.alpha_rot_trans = 0.02;
    square.min_sigma_xy = square.min_sigma_theta = 0.0;
    Rng rng(11);
    double s = 0.0, ss = 0.0;
    for (int i = 0; i < n; ++i) {
      Pose2 p;
      for (int k = 0; k < steps; ++k) {
        const Pose2 step(1.0 / steps, 0.0, 0.0);
        p = drift ? sampleDrift(p, step, kDrift(), &rng) : sampleMotion(p, step, square, &rng);
      }
      s += p.theta;
      ss += p.theta * p.theta;
    }
    return ss / n - (s / n) * (s / n);
  };
  EXPECT_NEAR(headingVariance(1, true), 0.02, 7e-4);
  EXPECT_NEAR(headingVariance(2, true), 0.02, 7e-4);
  EXPECT_NEAR(headingVariance(5, true), 0.02, 7e-4);
  EXPECT_NEAR(headingVariance(1, false), 0.04, 1.4e-3);
  EXPECT_NEAR(headingVariance(2, false), 0.02, 7e-4);
}

}  // namespace
}  // namespace evidential_slam
