// Tests of map alignment (core/fusion/alignment.h) on maps painted from synthetic worlds.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "evidential_slam/core/fusion/alignment.h"
#include "synthetic_world.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRes = 0.05;

// Robot A maps the office's west part from the world origin; robot B its east part, its map's
// frame at `b_in_world`. B's pose in A's frame is then b_in_world.
EvidentialGridMap mapA() {
  return synthetic::paint(synthetic::office(), Pose2(), {7.0, 7.0}, 9.0, kRes, 1);
}
EvidentialGridMap mapB(const Pose2& b_in_world) {
  return synthetic::paint(synthetic::office(), b_in_world, {13.0, 7.0}, 9.0, kRes, 2);
}

void expectRecovered(const Pose2& truth) {
  const EvidentialGridMap a = mapA(), b = mapB(truth);
  AlignmentResult result;
  std::string why;
  ASSERT_TRUE(alignMaps(a, b, AlignmentConfig{}, &result, &why)) << why;
  EXPECT_NEAR(result.pose.x, truth.x, kRes);
  EXPECT_NEAR(result.pose.y, truth.y, kRes);
  EXPECT_NEAR(normalizeAngle(result.pose.theta - truth.theta), 0.0, kPi / 180.0);
  EXPECT_LT(result.conflict, 0.1);
  EXPECT_GT(result.overlap_cells, 10000u);
  // A distinct alternative was found and scored clearly worse.
  EXPECT_GT(result.alternative_score, result.score / AlignmentConfig{}.ambiguity_ratio);
}

// Recovered within a cell and 1°, whatever the turn.
TEST(AlignmentTest, RecoversAKnownPose) { expectRecovered(Pose2(12.3, -4.1, 2.2)); }
TEST(AlignmentTest, RecoversAKnownPoseTurnedBackwards) { expectRecovered(Pose2(-3.0, 5.5, -2.9)); }
TEST(AlignmentTest, RecoversTheIdentity) { expectRecovered(Pose2()); }

// Every final candidate is refined below the cell before they are compared. Without ICP the
// pooled refinement stops at 0.2 m cells and a yaw step of about 1°, and the score forgives a cell
// of misregistration: the truth's score stays high, within the ambiguity band of its twins. The
// sub-cell refinement (least raw conflict per occupied evidence) brings it within a few cm.
TEST(AlignmentTest, RefinesEveryCandidateBelowTheCell) {
  for (const Pose2& truth : {Pose2(12.33, -4.12, 2.2037), Pose2(-3.07, 5.58, -2.913)}) {
    const EvidentialGridMap a = mapA(), b = mapB(truth);
    AlignmentConfig config;
    config.icp = false;
    AlignmentResult result;
    std::string why;
    ASSERT_TRUE(alignMaps(a, b, config, &result, &why)) << why;
    // The error at B's observed centre (13, 7) in the world, where the maps overlap.
    const Eigen::Vector2d c = truth.inverse().transformPoint({13.0, 7.0});
    EXPECT_LT((result.pose.transformPoint(c) - truth.transformPoint(c)).norm(), 0.03);
    EXPECT_LT(std::abs(normalizeAngle(result.pose.theta - truth.theta)), 0.2 * kPi / 180.0);
    EXPECT_LT(result.conflict, 0.1);
  }
}

// Corridors 1.8 m wide: the search's pooled cells must be fine enough that a corridor keeps free
// space after the erosion of the walls (three 0.8 m cells would not); otherwise walls on corridors
// cost nothing there and a wrong pose wins the search.
TEST(AlignmentTest, RecoversAPoseAmongNarrowCorridors) {
  const synthetic::World world = synthetic::corridors();
  const Pose2 truth(6.0, -3.0, 0.9);
  const EvidentialGridMap a = synthetic::paint(world, Pose2(), {12.0, 10.0}, 13.0, kRes, 1);
  const EvidentialGridMap b = synthetic::paint(world, truth, {24.0, 10.0}, 13.0, kRes, 2);
  AlignmentResult result;
  std::string why;
  ASSERT_TRUE(alignMaps(a, b, AlignmentConfig{}, &result, &why)) << why;
  EXPECT_NEAR(result.pose.x, truth.x, kRes);
  EXPECT_NEAR(result.pose.y, truth.y, kRes);
  EXPECT_NEAR(normalizeAngle(result.pose.theta - truth.theta), 0.0, kPi / 180.0);
  EXPECT_LT(result.conflict, 0.1);
}

