// Tests of the scan matcher (scan_matcher.h): in a mapped room the score peaks at the true pose and
// refine() pulls a perturbed pose back onto it. Behavioural tests (no closed-form numbers).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "evidential_slam/core/scan_matcher.h"
#include "evidential_slam/core/sensor_model.h"
#include "test_support.h"

namespace evidential_slam {
namespace {

// The room with its box corner, so it is not symmetric.
LaserScan roomScan(const Pose2& pose) {
  return testing_room::roomScan(pose, 0.0, /*with_box=*/true);
}

class ScanMatcherTest : public testing::Test {
 protected:
  ScanMatcherTest()
      : model_(SensorModelConfig(), 0.05),
        matcher_(testing_room::withoutRealRobotSettings(SlamConfig()).matcher, SensorModelConfig(),
                 0.05),
        truth_(-0.3, -0.2, 0.2) {
    // Map the room from two poses so the walls are well established.
    for (const Pose2& p : {truth_, Pose2(0.2, -0.5, -0.3)}) {
      TracedScan traced;
      model_.traceScan(p, roomScan(p), &traced);
      ScanAccumulator scratch;
      model_.integrateScan(traced, &map_, &scratch);
    }
    endpoints_ = matcher_.endpoints(roomScan(truth_));
  }

  BeamModel model_;
  ScanMatcher matcher_;
  EvidentialGridMap map_{0.05};
  Pose2 truth_;
  std::vector<MatchPoint> endpoints_;
};

// The score of the true pose beats that of shifted / rotated poses.
TEST_F(ScanMatcherTest, ScorePeaksAtTruth) {
  ASSERT_FALSE(endpoints_.empty());
  const double best = matcher_.score(map_, truth_, endpoints_);
  EXPECT_GT(best, 0.0);
  for (const Pose2& d : {Pose2(0.1, 0, 0), Pose2(-0.1, 0, 0), Pose2(0, 0.1, 0), Pose2(0, -0.1, 0),
                         Pose2(0, 0, 0.05), Pose2(0, 0, -0.05)}) {
    EXPECT_LT(matcher_.score(map_, truth_.compose(d), endpoints_), best)
        << d.x << " " << d.y << " " << d.theta;
  }
}

// refine() from a pose 8 cm / 6 cm / 0.03 rad off returns to the truth within 3 cm and 0.01 rad,
// with ICP point to line (the default) and point to point; so does ICP alone (no hill climb).
TEST_F(ScanMatcherTest, RefineRecoversPerturbedPose) {
  const Pose2 start(truth_.x + 0.08, truth_.y - 0.06, truth_.theta + 0.03);
  for (const bool to_line : {true, false}) {
    for (const int hill_climb_moves : {20, 0}) {
      ScanMatcherConfig config;
      config.point_to_line = to_line;
      config.max_iterations = hill_climb_moves;
      const ScanMatcher matcher(config, SensorModelConfig(), 0.05);
      const Pose2 refined = matcher.refine(map_, start, endpoints_);
      SCOPED_TRACE(testing::Message()
                   << "point to line " << to_line << ", hill climb " << hill_climb_moves);
      EXPECT_NEAR(refined.x, truth_.x, 0.03);
      EXPECT_NEAR(refined.y, truth_.y, 0.03);
      EXPECT_NEAR(normalizeAngle(refined.theta - truth_.theta), 0.0, 0.01);
      EXPECT_GE(matcher.score(map_, refined, endpoints_), matcher.score(map_, start, endpoints_));
    }
  }
}

using testing_room::corridorScan;

// The corridor (test_support.h) mapped from 17 poses along it, so its walls are continuous lines
// of occupied cells.
EvidentialGridMap mappedCorridor() {
  const BeamModel model(SensorModelConfig(), 0.05);
  EvidentialGridMap map(0.05);
  for (int i = -8; i <= 8; ++i) {
    const Pose2 p(0.25 * i, 0.2 * std::sin(i), 0.05 * std::cos(i));
    TracedScan traced;
    model.traceScan(p, corridorScan(p), &traced);
    ScanAccumulator scratch;
    model.integrateScan(traced, &map, &scratch);
  }
  return map;
}

// A scan in a corridor (walls y = ±1, no end within the laser's 20 m) says nothing about the
// position along it. ICP (point to line, the default, and point to point) corrects the offset
// across the corridor and the heading and leaves the position along it where the proposal put it,
// to within 2 cm.
TEST(ScanMatcherCorridorTest, IcpKeepsTheUnobservedDirection) {
  const EvidentialGridMap map = mappedCorridor();
  const Pose2 truth(0.4, 0.0, 0.0);
  for (const bool to_line : {true, false}) {
    ScanMatcherConfig config;
    config.point_to_line = to_line;
    config.max_iterations = 0;  // ICP alone
    const ScanMatcher matcher(config, SensorModelConfig(), 0.05);
    const std::vector<MatchPoint> pts = matcher.endpoints(corridorScan(truth));
    ASSERT_GT(pts.size(), 100u);
    for (const double along : {-0.3, 0.3}) {
      SCOPED_TRACE(testing::Message() << "point to line " << to_line << ", along " << along);
      const Pose2 start(truth.x + along, truth.y + 0.12, truth.theta + 0.04);
      const Pose2 refined = matcher.refine(map, start, pts);
      EXPECT_NEAR(refined.y, truth.y, 0.03);  // cell centres: within half a cell
      EXPECT_NEAR(normalizeAngle(refined.theta - truth.theta), 0.0, 0.005);
      EXPECT_NEAR(refined.x, start.x, 0.02);
    }
  }
}

// translationConstraint: in a corridor whose walls are lines of cells (set by hand: rows y = ±1 m
// occupied, the cells between free, x within ±20 m) every matched endpoint's normal is (0, ±1), so
// the translation information has no x part and the ratio is 0. Both with a point-to-line and a
// point-to-point matcher: the normals come from the map. In the room (with its box) walls face
// both ways: above 0.5. A map without walls matches nothing: 0.
TEST(ScanMatcherCorridorTest, TranslationConstraintIsZeroAlongACorridor) {
  EvidentialGridMap map(0.05);
  for (int x = -400; x < 400; ++x) {
    map.mutableCell(x, 20) = Cell::fromStored(0.9f, 0.0f, 0.0f);
    map.mutableCell(x, -21) = Cell::fromStored(0.9f, 0.0f, 0.0f);
    for (int y = -20; y < 20; ++y) map.mutableCell(x, y) = Cell::fromStored(0.0f, 0.9f, 0.0f);
  }
  const Pose2 truth(0.4, 0.0, 0.0);
  for (const bool to_line : {true, false}) {
    ScanMatcherConfig config;
    config.point_to_line = to_line;
    const ScanMatcher matcher(config, SensorModelConfig(), 0.05);
    const std::vector<MatchPoint> pts = matcher.endpoints(corridorScan(truth));
    // The endpoints do match the walls (a 0 from too few matches would prove nothing).
    ASSERT_GT(matcher.score(map, truth, pts), 0.3 * static_cast<double>(pts.size()));
    const double ratio = matcher.translationConstraint(map, truth, pts);
    EXPECT_NEAR(ratio, 0.0, 1e-12) << "point to line " << to_line;
  }
}

TEST_F(ScanMatcherTest, TranslationConstraintIsHighInARoom) {
  for (const bool to_line : {true, false}) {
    ScanMatcherConfig config;
    config.point_to_line = to_line;
    const ScanMatcher matcher(config, SensorModelConfig(), 0.05);
    const double ratio = matcher.translationConstraint(map_, truth_, endpoints_);
    EXPECT_GT(ratio, 0.5) << "point to line " << to_line;
    EXPECT_LE(ratio, 1.0) << "point to line " << to_line;
  }
  EXPECT_EQ(matcher_.translationConstraint(EvidentialGridMap(0.05), truth_, endpoints_), 0.0);
}

// search() turns the start by up to ±heading_window: from 0.6 rad (34°) and 10 cm off, where ICP
// alone stays caught, a window of 0.7 rad (a start 0.01 rad from the truth) brings it back.
TEST_F(ScanMatcherTest, SearchRecoversLargeHeadingError) {
  const Pose2 start(truth_.x + 0.1, truth_.y, truth_.theta + 0.6);
  const Pose2 icp_only = matcher_.refine(map_, start, endpoints_);
  EXPECT_GT(std::abs(normalizeAngle(icp_only.theta - truth_.theta)), 0.05);
  double score = 0.0;
  const Pose2 found = matcher_.search(map_, start, endpoints_, 0.7, &score);
  EXPECT_NEAR(found.x, truth_.x, 0.05);
  EXPECT_NEAR(found.y, truth_.y, 0.05);
  EXPECT_NEAR(normalizeAngle(found.theta - truth_.theta), 0.0, 0.03);
  EXPECT_NEAR(score, matcher_.score(map_, found, endpoints_), 1e-9);
  // Handing it the unturned start's ICP, already run, gives the same pose and score.
  const ScanMatcher::Match unturned = matcher_.matchFrom(map_, start, endpoints_);
  EXPECT_GE(unturned.score, 0.0);
  double reused_score = 0.0;
  const Pose2 reused = matcher_.search(map_, start, endpoints_, 0.7, &reused_score, &unturned);
  EXPECT_EQ(reused.x, found.x);
  EXPECT_EQ(reused.y, found.y);
  EXPECT_EQ(reused.theta, found.theta);
  EXPECT_EQ(reused_score, score);
  // An unturned start better than every turned one is what the search returns.
  const ScanMatcher::Match better{Pose2(1.0, 2.0, 0.3), score + 1.0};
  const Pose2 taken = matcher_.search(map_, start, endpoints_, 0.7, &reused_score, &better);
  EXPECT_EQ(taken.x, 1.0);
  EXPECT_EQ(reused_score, score + 1.0);
  // No match on an empty map: the prediction, score -1.
  const EvidentialGridMap empty(0.05);
  const Pose2 same = matcher_.search(empty, start, endpoints_, 0.35, &score);
  EXPECT_EQ(score, -1.0);
  EXPECT_DOUBLE_EQ(same.theta, start.theta);
  const ScanMatcher::Match none = matcher_.matchFrom(empty, start, endpoints_);
  EXPECT_EQ(none.score, -1.0);
  EXPECT_EQ(none.pose.theta, start.theta);
}

// A fan of `n` beams spread evenly over `aperture`, all hitting at 3 m; beams i with
// invalid(i) true are no-returns.
template <typename Invalid>
LaserScan fanScan(int n, double aperture, Invalid invalid) {
  LaserScan scan;
  scan.max_range = 30.0f;
  for (int i = 0; i < n; ++i) {
    scan.bearings.push_back(
        static_cast<float>(-0.5 * aperture + (n > 1 ? i * aperture / (n - 1) : 0.0)));
    scan.ranges.push_back(3.0f);
    scan.valid.push_back(invalid(i) ? 0 : 1);
  }
  return scan;
}

// Endpoints are matched every beam_spacing (2°) of bearing whatever the laser's density: every
// 2nd beam of a 1° laser, every 4th of a 0.5° one, counted over usable beams only.
TEST(ScanMatcherSpacingTest, MatchesBeamsAtTheConfiguredSpacing) {
  constexpr double kPi = 3.14159265358979323846;
  const auto none = [](int) { return false; };
  const ScanMatcher matcher(ScanMatcherConfig(), SensorModelConfig(), 0.05);
  const LaserScan one_degree = fanScan(181, kPi, none), half_degree = fanScan(361, kPi, none);
  EXPECT_EQ(matcher.matchStride(one_degree), 2);
  EXPECT_EQ(matcher.endpoints(one_degree).size(), 91u);  // beams 0, 2, ..., 180
  EXPECT_EQ(matcher.matchStride(half_degree), 4);
  EXPECT_EQ(matcher.endpoints(half_degree).size(), 91u);  // beams 0, 4, ..., 360
  // Every other beam a no-return: 181 usable, every 4th of them matched.
  const LaserScan gaps = fanScan(361, kPi, [](int i) { return i % 2 == 1; });
  EXPECT_EQ(matcher.endpoints(gaps).size(), 46u);
  // A single beam, or no spacing: every usable beam.
  EXPECT_EQ(matcher.matchStride(fanScan(1, 0.0, none)), 1);
  ScanMatcherConfig dense;
  dense.beam_spacing = 0.0;
  EXPECT_EQ(ScanMatcher(dense, SensorModelConfig(), 0.05).endpoints(half_degree).size(), 361u);
}

// On an empty map nothing can be matched: the initial pose is returned unchanged.
TEST_F(ScanMatcherTest, EmptyMapKeepsPose) {
  const EvidentialGridMap empty(0.05);
  const Pose2 start(0.5, 0.5, 0.5);
  const Pose2 refined = matcher_.refine(empty, start, endpoints_);
  EXPECT_DOUBLE_EQ(refined.x, start.x);
  EXPECT_DOUBLE_EQ(refined.y, start.y);
  EXPECT_DOUBLE_EQ(refined.theta, start.theta);
}

// score() against its definition, computed plainly: Σ over endpoints of the largest
// m̃(o)(hit cell + o)·m̃(e)(free cell + o)·kernel(d) over the 3x3 offsets o, d the endpoint's
// distance to the cell's centre (kernel exp(-d²/2σ²), σ = score_sigma, tabulated as score() does).
// score() skips cells that cannot beat the best so far; the sum must be the same, bit for bit, at
// poses all around the truth (sub-cell shifts, so endpoints fall at every position in their cells).
TEST_F(ScanMatcherTest, ScoreEqualsItsDefinition) {
  const ScanMatcherConfig config;
  const double res = 0.05, sigma_cells = config.score_sigma / res;
  const auto reference = [&](const Pose2& pose) {
    const double c = std::cos(pose.theta), s = std::sin(pose.theta);
    double total = 0.0;
    for (const MatchPoint& p : endpoints_) {
      const double fx = (pose.x + c * p.hit.x() - s * p.hit.y()) / res;
      const double fy = (pose.y + s * p.hit.x() + c * p.hit.y()) / res;
      const int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy));
      const int jx = static_cast<int>(std::floor((pose.x + c * p.free.x() - s * p.free.y()) / res));
      const int jy = static_cast<int>(std::floor((pose.y + s * p.free.x() + c * p.free.y()) / res));
      float best = 0.0f;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const double ddx = ix + dx + 0.5 - fx, ddy = iy + dy + 0.5 - fy;
          const double d2 = ddx * ddx + ddy * ddy;
          // The table's entry: exp at the tabulated squared distance (64 steps per cell²).
          const double d2_table = std::floor(d2 * 64.0) / 64.0;
          const float kernel =
              static_cast<float>(std::exp(-0.5 * d2_table / (sigma_cells * sigma_cells)));
          const float term =
              (map_.cell(ix + dx, iy + dy).occupied() * map_.cell(jx + dx, jy + dy).free()) *
              kernel;
          best = std::max(best, term);
        }
      }
      total += best;
    }
    return total;
  };
  int compared = 0;
  for (int i = -6; i <= 6; ++i) {
    for (int j = -6; j <= 6; ++j) {
      const Pose2 pose(truth_.x + 0.0073 * i, truth_.y + 0.0061 * j,
                       truth_.theta + 0.004 * (i - j));
      EXPECT_EQ(matcher_.score(map_, pose, endpoints_), reference(pose)) << i << " " << j;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 169);
  EXPECT_GT(reference(truth_), 0.0);
}

