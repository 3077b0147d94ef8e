// The evidential likelihood field (core/localization): plausible ends, distances and likelihoods
// by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "evidential_slam/core/localization/likelihood_field.h"

namespace evidential_slam {
namespace {

// A 10 x 5 strip of confidently empty cells (m(e) = 0.9; resolution 0.1 m) holding: a hole never
// observed at (3, 2) (not a plausible end: see likelihood_field.h), an occupied cell at (8, 2), a
// conflicting cell at (1, 4) (m~(e) = 0.9 and lambda = 1: m(e) = 0.9 e^-1 = 0.33), one at (5, 0)
// with m(e) = 0.5 exactly (Pl(o) = 0.5) and one at (6, 4) with m(e) = 0.6 and the rest on Theta
// (Pl(o) = 0.4, not a plausible end).
EvidentialGridMap strip() {
  EvidentialGridMap map(0.1);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 10; ++x) {
      if (x == 3 && y == 2) continue;
      map.mutableCell(x, y).setMasses(0.0f, 0.9f);
    }
  }
  map.mutableCell(8, 2).setMasses(0.9f, 0.0f);
  map.mutableCell(1, 4).setLambda(1.0f);
  map.mutableCell(5, 0).setMasses(0.0f, 0.5f);
  map.mutableCell(6, 4).setMasses(0.0f, 0.6f);
  return map;
}

TEST(LikelihoodField, PlausibleEndsAreTheCellsNotConfidentlyEmpty) {
  const EvidentialGridMap map = strip();
  EXPECT_FALSE(LikelihoodField::plausibleEnd(map.cell(3, 2)));  // never observed
  EXPECT_TRUE(LikelihoodField::plausibleEnd(map.cell(8, 2)));   // occupied
  EXPECT_TRUE(LikelihoodField::plausibleEnd(map.cell(1, 4)));   // conflicting
  EXPECT_TRUE(LikelihoodField::plausibleEnd(map.cell(5, 0)));   // Pl(o) = 1/2
  EXPECT_FALSE(LikelihoodField::plausibleEnd(map.cell(6, 4)));  // Pl(o) = 0.4
  EXPECT_FALSE(LikelihoodField::plausibleEnd(map.cell(0, 0)));  // Pl(o) = 0.1
}

// Distances between cell centres to the nearest of (8, 2), (1, 4), (5, 0), in metres: (0, 0):
// sqrt(1 + 16) 0.1 = 0.4123 (to (1, 4)); (9, 4): sqrt(1 + 4) 0.1 = 0.2236 (to (8, 2)); (6, 4):
// sqrt(4 + 4) 0.1 = 0.2828 (to (8, 2)); (0, 2): sqrt(1 + 4) 0.1 (to (1, 4)); (5, 1): 0.1; the
// unobserved hole (3, 2): sqrt(4 + 4) 0.1 (to (1, 4) and (5, 0)).
TEST(LikelihoodField, DistancesByHandAndTheCap) {
  const EvidentialGridMap map = strip();
  const LikelihoodField field(map, 2.0);
  const auto at = [&](int x, int y) { return field.distance((x + 0.5) * 0.1, (y + 0.5) * 0.1); };
  EXPECT_NEAR(at(0, 0), 0.41231, 1e-5);
  EXPECT_NEAR(at(9, 4), 0.22361, 1e-5);
  EXPECT_NEAR(at(6, 4), 0.28284, 1e-5);
  EXPECT_NEAR(at(0, 2), 0.22361, 1e-5);
  EXPECT_NEAR(at(5, 1), 0.1, 1e-6);
  EXPECT_EQ(at(8, 2), 0.0);
  EXPECT_NEAR(at(3, 2), 0.28284, 1e-5);
  // Off the observed box: the cap.
  EXPECT_EQ(field.distance(-0.05, 0.25), 2.0);
  EXPECT_EQ(field.distance(0.25, 0.55), 2.0);
  // A cap of 0.25 m.
  const LikelihoodField capped(map, 0.25);
  EXPECT_EQ(capped.distance(0.05, 0.05), 0.25);
  EXPECT_EQ(capped.distance(0.65, 0.45), 0.25);
  EXPECT_NEAR(capped.distance(0.95, 0.45), 0.22361, 1e-5);
  EXPECT_EQ(capped.distance(100.0, 0.0), 0.25);
  EXPECT_THROW(LikelihoodField(map, 0.0), std::invalid_argument);
}

// From (0.05, 0.25) (cell (0, 2)) facing +x, three beams, sigma_hit 0.2, z_hit 0.95, z_rand 0.05,
// range_max 10: ahead 0.8 m ends on the occupied cell (d = 0): 0.95 + 0.005 = 0.955; left 0.2 m
// ends in (0, 4), 0.1 m from (1, 4): 0.95 e^(-0.01/0.08) + 0.005 = 0.843372; behind 1 m ends off
// the map (d = 2): 0.95 e^-50 + 0.005 = 0.005. Σ ln = -5.514708.
TEST(LikelihoodField, LogLikelihoodByHand) {
  const LikelihoodField field(strip(), 2.0);
  LaserScan beams;
  beams.max_range = 10.0f;
  beams.ranges = {0.8f, 0.2f, 1.0f};
  beams.bearings = {0.0f, static_cast<float>(M_PI / 2), static_cast<float>(M_PI)};
  beams.valid = {1, 1, 1};
  EXPECT_NEAR(field.logLikelihood(Pose2(0.05, 0.25, 0.0), beams, 0.2, 0.95, 0.05), -5.514708,
              1e-5);
  // The same beams turned with the pose: the sensor's heading applies.
  LaserScan turned = beams;
  for (float& b : turned.bearings) b -= static_cast<float>(M_PI / 2);
  EXPECT_NEAR(field.logLikelihood(Pose2(0.05, 0.25, M_PI / 2), turned, 0.2, 0.95, 0.05),
              -5.514708, 1e-5);
  // amcl's weight of the same beams: 1 + 0.955^3 + 0.843372^3 + 0.005^3 = 2.470855.
  const FieldScore score = field.score(Pose2(0.05, 0.25, 0.0), beams, 0.2, 0.95, 0.05);
  EXPECT_NEAR(score.amcl_weight, 2.470855, 1e-6);
  EXPECT_NEAR(score.log_likelihood, -5.514708, 1e-5);
  // The beam off the map costs the product a factor 0.005 but amcl's weight only 0.005^3: without
  // it the weight is 2.470855 - 1.25e-7, with it at d = 0 it would be 2.470855 + 0.870984.
  LaserScan two = beams;
  two.ranges.pop_back();
  two.bearings.pop_back();
  two.valid.pop_back();
  EXPECT_NEAR(field.score(Pose2(0.05, 0.25, 0.0), two, 0.2, 0.95, 0.05).amcl_weight,
              2.470855 - 1.25e-7, 1e-6);
  // Without the random part a beam far off has likelihood ~0: floored, finite.
  const double no_rand = field.logLikelihood(Pose2(0.05, 0.25, 0.0), beams, 0.01, 1.0, 0.0);
  EXPECT_TRUE(std::isfinite(no_rand));
  EXPECT_LT(no_rand, -700.0);
}

}  // namespace
}  // namespace evidential_slam
