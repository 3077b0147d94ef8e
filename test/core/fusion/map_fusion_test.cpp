// Tests of whole-map fusion (core/fusion/map_fusion.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "evidential_slam/core/fusion/map_fusion.h"
#include "evidential_slam/core/fusion/map_score.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;

void set(EvidentialGridMap* map, int x, int y, float occupied, float free, float lambda = 0.0f) {
  map->mutableCell(x, y) = Cell::fromStored(occupied, free, lambda);
}

// A 40 x 30 cell room at 0.05 m: walls (m̃(o) 0.9) around free space (m̃(e) 0.8), some conflict
// on one wall, a mixed cell (o and e) in a corner.
EvidentialGridMap room() {
  EvidentialGridMap map(0.05);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const bool wall = x == 0 || y == 0 || x == 39 || y == 29;
      if (wall) {
        set(&map, x, y, 0.9f, 0.0f, x == 0 ? 0.7f : 0.0f);
      } else {
        set(&map, x, y, 0.0f, 0.8f);
      }
    }
  }
  set(&map, 1, 1, 0.5f, 0.3f);
  return map;
}

size_t observedCells(const EvidentialGridMap& map) {
  size_t n = 0;
  const CellBox box = map.allocatedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) n += map.cell(x, y).observed() ? 1 : 0;
  }
  return n;
}

bool fuse(const std::vector<FusionSource>& sources, Rule rule, EvidentialGridMap* out,
          FusionReport* report, std::string* why = nullptr) {
  FusionConfig config;
  config.rule = rule;
  return fuseMaps(sources, config, out, report, why);
}

// Cautious fusion of a map with itself changes no cell; the overlap is every observed cell and
// the rule adds no conflict.
TEST(MapFusionTest, CautiousFusionOfAMapWithItselfChangesNothing) {
  const EvidentialGridMap a = room();
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&a, Pose2()}}, Rule::kCautious, &out, &report));
  const size_t n = observedCells(a);
  EXPECT_EQ(report.fused_cells, n);
  EXPECT_EQ(report.overlap_cells, n);
  EXPECT_NEAR(report.mean_conflict_added, 0.0, 1e-7);
  for (int y = -2; y < 32; ++y) {
    for (int x = -2; x < 42; ++x) ASSERT_EQ(out.cell(x, y), a.cell(x, y)) << x << ", " << y;
  }
  // The conflict between a map and itself: only the mixed cell, 2 · 0.5 · 0.3 = 0.3, over n cells.
  EXPECT_NEAR(report.mean_conflict, 0.3 / n, 1e-6);
}

// ... while the conjunctive rule counts every cell's evidence twice: a wall cell goes from m̃(o)
// 0.9 to 0.99, a free cell from m̃(e) 0.8 to 0.96, and the conflicted wall's λ doubles.
TEST(MapFusionTest, ConjunctiveFusionOfAMapWithItselfInflatesCertainty) {
  const EvidentialGridMap a = room();
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&a, Pose2()}}, Rule::kConjunctive, &out, &report));
  EXPECT_NEAR(out.cell(10, 0).occupied(), 0.99, 1e-6);
  EXPECT_NEAR(out.cell(10, 10).free(), 0.96, 1e-6);
  EXPECT_NEAR(out.cell(0, 10).lambda(), 1.4, 2e-3);
  EXPECT_GT(report.mean_conflict_added, 0.0);
}

// A map that never observed a cell leaves it alone, whatever the rule (for the disjunctive rule
// too: an unobserved cell is no source, not a vacuous one).
TEST(MapFusionTest, AnEmptyMapChangesNothing) {
  const EvidentialGridMap a = room();
  const EvidentialGridMap empty(0.05);
  for (const Rule rule : {Rule::kConjunctive, Rule::kDisjunctive, Rule::kCautious}) {
    EvidentialGridMap out;
    FusionReport report;
    ASSERT_TRUE(fuse({{&a, Pose2()}, {&empty, Pose2(3.0, -1.0, 0.4)}}, rule, &out, &report));
    EXPECT_EQ(report.overlap_cells, 0u);
    EXPECT_EQ(report.fused_cells, observedCells(a));
    EXPECT_EQ(report.observed_cells, (std::vector<size_t>{observedCells(a), 0}));
    for (int y = 0; y < 30; ++y) {
      for (int x = 0; x < 40; ++x) ASSERT_EQ(out.cell(x, y), a.cell(x, y)) << ruleName(rule);
    }
  }
}