// Two maps of different worlds: no pose explains their overlap.
TEST(AlignmentTest, RefusesMapsWithNoCommonStructure) {
  const EvidentialGridMap a = mapA();
  const EvidentialGridMap b =
      synthetic::paint(synthetic::clutter(5), Pose2(1.0, 2.0, 0.3), {8.0, 8.0}, 8.0, kRes, 3);
  AlignmentResult result;
  std::string why;
  EXPECT_FALSE(alignMaps(a, b, AlignmentConfig{}, &result, &why));
  EXPECT_TRUE(why.rfind("no pose explains the overlap", 0) == 0 ||
              why.rfind("ambiguous alignment", 0) == 0)
      << why;
}

// The same map of a mirror-symmetric room twice: two poses (turned by 180°) explain it equally.
TEST(AlignmentTest, RefusesAnAmbiguousAlignment) {
  synthetic::World room;
  room.min = {0.0, 0.0};
  room.max = {10.0, 6.0};
  synthetic::addBox(&room, 0, 0, 10, 6);
  room.walls.push_back({{5.0, 0.0}, {5.0, 2.0}});
  room.walls.push_back({{5.0, 6.0}, {5.0, 4.0}});
  const EvidentialGridMap a = synthetic::paint(room, Pose2(), {5.0, 3.0}, 20.0, kRes, 1);
  const EvidentialGridMap b =
      synthetic::paint(room, Pose2(2.0, 1.0, 0.5), {5.0, 3.0}, 20.0, kRes, 2);
  AlignmentResult result;
  std::string why;
  EXPECT_FALSE(alignMaps(a, b, AlignmentConfig{}, &result, &why));
  EXPECT_EQ(why.rfind("ambiguous alignment", 0), 0u) << why;
  EXPECT_GE(result.alternative_score, 0.0);
}

// A 10 m x 1 m strip and a 3 m x 3 m square: no pose puts all of the square on the strip.
TEST(AlignmentTest, RefusesTooLittleOverlap) {
  synthetic::World strip;
  strip.min = {0.0, 0.0};
  strip.max = {10.0, 1.0};
  synthetic::addBox(&strip, 0, 0, 10, 1);
  synthetic::World square;
  square.min = {0.0, 0.0};
  square.max = {3.0, 3.0};
  synthetic::addBox(&square, 0, 0, 3, 3);
  const EvidentialGridMap a = synthetic::paint(strip, Pose2(), {5.0, 0.5}, 20.0, kRes, 1);
  const EvidentialGridMap b = synthetic::paint(square, Pose2(), {1.5, 1.5}, 20.0, kRes, 2);
  AlignmentConfig config;
  config.min_overlap = 0.9;
  AlignmentResult result;
  std::string why;
  EXPECT_FALSE(alignMaps(a, b, config, &result, &why));
  EXPECT_EQ(why,
            "too little overlap: no pose puts 90 % of the smaller map's observed cells and "
            "occupied evidence on the other map");
}

// Two maps of a building a half turn maps onto itself, B's frame at `truth`, each seeing most of
// it.
struct SymmetricPair {
  EvidentialGridMap a, b;
};
SymmetricPair symmetricPair(bool furnished, const Pose2& truth) {
  const synthetic::World world = synthetic::symmetricOffice(furnished);
  return {synthetic::paint(world, Pose2(), {8.0, 6.0}, 11.0, kRes, 1),
          synthetic::paint(world, truth, {12.0, 6.0}, 11.0, kRes, 2)};
}

