// The anomaly layer (anomaly.h): its two rules on hand-built maps and scan masses, the grid that
// accumulates it, its raster layer, and the SLAM's per-particle anomaly of a room that changed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "cell_support.h"
#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/core/slam_engine.h"
#include "test_support.h"

namespace evidential_slam {
namespace {

using namespace testing_cells;

constexpr double kRes = 0.05;
// Stored masses are multiples of 2^-23: bits computed from the nominal values agree to ~1e-5.
constexpr double kBits = 1e-4;

std::vector<AnomalyCell> anomalyOf(const ScanAccumulator& acc, const EvidentialGridMap& map) {
  std::vector<AnomalyCell> out;
  scanAnomaly(acc, map, 2, &out);
  return out;
}

// A hit on open floor: K = m̃(e) s(o), anomaly -log2(1 - K). A hit counts where the map holds the
// cell free (m̃(e) >= 1/2) and the endpoint lies in it (s(o) >= 0.35: 0.48 when it falls on the
// cell's border, which K >= 1/2 used to leave out); not with a cell the map does not believe free
// within 2 cells; clearing beams on free floor add none.
TEST(ScanAnomaly, HitInOpenSpace) {
  EvidentialGridMap map = filledMap(storedCell(0.0f, 0.99f));
  map.mutableCell(6, 0) = storedCell(0.7f, 0.2f);     // a wall cell
  map.mutableCell(0, -6) = storedCell(0.05f, 0.45f);  // floor seen free, not confidently
  ScanAccumulator acc;
  acc.reset(CellIndex{0, 0}, 16);
  acc.add(0, 0, scanMass(0.8f, 0.0f));    // K = 0.792: 2.2655 bits
  acc.add(-4, 0, scanMass(0.48f, 0.0f));  // an endpoint on the cell's border: K = 0.4752
  acc.add(-4, 4, scanMass(0.3f, 0.0f));   // the cell next to an endpoint: not the hit's cell
  acc.add(4, 0, scanMass(0.8f, 0.0f));    // the wall cell is 2 away
  acc.add(0, -6, scanMass(0.8f, 0.0f));   // m̃(e) = 0.45 < 1/2
  acc.add(0, 4, scanMass(0.0f, 0.8f));    // a clearing beam agrees with the floor
  const std::vector<AnomalyCell> cells = anomalyOf(acc, map);
  ASSERT_EQ(cells.size(), 2u);
  const AnomalyCell& a = cells[0].x == 0 ? cells[0] : cells[1];
  const AnomalyCell& b = cells[0].x == 0 ? cells[1] : cells[0];
  EXPECT_EQ(a.y, 0);
  EXPECT_NEAR(a.bits, -std::log2(1.0 - 0.99 * 0.8), kBits);
  EXPECT_NEAR(a.bits, 2.2655, 1e-3);
  EXPECT_EQ(b.x, -4);
  EXPECT_EQ(b.y, 0);
  EXPECT_NEAR(b.bits, 0.9302, 1e-3);  // -log2(1 - 0.99 * 0.48)
  EXPECT_NEAR(contradictionOf(cells), 0.792 + 0.4752, 1e-4);

  // Three cells from the wall the same hit counts; next to never-observed space it does not.
  ScanAccumulator far;
  far.reset(CellIndex{0, 0}, 16);
  far.add(3, 0, scanMass(0.8f, 0.0f));
  far.add(9, 9, scanMass(0.8f, 0.0f));  // (11, 11) is unobserved: within 2 cells
  const std::vector<AnomalyCell> far_cells = anomalyOf(far, map);
  ASSERT_EQ(far_cells.size(), 1u);
  EXPECT_EQ(far_cells[0].x, 3);
}

// A cell the map holds occupied that a clearing beam crosses: K = m̃(o) s(e) >= 1/2 (a surface
// cell held occupied without confidence does not count). Only through the obstacle: every
// neighbour the map does not hold free is cleared too (a beam clipping the end of a door leaves
// the rest of it as it was). Not when the scan itself puts a surface (s(o) >= 0.05) within 2
// cells of it: a beam grazing a wall it hits next to.
TEST(ScanAnomaly, PassThroughAnObstacle) {
  EvidentialGridMap map = filledMap(storedCell(0.0f, 0.99f));
  for (int y = -1; y <= 1; ++y) map.mutableCell(0, y) = storedCell(0.9f, 0.05f);  // a door
  map.mutableCell(0, 5) = storedCell(0.6f, 0.3f);   // occupied, but K = 0.48 < 1/2
  map.mutableCell(0, 9) = storedCell(0.7f, 0.05f);  // a post: K = 0.7 s(e) = 0.56
  map.mutableCell(9, 0) = storedCell(0.9f, 0.05f);
  auto clear = [](ScanAccumulator* a, int y) {
    for (int x = -5; x <= 5; ++x) a->add(x, y, scanMass(0.0f, 0.8f));
  };
  ScanAccumulator acc;
  acc.reset(CellIndex{0, 0}, 16);
  for (int y = -1; y <= 1; ++y) clear(&acc, y);  // beams through the whole (opened) door
  acc.add(0, 5, scanMass(0.0f, 0.8f));
  acc.add(0, 9, scanMass(0.0f, 0.8f));
  acc.add(9, 0, scanMass(0.0f, 0.45f));  // near its own hit: not a clearing beam there
  std::vector<AnomalyCell> cells = anomalyOf(acc, map);
  ASSERT_EQ(cells.size(), 4u);
  int door = 0;
  for (const AnomalyCell& c : cells) {
    EXPECT_EQ(c.x, 0);
    if (c.y == 9) {
      EXPECT_NEAR(c.bits, 1.1844, 1e-3);  // -log2(1 - 0.7 * 0.8)
    } else {
      EXPECT_LE(std::abs(c.y), 1);
      EXPECT_NEAR(c.bits, -std::log2(1.0 - 0.9 * 0.8), kBits);
      ++door;
    }
  }
  EXPECT_EQ(door, 3);

  // One beam clipping the door's end cell: (0, 0) next to it is held occupied and not cleared.
  ScanAccumulator clip;
  clip.reset(CellIndex{0, 0}, 16);
  clear(&clip, 1);
  EXPECT_TRUE(anomalyOf(clip, map).empty());

  // A hit two cells from the door (a beam grazing the wall it hits next to): nothing.
  acc.reset(CellIndex{0, 0}, 16);
  for (int y = -1; y <= 1; ++y) clear(&acc, y);
  acc.add(2, -2, scanMass(0.1f, 0.0f));
  acc.add(2, 2, scanMass(0.1f, 0.0f));
  cells = anomalyOf(acc, map);
  EXPECT_TRUE(cells.empty());
  // Three cells away, or a hit below the surface mass: counted again.
  ScanAccumulator farther;
  farther.reset(CellIndex{0, 0}, 16);
  for (int y = -1; y <= 1; ++y) clear(&farther, y);
  farther.add(3, 3, scanMass(0.6f, 0.0f));
  farther.add(1, 2, scanMass(0.04f, 0.0f));
  cells = anomalyOf(farther, map);
  EXPECT_EQ(cells.size(), 4u);  // the door's three cells, and (3, 3) as a hit in open space
}

// The anomaly rules read the map before the scan: anomaly is what the update's conflict would be,
// in bits, on the cells they pass (EC's increment there).
TEST(ScanAnomaly, EqualsTheExternalConflictTheUpdateAddsThere) {
  EvidentialGridMap map = filledMap(storedCell(0.0f, 0.99f));
  map.mutableCell(-6, 0) = storedCell(0.95f, 0.0f);
  ScanAccumulator acc;
  acc.reset(CellIndex{0, 0}, 16);
  acc.add(0, 0, scanMass(0.62f, 0.0f));
  acc.add(-6, 0, scanMass(0.0f, 0.8f));
  const std::vector<AnomalyCell> cells = anomalyOf(acc, map);
  ASSERT_EQ(cells.size(), 2u);
  const double ec0 = externalConflict(map.cell(0, 0));
  const double ec6 = externalConflict(map.cell(-6, 0));
  acc.applyTo(&map);
  for (const AnomalyCell& c : cells) {
    const double before = c.x == 0 ? ec0 : ec6;
    EXPECT_NEAR(c.bits, externalConflict(map.cell(c.x, c.y)) - before, 2e-3) << c.x;
  }
}

TEST(AnomalyGrid, AccumulatesAlongALineage) {
  auto root = std::make_shared<AnomalyNode>();
  root->cells = {AnomalyCell{1, 2, 0.5f}, AnomalyCell{-3, 4, 1.0f}};
  auto child = std::make_shared<AnomalyNode>();
  child->cells = {AnomalyCell{1, 2, 0.25f}};
  child->parent = root;
  auto sibling = std::make_shared<AnomalyNode>();
  sibling->cells = {AnomalyCell{7, 7, 2.0f}};
  sibling->parent = root;
  const AnomalyGrid a = accumulateAnomaly(child.get());
  EXPECT_FLOAT_EQ(a.at(1, 2), 0.75f);
  EXPECT_FLOAT_EQ(a.at(-3, 4), 1.0f);
  EXPECT_FLOAT_EQ(a.at(7, 7), 0.0f);
  EXPECT_EQ(a.size(), 2u);
  EXPECT_FLOAT_EQ(static_cast<float>(a.total()), 1.75f);
  const AnomalyGrid b = accumulateAnomaly(sibling.get());
  EXPECT_FLOAT_EQ(b.at(7, 7), 2.0f);
  EXPECT_FLOAT_EQ(b.at(1, 2), 0.5f);
  EXPECT_TRUE(accumulateAnomaly(nullptr).empty());

  // A long chain is released without recursion.
  std::shared_ptr<const AnomalyNode> chain;
  for (int i = 0; i < 200000; ++i) {
    auto n = std::make_shared<AnomalyNode>();
    n->parent = chain;
    chain = n;
  }
  chain.reset();
}

// The tenth layer of a raster is the grid's anomaly at each cell of the box, 0 elsewhere and
// without a grid; cells outside the box are left out.
TEST(AnomalyGrid, FillsTheAnomalyLayer) {
  EvidentialGridMap map(kRes);
  for (int x = 0; x < 4; ++x) map.mutableCell(x, 0) = storedCell(0.5f, 0.2f);
  AnomalyGrid anomaly;
  anomaly.add(2, 0, 3.0f);
  anomaly.add(100, 100, 1.0f);
  const LayerRaster r = extractLayers(map, CellBox{0, 0, 3, 1}, &anomaly);
  const std::vector<float>& v = r.layer(Layer::kAnomaly);
  ASSERT_EQ(v.size(), 8u);
  for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], i == 2 ? 3.0f : 0.0f) << i;
  const LayerRaster none = extractLayers(map, CellBox{0, 0, 3, 1});
  for (float x : none.layer(Layer::kAnomaly)) EXPECT_EQ(x, 0.0f);
  EXPECT_EQ(layerName(Layer::kAnomaly), "anomaly");
  EXPECT_EQ(layerValue(storedCell(0.5f, 0.2f, 1.0f), Layer::kAnomaly), 0.0);
}