// correspondence() against its definition, searched plainly: every offset within the search
// radius in the order (d², dy, dx), the first whose hit cell holds m̃(o) ≥ threshold and whose
// free cell m̃(e) ≥ threshold. On a random map around tile corners (negative cells included), with
// a radius of 8 cells (the default) and of 40 (rows spanning three 32-cell tiles), for hit cells
// with and without a target in reach.
TEST(ScanMatcherCorrespondenceTest, EqualsNearestQualifyingOffset) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  EvidentialGridMap map(0.05);
  for (int y = -70; y < 70; ++y) {
    for (int x = -70; x < 70; ++x) {
      const float u = unit(rng);
      if (u < 0.04f) map.mutableCell(x, y).setMasses(0.3f + 0.7f * unit(rng), 0.0f);  // target
      if (u > 0.5f) map.mutableCell(x, y).setMasses(0.0f, unit(rng));
    }
  }
  for (const double radius : {0.4, 2.0}) {
    ScanMatcherConfig config;
    config.search_radius = radius;
    const ScanMatcher matcher(config, SensorModelConfig(), 0.05);
    const int r = static_cast<int>(std::ceil(radius / 0.05));
    std::vector<CellIndex> order;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        if (dx * dx + dy * dy <= r * r) order.push_back(CellIndex{dx, dy});
      }
    }
    std::stable_sort(order.begin(), order.end(), [](const CellIndex& a, const CellIndex& b) {
      return a.x * a.x + a.y * a.y < b.x * b.x + b.y * b.y;
    });
    const float threshold = static_cast<float>(config.occupied_threshold);
    std::uniform_int_distribution<int> coord(-90, 90), step(-3, 3);
    int found = 0, none = 0;
    for (int i = 0; i < 3000; ++i) {
      const CellIndex hit{coord(rng), coord(rng)};
      const CellIndex free{hit.x + step(rng), hit.y + step(rng)};
      bool expected = false;
      CellIndex expected_offset;
      for (const CellIndex& o : order) {
        if (map.cell(hit.x + o.x, hit.y + o.y).occupied() < threshold) continue;
        if (map.cell(free.x + o.x, free.y + o.y).free() < threshold) continue;
        expected = true;
        expected_offset = o;
        break;
      }
      CellIndex offset{1000, 1000};
      ASSERT_EQ(matcher.correspondence(map, hit, free, &offset), expected)
          << radius << " " << hit.x << " " << hit.y;
      if (expected) {
        EXPECT_EQ(offset, expected_offset) << radius << " " << hit.x << " " << hit.y;
        ++found;
      } else {
        ++none;
      }
    }
    EXPECT_GT(found, 500) << radius;
    if (radius < 1.0) {
      EXPECT_GT(none, 100);  // hit cells beyond the mapped square
    }
  }
}

}  // namespace
}  // namespace evidential_slam