// What either map knows, the cautious fusion knows where the other does not contradict it: a
// cell classified by one map keeps its class when the other map's cell gives its opposite no mass
// (it supports the same singleton weakly, or only Θ, with or without stored conflict). Example:
// a = (o 0.7, e 0.1) has BetP(o) 0.8 and NS 0.2; b = (o 0.3, e 0) has weights w(o) 0.7, w(e) 1;
// the minimum weights are a's w(o) = 0.2/0.9 and w(e) = 0.2/0.3, so the fusion is a itself.
TEST(MapFusionTest, ACellOneMapKnowsKeepsItsClassWhereTheOtherDoesNotContradictIt) {
  const ClassifyConfig thresholds;
  const std::vector<float> levels = {0.0f,  0.05f, 0.1f,  0.2f, 0.3f,
                                     0.45f, 0.6f,  0.75f, 0.9f, 0.99f};
  EvidentialGridMap a(0.05), b(0.05);
  int x = 0, known = 0;
  for (const float o : levels) {
    for (const float e : levels) {
      if (o + e > 1.0f) continue;
      for (const float weak : {0.0f, 0.1f, 0.4f, 0.8f}) {
        for (const float lambda : {0.0f, 0.5f}) {
          set(&a, x, 0, o, e);
          const CellClass c = classify(a.cell(x, 0), thresholds);
          if (c == CellClass::kUnknown) continue;
          // b: weak support for a's class, none for the other (weak 0: observed, only Θ).
          if (c == CellClass::kOccupied) set(&b, x, 0, weak, 0.0f, lambda);
          if (c == CellClass::kFree) set(&b, x, 0, 0.0f, weak, lambda);
          ++x;
          ++known;
        }
      }
    }
  }
  ASSERT_GT(known, 100);
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&b, Pose2()}}, Rule::kCautious, &out, &report));
  for (int i = 0; i < x; ++i) {
    EXPECT_EQ(classify(out.cell(i, 0), thresholds), classify(a.cell(i, 0), thresholds))
        << "a " << a.cell(i, 0).occupied() << " " << a.cell(i, 0).free() << ", b "
        << b.cell(i, 0).occupied() << " " << b.cell(i, 0).free();
  }
}

// Dempster's rule acts on a cell's own conflict even where one map alone observed it.
TEST(MapFusionTest, DempsterNormalisesCellsOneMapObserved) {
  const EvidentialGridMap a = room();
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&a, Pose2()}}, Rule::kDempster, &out, &report));
  EXPECT_EQ(out.cell(0, 10).lambda(), 0.0f);
  EXPECT_EQ(out.cell(0, 10).occupied(), a.cell(0, 10).occupied());
}

// A map placed by a pose: B's cell (2, 0) at 0.1 m has its centre at (0.25, 0.05); B at
// (1.0, 0.5, 90°) puts it at (1.0 - 0.05, 0.5 + 0.25) = (0.95, 0.75): fused cell (9, 7).
TEST(MapFusionTest, APoseMovesTheMapIntoTheFirstMapsFrame) {
  EvidentialGridMap a(0.1), b(0.1);
  set(&a, 0, 0, 0.0f, 0.6f);
  set(&b, 2, 0, 0.7f, 0.1f, 0.25f);
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(
      fuse({{&a, Pose2()}, {&b, Pose2(1.0, 0.5, kPi / 2)}}, Rule::kCautious, &out, &report));
  EXPECT_EQ(out.cell(9, 7), b.cell(2, 0));
  EXPECT_EQ(out.cell(0, 0), a.cell(0, 0));
  EXPECT_EQ(report.fused_cells, 2u);
  EXPECT_EQ(report.overlap_cells, 0u);
  EXPECT_FALSE(out.cell(8, 7).observed());
  EXPECT_FALSE(out.cell(9, 6).observed());
}

// Where the maps overlap: A says occupied (0.8), B free (0.8): K = 0.64, the cautious rule keeps
// it as conflict (two simple supports: as the conjunctive rule), Dempster's rule none of it.
TEST(MapFusionTest, ReportsTheConflictCreatedInTheOverlap) {
  EvidentialGridMap a(0.05), b(0.05);
  set(&a, 3, 3, 0.8f, 0.0f);
  set(&a, 4, 3, 0.0f, 0.5f);
  set(&b, 3, 3, 0.0f, 0.8f);
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&b, Pose2()}}, Rule::kCautious, &out, &report));
  EXPECT_EQ(report.overlap_cells, 1u);
  EXPECT_EQ(report.fused_cells, 2u);
  EXPECT_NEAR(report.mean_conflict, 0.64, 1e-6);
  EXPECT_NEAR(report.mean_conflict_added, 0.64, 1e-3);
  EXPECT_NEAR(out.cell(3, 3).toMass().conflict, 0.64, 1e-3);
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&b, Pose2()}}, Rule::kDempster, &out, &report));
  EXPECT_NEAR(report.mean_conflict, 0.64, 1e-6);
  EXPECT_EQ(out.cell(3, 3).lambda(), 0.0f);
}

