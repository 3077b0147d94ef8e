// Tests of the absolute trajectory error (metrics.h): association by nearest timestamp, SE(2)
// alignment (rotation + translation, no scale) and RMSE, with hand-derived expected values.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"

namespace evidential_slam {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A non-degenerate (not collinear) trajectory: x = 0.5 i, y = 2 sin(0.3 i), one pose per second.
std::vector<StampedPose> makeTruth(int n) {
  std::vector<StampedPose> t;
  for (int i = 0; i < n; ++i) {
    t.push_back({static_cast<double>(i), Pose2(0.5 * i, 2.0 * std::sin(0.3 * i), 0.1 * i)});
  }
  return t;
}

// Identical trajectories: every pose matches, RMSE = max error = 0, alignment = identity.
TEST(AteTest, IdenticalTrajectoriesGiveZero) {
  const auto truth = makeTruth(20);
  AteResult r;
  std::string why;
  ASSERT_TRUE(computeAte(truth, truth, 0.01, &r, &why)) << why;
  EXPECT_EQ(r.matched, 20u);
  EXPECT_NEAR(r.rmse, 0.0, 1e-9);
  EXPECT_NEAR(r.max_error, 0.0, 1e-9);
  EXPECT_NEAR(r.alignment.x, 0.0, 1e-9);
  EXPECT_NEAR(r.alignment.y, 0.0, 1e-9);
  EXPECT_NEAR(r.alignment.theta, 0.0, 1e-9);
}

// Estimate = T ⊕ truth with T = (2, -1, 30°): the alignment removes it exactly, RMSE ≈ 0, and the
// alignment (estimate -> truth) is T⁻¹ = (-R^T t, -30°) = (-(cos30*2 - sin30), -(-sin30*2 - cos30))
// = (-1.23205081, 1.86602540, -π/6).
TEST(AteTest, RigidlyMovedEstimateAlignsToZero) {
  const auto truth = makeTruth(20);
  const Pose2 t(2.0, -1.0, kPi / 6);
  std::vector<StampedPose> estimate;
  for (const auto& p : truth) estimate.push_back({p.stamp, t.compose(p.pose)});
  AteResult r;
  std::string why;
  ASSERT_TRUE(computeAte(estimate, truth, 0.01, &r, &why)) << why;
  EXPECT_EQ(r.matched, 20u);
  EXPECT_NEAR(r.rmse, 0.0, 1e-6);
  EXPECT_NEAR(r.max_error, 0.0, 1e-6);
  EXPECT_NEAR(r.alignment.x, -1.23205080756888, 1e-6);
  EXPECT_NEAR(r.alignment.y, 1.86602540378444, 1e-6);
  EXPECT_NEAR(r.alignment.theta, -kPi / 6, 1e-6);
}

// Truth P = (-1,0), (1,0), (0,0); the estimate moves only the middle point by d = 0.3 in y.
// Centroids: truth (0,0), estimate (0, d/3). Centred estimate (-1,-d/3), (1,-d/3), (0,2d/3) vs
// centred truth (-1,0), (1,0), (0,0): Σ q·p = 2, Σ q×p = (-d/3) + (d/3) + 0 = 0 -> best rotation 0,
// translation -d/3. Residuals d/3, d/3, 2d/3: RMSE = sqrt((1 + 1 + 4) d²/9 / 3) = d sqrt(2)/3
// = 0.14142136, max error = 2d/3 = 0.2.
TEST(AteTest, OffsetInOnePointGivesHandComputedRmse) {
  const double d = 0.3;
  const std::vector<StampedPose> truth = {
      {0.0, Pose2(-1, 0, 0)}, {1.0, Pose2(1, 0, 0)}, {2.0, Pose2(0, 0, 0)}};
  const std::vector<StampedPose> estimate = {
      {0.0, Pose2(-1, 0, 0)}, {1.0, Pose2(1, 0, 0)}, {2.0, Pose2(0, d, 0)}};
  AteResult r;
  std::string why;
  ASSERT_TRUE(computeAte(estimate, truth, 0.1, &r, &why)) << why;
  EXPECT_EQ(r.matched, 3u);
  EXPECT_NEAR(r.rmse, 0.14142135623731, 1e-9);
  EXPECT_NEAR(r.max_error, 0.2, 1e-9);
  EXPECT_NEAR(r.alignment.theta, 0.0, 1e-9);
  EXPECT_NEAR(r.alignment.x, 0.0, 1e-9);
  EXPECT_NEAR(r.alignment.y, -0.1, 1e-9);
}

// A constant translation of the whole estimate is removed completely by the alignment.
TEST(AteTest, ConstantOffsetEverywhereIsAlignedAway) {
  const auto truth = makeTruth(10);
  std::vector<StampedPose> estimate = truth;
  for (auto& p : estimate) {
    p.pose.x += 3.0;
    p.pose.y -= 4.0;
  }
  AteResult r;
  std::string why;
  ASSERT_TRUE(computeAte(estimate, truth, 0.01, &r, &why)) << why;
  EXPECT_NEAR(r.rmse, 0.0, 1e-9);
  EXPECT_NEAR(r.alignment.x, -3.0, 1e-9);
  EXPECT_NEAR(r.alignment.y, 4.0, 1e-9);
}

// Fewer than two associated pairs: false with a reason.
TEST(AteTest, FewerThanTwoMatchesFails) {
  const auto truth = makeTruth(10);
  AteResult r;
  std::string why;
  // One estimate pose only.
  EXPECT_FALSE(computeAte({truth[3]}, truth, 0.1, &r, &why));
  EXPECT_FALSE(why.empty());
  // Two estimate poses, but only one within max_dt (stamp 5.5 is 0.5 s from any truth pose).
  why.clear();
  EXPECT_FALSE(computeAte({truth[2], {5.5, Pose2(1, 1, 0)}}, truth, 0.1, &r, &why));
  EXPECT_FALSE(why.empty());
  // Empty inputs.
  why.clear();
  EXPECT_FALSE(computeAte({}, truth, 0.1, &r, &why));
  EXPECT_FALSE(why.empty());
  why.clear();
  EXPECT_FALSE(computeAte(truth, {}, 0.1, &r, &why));
  EXPECT_FALSE(why.empty());
}

// Association by the nearest truth stamp within max_dt: the estimate at t = 2.05 must pair with
// truth t = 2.08 (dt 0.03) and not t = 2.0 (dt 0.05). With the right pairing every estimate equals
// its truth and RMSE = 0; the wrong pairing ((5,5) vs (2,1)) cannot be aligned to zero because
// the distances between points differ (|(1,0)-(5,5)| = 6.40 vs |(1,0)-(2,1)| = 1.41).
// The estimate at t = 3.5 is 0.5 s from its nearest truth (t = 4.0) and is dropped: 3 matches.
TEST(AteTest, AssociatesNearestTimestampWithinMaxDt) {
  const std::vector<StampedPose> truth = {{0.0, Pose2(0, 0, 0)},
                                          {1.0, Pose2(1, 0, 0)},
                                          {2.0, Pose2(2, 1, 0)},
                                          {2.08, Pose2(5, 5, 0)},
                                          {4.0, Pose2(9, 9, 0)}};
  const std::vector<StampedPose> estimate = {{0.02, Pose2(0, 0, 0)},
                                             {0.97, Pose2(1, 0, 0)},
                                             {2.05, Pose2(5, 5, 0)},
                                             {3.5, Pose2(-7, 3, 0)}};
  AteResult r;
  std::string why;
  ASSERT_TRUE(computeAte(estimate, truth, 0.1, &r, &why)) << why;
  EXPECT_EQ(r.matched, 3u);
  EXPECT_NEAR(r.rmse, 0.0, 1e-9);
  EXPECT_NEAR(r.max_error, 0.0, 1e-9);
}

// Stamps offset by less than max_dt still match; the same offset beyond max_dt matches nothing.
TEST(AteTest, MaxDtIsRespected) {
  const auto truth = makeTruth(10);
  std::vector<StampedPose> estimate = truth;
  for (auto& p : estimate) p.stamp += 0.04;
  AteResult r;
  std::string why;
  ASSERT_TRUE(computeAte(estimate, truth, 0.05, &r, &why)) << why;
  EXPECT_EQ(r.matched, 10u);
  EXPECT_NEAR(r.rmse, 0.0, 1e-9);
  why.clear();
  EXPECT_FALSE(computeAte(estimate, truth, 0.03, &r, &why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace evidential_slam