// The SLAM takes each scan's anomaly against each particle's map before the scan. The room mapped
// without its box, then seen with it: the box's face lies in mapped open floor and stands out;
// scans of the unchanged room add next to nothing on the walls.
// A 12 m square room (walls x, y = ±6) with a 1 m pillar at [2, 3] x [2, 3] and, with `box`, a
// box at [1, 1.5] x [-1, -0.5] the map never saw: 720 beams over a full turn from `pose`; every
// 7th beam no return, every 11th beyond the laser's range.
LaserScan bigRoomScan(const Pose2& pose, bool box) {
  const auto block = [&](double c, double s, double x0, double x1, double y0, double y1) {
    double t_lo = 0.0, t_hi = 1e9;  // slab test
    for (int axis = 0; axis < 2; ++axis) {
      const double o = axis == 0 ? pose.x : pose.y, d = axis == 0 ? c : s;
      const double lo = axis == 0 ? x0 : y0, hi = axis == 0 ? x1 : y1;
      if (std::abs(d) < 1e-12) {
        if (o < lo || o > hi) return 1e9;
        continue;
      }
      double a = (lo - o) / d, b = (hi - o) / d;
      if (a > b) std::swap(a, b);
      t_lo = std::max(t_lo, a);
      t_hi = std::min(t_hi, b);
    }
    return t_lo <= t_hi ? t_lo : 1e9;
  };
  LaserScan scan;
  scan.max_range = 30.0f;
  for (int i = 0; i < 720; ++i) {
    const double bearing = -M_PI + i * (M_PI / 360.0);
    const double a = pose.theta + bearing, c = std::cos(a), s = std::sin(a);
    double t = 1e9;
    if (c > 1e-9) t = std::min(t, (6.0 - pose.x) / c);
    if (c < -1e-9) t = std::min(t, (-6.0 - pose.x) / c);
    if (s > 1e-9) t = std::min(t, (6.0 - pose.y) / s);
    if (s < -1e-9) t = std::min(t, (-6.0 - pose.y) / s);
    t = std::min(t, block(c, s, 2.0, 3.0, 2.0, 3.0));
    if (box) t = std::min(t, block(c, s, 1.0, 1.5, -1.0, -0.5));
    if (i % 11 == 5) t = 35.0;
    scan.ranges.push_back(static_cast<float>(t));
    scan.bearings.push_back(static_cast<float>(bearing));
    scan.valid.push_back(i % 7 == 3 ? 0 : 1);
  }
  return scan;
}