// The score alone cannot tell the pose from its half turn (only a pillar and a cabinet differ);
// the verifier can: at the half turn they stand in the other map's open rooms.
TEST(AlignmentTest, ConflictVerifiesAPoseTheScoreCannotTell) {
  const Pose2 truth(1.5, -0.8, 0.3);
  const SymmetricPair pair = symmetricPair(true, truth);
  AlignmentResult result;
  std::string why;
  ASSERT_TRUE(alignMaps(pair.a, pair.b, AlignmentConfig{}, &result, &why)) << why;
  EXPECT_NEAR(result.pose.x, truth.x, kRes);
  EXPECT_NEAR(result.pose.y, truth.y, kRes);
  EXPECT_NEAR(normalizeAngle(result.pose.theta - truth.theta), 0.0, kPi / 180.0);
  EXPECT_TRUE(result.decided_by_verifier);
  ASSERT_GE(result.candidates.size(), 2u);
  // The half turn is a candidate, and where it scores within the ambiguity band it contradicts
  // metres of wall the truth does not.
  const double band = result.candidates.front().score / AlignmentConfig{}.ambiguity_ratio;
  bool half_turn = false;
  std::string listed;
  for (const AlignmentResult::Candidate& c : result.candidates) {
    listed += "(" + std::to_string(c.pose.x) + ", " + std::to_string(c.pose.y) + ", " +
              std::to_string(c.pose.theta) + ") score " + std::to_string(c.score) + " share " +
              std::to_string(c.disagreement) + " wall " + std::to_string(c.contradicted_m) + "; ";
    if (std::abs(normalizeAngle(c.pose.theta - truth.theta - kPi)) < 0.05) {
      half_turn = true;
      if (c.score <= band) {
        EXPECT_GT(c.contradicted_m, 1.0);
      }
    }
  }
  EXPECT_TRUE(half_turn);
  RecordProperty("candidates", listed);
}

// Nothing tells the pose from its half turn: refused, every candidate listed with its numbers.
TEST(AlignmentTest, RefusesWhenNothingTellsThePoseFromItsTwin) {
  const SymmetricPair pair = symmetricPair(false, Pose2(1.5, -0.8, 0.3));
  AlignmentResult result;
  std::string why;
  EXPECT_FALSE(alignMaps(pair.a, pair.b, AlignmentConfig{}, &result, &why));
  EXPECT_EQ(why.rfind("ambiguous alignment: neither the score", 0), 0u) << why;
  EXPECT_NE(why.find("disagreement"), std::string::npos) << why;
  EXPECT_GE(result.candidates.size(), 2u);
}

// An initial guess (within 3 sigma) removes the twin from the candidates.
TEST(AlignmentTest, AnInitialGuessBreaksTheTie) {
  const Pose2 truth(1.5, -0.8, 0.3);
  const SymmetricPair pair = symmetricPair(false, truth);
  AlignmentConfig config;
  config.has_prior = true;
  config.prior = Pose2(1.0, -0.5, 0.2);
  AlignmentResult result;
  std::string why;
  ASSERT_TRUE(alignMaps(pair.a, pair.b, config, &result, &why)) << why;
  EXPECT_NEAR(result.pose.x, truth.x, kRes);
  EXPECT_NEAR(result.pose.y, truth.y, kRes);
  EXPECT_NEAR(normalizeAngle(result.pose.theta - truth.theta), 0.0, kPi / 180.0);
  config.prior_sigma = 0.0;
  EXPECT_FALSE(alignMaps(pair.a, pair.b, config, &result, &why));
  EXPECT_EQ(why, "invalid alignment config: the initial guess must be finite with sigmas > 0");
}

TEST(AlignmentTest, RefusesBadInput) {
  const EvidentialGridMap a = mapA(), coarse(0.1), empty(kRes);
  AlignmentResult result;
  std::string why;
  EXPECT_FALSE(alignMaps(a, coarse, AlignmentConfig{}, &result, &why));
  EXPECT_EQ(why, "the maps' cells differ (0.05 m and 0.1 m): alignment needs one resolution");
  EXPECT_FALSE(alignMaps(a, empty, AlignmentConfig{}, &result, &why));
  EXPECT_EQ(why, "a map to align has no observed cell");
  AlignmentConfig config;
  config.ambiguity_ratio = 0.0;
  EXPECT_FALSE(alignMaps(a, a, config, &result, &why));
  EXPECT_EQ(why, "invalid alignment config: ambiguity_ratio must be in (0, 1]");
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
