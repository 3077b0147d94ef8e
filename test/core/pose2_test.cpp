// Tests of the planar pose algebra (pose2.h) on hand-worked examples.
// compose: (x1,y1,t1) ⊕ (x2,y2,t2)
//        = (x1 + cos t1 x2 - sin t1 y2, y1 + sin t1 x2 + cos t1 y2, t1 + t2).
#include <gtest/gtest.h>

#include <cmath>

#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-9;

void expectPose(const Pose2& p, double x, double y, double theta) {
  EXPECT_NEAR(p.x, x, kTol);
  EXPECT_NEAR(p.y, y, kTol);
  EXPECT_NEAR(p.theta, theta, kTol);
}

// (1,2,90°) ⊕ (3,1,45°): x = 1 + 0*3 - 1*1 = 0, y = 2 + 1*3 + 0*1 = 5, θ = 135°.
TEST(Pose2Test, ComposeQuarterTurn) {
  expectPose(Pose2(1, 2, kPi / 2).compose(Pose2(3, 1, kPi / 4)), 0.0, 5.0, 3 * kPi / 4);
}

// (2,-1,30°) ⊕ (1,1,60°): x = 2 + cos30 - sin30 = 2 + 0.8660254 - 0.5 = 2.36602540378,
// y = -1 + sin30 + cos30 = 0.36602540378, θ = 90°.
TEST(Pose2Test, ComposeThirtyDegrees) {
  expectPose(Pose2(2, -1, kPi / 6).compose(Pose2(1, 1, kPi / 3)), 2.36602540378444,
             0.36602540378444, kPi / 2);
}

// The composed heading is wrapped: 135° + 135° = 270° -> -90°.
TEST(Pose2Test, ComposeWrapsHeading) {
  expectPose(Pose2(0, 0, 3 * kPi / 4).compose(Pose2(0, 0, 3 * kPi / 4)), 0.0, 0.0, -kPi / 2);
}

// inverse(1,2,90°) = (-R^T t, -90°): R^T t = (cos90*1 + sin90*2, -sin90*1 + cos90*2) = (2, -1),
// negated (-2, 1).
// inverse(2,-1,30°): R^T t = (cos30*2 - sin30, -sin30*2 - cos30) = (1.23205081, -1.86602540),
// negated (-1.23205081, 1.86602540), θ = -30°.
TEST(Pose2Test, Inverse) {
  expectPose(Pose2(1, 2, kPi / 2).inverse(), -2.0, 1.0, -kPi / 2);
  expectPose(Pose2(2, -1, kPi / 6).inverse(), -1.23205080756888, 1.86602540378444, -kPi / 6);
  // p ⊕ p⁻¹ = identity.
  const Pose2 p(2, -1, kPi / 6);
  expectPose(p.compose(p.inverse()), 0.0, 0.0, 0.0);
  expectPose(p.inverse().compose(p), 0.0, 0.0, 0.0);
}

// between(a, b) = a⁻¹ ⊕ b. From (1,2,90°) the pose (0,5,135°) is (3,1,45°) (ComposeQuarterTurn
// reversed); from (1,1,0) the pose (3,1,90°) is (2,0,90°); from (0,0,90°) the pose (0,1,90°) is
// one metre straight ahead: (1,0,0).
TEST(Pose2Test, Between) {
  expectPose(Pose2(1, 2, kPi / 2).between(Pose2(0, 5, 3 * kPi / 4)), 3.0, 1.0, kPi / 4);
  expectPose(Pose2(1, 1, 0).between(Pose2(3, 1, kPi / 2)), 2.0, 0.0, kPi / 2);
  expectPose(Pose2(0, 0, kPi / 2).between(Pose2(0, 1, kPi / 2)), 1.0, 0.0, 0.0);
}

// transformPoint with (1,2,90°): (1,0) -> (1 - 0, 2 + 1) = (1,3); (0,2) -> (1 - 2, 2 + 0) = (-1,2).
TEST(Pose2Test, TransformPoint) {
  const Pose2 p(1, 2, kPi / 2);
  const Eigen::Vector2d a = p.transformPoint(Eigen::Vector2d(1, 0));
  EXPECT_NEAR(a.x(), 1.0, kTol);
  EXPECT_NEAR(a.y(), 3.0, kTol);
  const Eigen::Vector2d b = p.transformPoint(Eigen::Vector2d(0, 2));
  EXPECT_NEAR(b.x(), -1.0, kTol);
  EXPECT_NEAR(b.y(), 2.0, kTol);
  EXPECT_NEAR(p.translation().x(), 1.0, kTol);
  EXPECT_NEAR(p.translation().y(), 2.0, kTol);
}

// Isometry round trip: translation (1,2), rotation 0.5 rad.
TEST(Pose2Test, IsometryRoundTrip) {
  Eigen::Isometry2d iso = Eigen::Isometry2d::Identity();
  iso.translate(Eigen::Vector2d(1.0, 2.0));
  iso.rotate(0.5);
  expectPose(Pose2::fromIsometry(iso), 1.0, 2.0, 0.5);
  const Eigen::Isometry2d back = Pose2(1.0, 2.0, 0.5).toIsometry();
  EXPECT_NEAR(back.translation().x(), 1.0, kTol);
  EXPECT_NEAR(back.translation().y(), 2.0, kTol);
  EXPECT_NEAR(back.linear()(1, 0), std::sin(0.5), kTol);
  EXPECT_NEAR(back.linear()(0, 0), std::cos(0.5), kTol);
}

// normalizeAngle wraps to (-π, π]: 7 -> 7 - 2π = 0.71681469; -7 -> -0.71681469;
// 2π + 0.1 -> 0.1; -3π/2 -> π/2; 100 -> 100 - 32π = -0.53096491; -100 -> 0.53096491.
TEST(Pose2Test, NormalizeAngle) {
  EXPECT_NEAR(normalizeAngle(0.0), 0.0, kTol);
  EXPECT_NEAR(normalizeAngle(7.0), 0.71681469282041, kTol);
  EXPECT_NEAR(normalizeAngle(-7.0), -0.71681469282041, kTol);
  EXPECT_NEAR(normalizeAngle(2 * kPi + 0.1), 0.1, kTol);
  EXPECT_NEAR(normalizeAngle(-3 * kPi / 2), kPi / 2, kTol);
  EXPECT_NEAR(normalizeAngle(100.0), -0.53096491487338, kTol);
  EXPECT_NEAR(normalizeAngle(-100.0), 0.53096491487338, kTol);
  EXPECT_NEAR(normalizeAngle(1.0), 1.0, kTol);
  EXPECT_NEAR(std::fabs(normalizeAngle(3 * kPi)), kPi, kTol);  // 3π rounds to ±π
}

// The interval is half-open (-π, π]: π stays π and -π maps to π.
TEST(Pose2Test, NormalizeAngleBoundary) {
  EXPECT_NEAR(normalizeAngle(kPi), kPi, kTol);
  EXPECT_NEAR(normalizeAngle(-kPi), kPi, kTol);
  EXPECT_GT(normalizeAngle(-kPi), 0.0);
}

}  // namespace
}  // namespace evidential_slam