std::vector<AnomalyCell> sortedCells(std::vector<AnomalyCell> cells) {
  std::sort(cells.begin(), cells.end(), [](const AnomalyCell& a, const AnomalyCell& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  return cells;
}

// accumulateForAnomaly leaves out the evidence of the map's tiles believed free that no hit
// reaches, and the anomaly is the same, cell for cell and bit for bit, as from the whole scan's
// evidence: on a mapped room, for a precise and a noisy laser (whose hit windows reach metres),
// for a scan that sees a new box and for scans placed off their true pose (hits in open space,
// beams through the pillar and the walls).
TEST(ScanAnomaly, AccumulatedForTheAnomalyAloneTheSame) {
  for (const double range_sigma : {0.0, 0.3}) {
    const SensorModelConfig config = SensorModelConfig().forSensorNoise(range_sigma, kRes);
    const BeamModel model(config, kRes);
    EvidentialGridMap map(kRes);
    ScanAccumulator acc;
    const std::vector<Pose2> mapping = {Pose2(-3.0, -3.0, 0.0), Pose2(-2.0, 3.0, 1.0),
                                        Pose2(3.0, -2.0, 2.0), Pose2(0.0, 0.0, 0.5),
                                        Pose2(4.0, 4.0, -2.0)};
    for (int lap = 0; lap < 3; ++lap) {
      for (const Pose2& p : mapping)
        model.weighAndIntegrate(p, bigRoomScan(p, false), &map, &acc, 1);
    }
    const BelievedFreeTiles free_tiles(map);
    EXPECT_GT(free_tiles.count(), 4u);
    struct Case {
      Pose2 truth, placed;
      bool box;
    };
    const std::vector<Case> cases = {
        {Pose2(-1.0, 1.0, 0.3), Pose2(-1.0, 1.0, 0.3), true},
        {Pose2(1.0, -3.0, 0.2), Pose2(2.2, -2.2, 0.6), false},
        {Pose2(-4.0, 0.5, 2.5), Pose2(-3.4, 0.0, 2.2), true},
    };
    double total = 0.0;
    for (const Case& k : cases) {
      const LaserScan scan = bigRoomScan(k.truth, k.box);
      ScanAccumulator whole, part;
      model.weighAndAccumulate(k.placed, scan, map, &whole, std::numeric_limits<int>::max());
      model.accumulateForAnomaly(k.placed, scan, free_tiles, &part);
      EXPECT_LT(part.touched(), whole.touched());
      std::vector<AnomalyCell> a, b;
      scanAnomaly(whole, map, model.openSpaceRadius(), &a);
      scanAnomaly(part, map, model.openSpaceRadius(), &b);
      a = sortedCells(a);
      b = sortedCells(b);
      ASSERT_EQ(a.size(), b.size()) << range_sigma;
      for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].x, b[i].x);
        EXPECT_EQ(a[i].y, b[i].y);
        EXPECT_EQ(a[i].bits, b[i].bits);
      }
      total += contradictionOf(a);
    }
    EXPECT_GT(total, 5.0) << range_sigma;  // the cases do contradict the map
  }
}