// A discounted source weighs less: B free 0.8 with discount 0.5 is free 0.4; K = 0.8 · 0.4.
// Discount 1 removes the source everywhere.
TEST(MapFusionTest, DiscountWeakensASource) {
  EvidentialGridMap a(0.05), b(0.05);
  set(&a, 3, 3, 0.8f, 0.0f);
  set(&b, 3, 3, 0.0f, 0.8f);
  set(&b, 9, 9, 0.0f, 0.8f);
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&b, Pose2(), 0.5}}, Rule::kConjunctive, &out, &report));
  EXPECT_NEAR(report.mean_conflict, 0.32, 1e-6);
  EXPECT_NEAR(out.cell(9, 9).free(), 0.4, 1e-6);
  ASSERT_TRUE(fuse({{&a, Pose2()}, {&b, Pose2(), 1.0}}, Rule::kConjunctive, &out, &report));
  EXPECT_EQ(report.overlap_cells, 0u);
  EXPECT_EQ(out.cell(3, 3), a.cell(3, 3));
  EXPECT_FALSE(out.cell(9, 9).observed());
}

// A door one robot saw closed and the other open: the cautious fusion does not average it into a
// half-occupied doorway a planner might take for either; it marks it as conflict, m(∅) several
// times that of the walls both saw alike.
TEST(MapFusionTest, ADoorSeenClosedAndOpenIsConflictNotAnAverage) {
  EvidentialGridMap closed(0.05), open(0.05);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const bool wall = x == 0 || y == 0 || x == 39 || y == 29 || x == 20;
      const bool door = x == 20 && y >= 10 && y < 20;
      set(&closed, x, y, wall ? 0.85f : 0.0f, wall ? 0.0f : 0.8f);
      set(&open, x, y, wall && !door ? 0.85f : 0.0f, wall && !door ? 0.0f : 0.8f);
    }
  }
  EvidentialGridMap out;
  FusionReport report;
  ASSERT_TRUE(fuse({{&closed, Pose2()}, {&open, Pose2()}}, Rule::kCautious, &out, &report));
  for (int y = 10; y < 20; ++y) {
    const Mass door = out.cell(20, y).toMass();
    // 0.85 · 0.8 of the mass is conflict; what is left splits as the two simple supports do.
    EXPECT_NEAR(door.conflict, 0.85 * 0.8, 1e-3);
    EXPECT_NEAR(door.occupied, 0.85 * 0.2, 1e-3);
    EXPECT_NEAR(door.free, 0.8 * 0.15, 1e-3);
  }
  for (int y = 1; y < 10; ++y) EXPECT_LT(out.cell(20, y).toMass().conflict, 1e-6);
  // Ten door cells of conflict 0.68 in the overlap of 1200 cells.
  EXPECT_NEAR(report.mean_conflict, 10 * 0.85 * 0.8 / 1200, 1e-5);
}

TEST(MapFusionTest, RefusesDifferentResolutions) {
  const EvidentialGridMap a(0.05), b(0.1);
  EvidentialGridMap out;
  FusionReport report;
  std::string why;
  EXPECT_FALSE(fuse({{&a, Pose2()}, {&b, Pose2()}}, Rule::kCautious, &out, &report, &why));
  EXPECT_EQ(why, "map 2 has 0.1 m cells and map 1 0.05 m: fusion needs one resolution");
}

TEST(MapFusionTest, RefusesBadInput) {
  const EvidentialGridMap a(0.05);
  EvidentialGridMap out;
  FusionReport report;
  std::string why;
  EXPECT_FALSE(fuse({}, Rule::kCautious, &out, &report, &why));
  EXPECT_EQ(why, "no maps to fuse");
  EXPECT_FALSE(fuse({{&a, Pose2()}, {nullptr, Pose2()}}, Rule::kCautious, &out, &report, &why));
  EXPECT_EQ(why, "map 2 is missing");
  EXPECT_FALSE(fuse({{&a, Pose2()}, {&a, Pose2(), 1.5}}, Rule::kCautious, &out, &report, &why));
  EXPECT_EQ(why, "map 2: discount 1.5 is outside [0, 1]");
  EXPECT_FALSE(fuse({{&a, Pose2(NAN, 0, 0)}}, Rule::kCautious, &out, &report, &why));
  EXPECT_EQ(why, "map 1: its pose is not finite");
  FusionConfig config;
  config.rule = static_cast<Rule>(9);
  EXPECT_FALSE(fuseMaps({{&a, Pose2()}}, config, &out, &report, &why));
  EXPECT_EQ(why, "invalid fusion config: fusion rule 9 does not exist");
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