TEST(SlamAnomaly, AnObjectThatAppearsStandsOut) {
  SlamConfig c = testing_room::withoutRealRobotSettings(SlamConfig());
  c.particles = 4;
  c.threads = 1;
  c.matcher.enabled = false;
  c.motion = testing_room::noiselessMotion();
  c.update_min_distance = 0.0;
  c.update_min_angle = 0.0;
  SlamEngine engine(c);
  const std::vector<Pose2> poses = {Pose2(-1.0, -0.5, 0.0), Pose2(-0.8, 0.0, 0.3),
                                    Pose2(-0.6, 0.4, -0.2), Pose2(-1.0, 0.8, 0.0)};
  // The map frame is the room's shifted by half a cell: the walls (at whole metres) lie on cell
  // centres, where a hit puts an occupied mass above 1/2 (on a cell border, 0.48 in two cells).
  const auto inMap = [](const Pose2& p) { return Pose2(p.x + 0.025, p.y + 0.025, p.theta); };
  double stamp = 1.0;
  for (int lap = 0; lap < 3; ++lap) {
    for (const Pose2& p : poses) {
      engine.processScan(inMap(p), testing_room::roomScan(p, stamp++, false));
    }
  }
  const double static_total = engine.bestAnomaly().total();
  for (const Pose2& p : poses) {
    engine.processScan(inMap(p), testing_room::roomScan(p, stamp++, true));
  }
  const AnomalyGrid anomaly = engine.bestAnomaly();
  double box = 0.0, walls = 0.0;
  anomaly.forEach([&](int x, int y, float bits) {
    const Eigen::Vector2d p =
        engine.bestMap().cellCenter(CellIndex{x, y}) - Eigen::Vector2d(0.025, 0.025);
    if (std::abs(p.x() - 1.0) < 0.1 && p.y() > 0.4 && p.y() < 1.9) {
      box += bits;
    } else {
      walls += bits;
    }
  });
  EXPECT_GT(box, 20.0);  // about 1.3 bits per cell of a 1.5 m face, per scan that first sees it
  EXPECT_LT(walls, 0.05 * box);
  EXPECT_LT(static_total, 0.05 * box);
}

}  // namespace
}  // namespace evidential_slam
