// Tests of the evidential laser models (sensor_model.h): algorithm.md §3 (forward), §4 (inverse).
// Defaults: Δ = 0.05 m, σ_f = σ_i = 0.025 m, k_f = k_i = 3, r = 0.2, p_o = 0.4, z_max = usable
// range = 20 m. Expected numbers were computed by hand (python, math.erfc for Φ) from the formulas:
//   g(δ) = Φ(δ/σ_f + 3) - Φ(δ/σ_f - 3)
//   m_i = Φ((s + Δ/2)/σ) - Φ((s - Δ/2)/σ), pl_i = m_i, β_i = 1 - Φ((s + 3σ + Δ/2)/σ)
//   η = 1/(1 - p_o(1 - pl_i)), m(o) = (1-r)η[p_o pl_i + (1-p_o) m_i], m(e) = (1-r)η(1-p_o)β_i
// The models are tabulated (nearest neighbour, step σ/64), hence tolerances of ~1e-3 where the
// functions are steep.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "cell_support.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/mass.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/core/sensor_model.h"
#include "test_support.h"

namespace evidential_slam {
namespace {

using namespace testing_cells;

constexpr double kRes = 0.05;
constexpr double kPi = 3.14159265358979323846;
constexpr double kTable = 2e-3;  // tolerance for tabulated values on steep parts

// The documented model parameters, set explicitly so that retuning the shipped defaults does not
// change these tests.
SensorModelConfig paperConfig() {
  SensorModelConfig c;
  c.hit_sigma = 0.025;
  c.forward_sigma = 0.025;
  c.forward_window = 3.0;
  c.free_gap = 3.0;
  c.random_weight = 0.2;
  c.forward_conflict_as_unknown = false;
  c.prior_occupied = 0.4;
  c.usable_range = 20.0;
  c.min_range = 0.05;
  c.clear_no_return = true;
  c.flip_scans = 0;  // unbounded confidence, as in the paper
  return c;
}

// --- Forward model --------------------------------------------------------------------------

// g(0) = Φ(3) - Φ(-3) = 0.99730020; g(±0.05) = Φ(5) - Φ(-1) = 0.84134446;
// g(0.1) = Φ(7) - Φ(1) = 0.15865525; g(0.15) = Φ(9) - Φ(3) = 0.00134990; far away 0.
TEST(BeamModelTest, HitWindow) {
  const BeamModel model(paperConfig(), kRes);
  EXPECT_NEAR(model.hitWindow(0.0), 0.9973002039, 1e-4);
  EXPECT_NEAR(model.hitWindow(0.05), 0.8413444594, kTable);
  EXPECT_NEAR(model.hitWindow(-0.05), 0.8413444594, kTable);
  EXPECT_NEAR(model.hitWindow(0.1), 0.1586552539, kTable);
  EXPECT_NEAR(model.hitWindow(-0.1), 0.1586552539, kTable);
  EXPECT_NEAR(model.hitWindow(0.15), 0.0013498980, 5e-4);
  EXPECT_NEAR(model.hitWindow(0.5), 0.0, 1e-6);
  EXPECT_NEAR(model.hitWindow(-5.0), 0.0, 1e-6);
}

// A beam of z = 1.025 m along +x over cells (i, 0), i = 0..22, cell centres at d_i = (i + 0.5)Δ;
// the measured end point is the centre of cell 20 (δ = z - d_i = (20 - i)Δ).
class ForwardModelTest : public testing::Test {
 protected:
  static constexpr int kHitCell = 20;
  static constexpr double kZ = (kHitCell + 0.5) * kRes;  // 1.025 m

  ForwardModelTest() : model_(paperConfig(), kRes) {
    for (int i = 0; i <= kHitCell + 2; ++i) {
      ray_.push_back(RayCell{i, 0, static_cast<float>((i + 0.5) * kRes)});
    }
  }
  void fill(const Cell& c) {
    for (const RayCell& rc : ray_) map_.mutableCell(rc.x, rc.y) = c;
  }
  double plausibility(double z) const {
    return model_.beamPlausibility(map_, ray_.data(), ray_.size(), z);
  }

  BeamModel model_;
  EvidentialGridMap map_{kRes};
  std::vector<RayCell> ray_;
};

// Beam ending in unknown space (all cells vacuous): a_i = g_i, b_i = 1 - g_i, so
// P_0 = 1 - Π(1 - g_i) = 1 - 0.0026998 * 0.1586555^2 * 0.8413447^2 * 0.998650 = 0.99995196
// (the end-point term g(z - 20) is 0); pl = 0.8 * 0.99995196 + 0.2 = 0.99996157 ≈ 1.
TEST_F(ForwardModelTest, UnknownSpaceIsFullyPlausible) {
  EXPECT_NEAR(plausibility(kZ), 0.99996157, 1e-3);
}

// A certainly free hit cell with conflict λ = 0.5 (m(∅) = 1 - e^{-0.5} = 0.39346934), in free
// space. Normalised (Dempster, config/sim.yaml) it is free: pl = r = 0.2. Read with its conflict as
// ignorance (Yager): m(e) = e^{-0.5} = 0.60653066, m(Θ) = 0.39346934, so P_0 = g(0) · 0.39346934
// = 0.99730020 · 0.39346934 = 0.39240705 and pl = 0.8 · 0.39240705 + 0.2 = 0.51392564.
TEST_F(ForwardModelTest, ConflictReadAsIgnorance) {
  fill(storedCell(0.0f, 1.0f));
  map_.mutableCell(kHitCell, 0) = Cell::fromStored(0.0f, 1.0f, 0.5f);
  EXPECT_NEAR(plausibility(kZ), 0.2, 1e-6);
  SensorModelConfig config = paperConfig();
  config.forward_conflict_as_unknown = true;
  const BeamModel yager(config, kRes);
  EXPECT_NEAR(yager.beamPlausibility(map_, ray_.data(), ray_.size(), kZ), 0.51392564, 1e-4);
  // Cells without conflict read the same either way.
  map_.mutableCell(kHitCell, 0) = storedCell(1.0f, 0.0f);
  EXPECT_NEAR(yager.beamPlausibility(map_, ray_.data(), ray_.size(), kZ), 0.99784016, 1e-4);
}

// Beam ending in certainly free space: a_i = 0, b_i = 1, P_0 = g(z - z_max) = 0: pl = r = 0.2.
TEST_F(ForwardModelTest, FreeSpaceGivesTheFloor) {
  fill(storedCell(0.0f, 1.0f));
  EXPECT_NEAR(plausibility(kZ), 0.2, 1e-6);
}

// Free cells with a certain obstacle exactly at the measured range: P_0 = g(0) = 0.99730020,
// pl = 0.8 * 0.99730020 + 0.2 = 0.99784016.
TEST_F(ForwardModelTest, ObstacleAtTheRangeIsPlausible) {
  fill(storedCell(0.0f, 1.0f));
  map_.mutableCell(kHitCell, 0) = storedCell(1.0f, 0.0f);
  EXPECT_NEAR(plausibility(kZ), 0.99784016, 1e-4);
  // Same map, measurement 2.5 cells short of the obstacle: δ_20 = -0.125 (g = 0.0227501),
  // P_0 = g(-0.125) = Φ(-2) - Φ(-8) = 0.02275013, pl = 0.8 * 0.02275013 + 0.2 = 0.21820010.
  EXPECT_NEAR(plausibility(kZ - 0.125), 0.21820010, kTable);
}

// An occupied cell 10 cells (0.5 m) before the measured end point stops the beam there: a_j =
// g(0.5) = 0 and b_j = 0, so P_0 = 0 and pl = r = 0.2 — below the 0.99996 of unknown space.
TEST_F(ForwardModelTest, OccupiedCellBeforeTheHitLowersPlausibility) {
  map_.mutableCell(kHitCell - 10, 0) = storedCell(1.0f, 0.0f);
  EXPECT_NEAR(plausibility(kZ), 0.2, 1e-6);
  // Half-occupied (o 0.5, e 0.5) instead: b_j = 0.5, the rest is vacuous:
  // P_0 = 0.5 * 0.99995196 = 0.49997598, pl = 0.8 * 0.49997598 + 0.2 = 0.59998078.
  map_.mutableCell(kHitCell - 10, 0) = storedCell(0.5f, 0.5f);
  EXPECT_NEAR(plausibility(kZ), 0.59998078, 1e-3);
  // The same cell with conflict λ = 0.5, read as ignorance: m(o) = 0.5 e^{-0.5} = 0.30326533,
  // b_j = 1 - 0.30326533, P_0 = 0.69673467 * 0.99995196 = 0.69670120,
  // pl = 0.8 * 0.69670120 + 0.2 = 0.75736096.
  map_.mutableCell(kHitCell - 10, 0) = Cell::fromStored(0.5f, 0.5f, 0.5f);
  SensorModelConfig config = paperConfig();
  config.forward_conflict_as_unknown = true;
  const BeamModel yager(config, kRes);
  EXPECT_NEAR(yager.beamPlausibility(map_, ray_.data(), ray_.size(), kZ), 0.75736096, 1e-3);
}

// The recursion P_i = m̃(o) g_i + m̃(e) P_{i+1} + m̃(Θ)[g_i + P_{i+1} - g_i P_{i+1}] on mixed
// cells:
// all free except cell 19 (o .3, e .5, Θ .2), cell 20 (o .6, e .1, Θ .3), cell 21 vacuous.
//   P_22 = 0 (free, and g(z - 20) = 0); P_21 = g(-0.05) = 0.84134446
//   P_20 = 0.6*0.99730020 + 0.1*0.84134446 + 0.3*(0.99730020 + 0.84134446 - 0.83907308)
//        = 0.98238625
//   P_19 = 0.3*0.84134446 + 0.5*0.98238625 + 0.2*(0.84134446 + 0.98238625 - 0.82652519)
//        = 0.94303746
//   free cells before: P_0 = 0.94303746; pl = 0.8 * 0.94303746 + 0.2 = 0.95442997
TEST_F(ForwardModelTest, RecursionOnMixedCells) {
  fill(storedCell(0.0f, 1.0f));
  map_.mutableCell(kHitCell - 1, 0) = storedCell(0.3f, 0.5f);
  map_.mutableCell(kHitCell, 0) = storedCell(0.6f, 0.1f);
  map_.mutableCell(kHitCell + 1, 0) = Cell();
  EXPECT_NEAR(plausibility(kZ), 0.95442997, kTable);
}

// Plausibility is bounded by the floor r and by 1 for arbitrary maps and ranges.
TEST_F(ForwardModelTest, PlausibilityBetweenFloorAndOne) {
  for (int i = 0; i < static_cast<int>(ray_.size()); ++i) {
    map_.mutableCell(i, 0) = storedCell(0.05f * (i % 7), 0.1f * (i % 4));
  }
  for (double z = 0.1; z < 1.3; z += 0.013) {
    const double pl = plausibility(z);
    EXPECT_GE(pl, 0.2 - 1e-6) << "z = " << z;
    EXPECT_LE(pl, 1.0 + 1e-6) << "z = " << z;
  }
}

// --- Inverse model --------------------------------------------------------------------------

// Cell at the hit (s = 0): m = Φ(1) - Φ(-1) = 0.68268949, β = 1 - Φ(4) = 3.1671e-5,
// η = 1/(1 - 0.4*0.31731051) = 1.14537593, m(o) = 0.8*1.14537593*0.68268949 = 0.62554889,
// m(e) = 0.8*1.14537593*0.6*3.1671e-5 = 1.741e-5, m(Θ) = 0.37443370 (≈ o 0.63, Θ 0.37).
TEST(InverseModelTest, CellAtTheHit) {
  const BeamModel model(paperConfig(), kRes);
  const ScanMass m = model.inverseMass(0.0);
  EXPECT_NEAR(m.occupied, 0.62554889, 1e-3);
  EXPECT_NEAR(m.free, 1.741e-5, 1e-4);
  EXPECT_NEAR(m.unknown(), 0.37443370, 1e-3);
}

// One cell in front (s = -0.05): m = Φ(-1) - Φ(-3) = 0.15730536, β = 1 - Φ(2) = 0.02275013,
// η = 1/(1 - 0.4*0.84269464) = 1.50847277: m(o) = 0.8*1.50847277*0.15730536 = 0.18983268,
// m(e) = 0.8*1.50847277*0.6*0.02275013 = 0.01647262.
// One cell behind (s = +0.05): same m, β = 1 - Φ(6) ≈ 1e-9: m(o) = 0.18983268, m(e) ≈ 0.
// Two cells in front (s = -0.1): m = Φ(-3) - Φ(-5) = 0.00134961, β = 1 - Φ(0) = 0.5,
// η = 1/(1 - 0.4*0.99865039) = 1.66516845: m(o) = 0.00179786,
// m(e) = 0.8*1.66516845*0.6*0.5 = 0.39964043.
// Two cells behind (s = +0.1): m(o) = 0.00179786, m(e) ≈ 0.
TEST(InverseModelTest, CellsAroundTheHit) {
  const BeamModel model(paperConfig(), kRes);
  ScanMass m = model.inverseMass(-0.05);
  EXPECT_NEAR(m.occupied, 0.18983268, kTable);
  EXPECT_NEAR(m.free, 0.01647262, kTable);
  m = model.inverseMass(0.05);
  EXPECT_NEAR(m.occupied, 0.18983268, kTable);
  EXPECT_NEAR(m.free, 0.0, 1e-6);
  m = model.inverseMass(-0.1);
  EXPECT_NEAR(m.occupied, 0.00179786, 5e-4);
  EXPECT_NEAR(m.free, 0.39964043, 5e-3);  // β = 1 - Φ(0) sits on the steepest part
  m = model.inverseMass(0.1);
  EXPECT_NEAR(m.occupied, 0.00179786, 5e-4);
  EXPECT_NEAR(m.free, 0.0, 1e-6);
}

// Far in front of the hit: m ≈ 0, β ≈ 1, η = 1/(1 - 0.4) = 5/3, m(e) = 0.8 * 5/3 * 0.6 = 0.8,
// i.e. 1 - r, and m(Θ) = r = 0.2; clearMass() is exactly that. Far behind: vacuous (not touched).
TEST(InverseModelTest, FarInFrontIsFreeAndFarBehindIsVacuous) {
  const BeamModel model(paperConfig(), kRes);
  for (double s : {-0.5, -1.0, -5.0, -19.0}) {
    const ScanMass m = model.inverseMass(s);
    EXPECT_NEAR(m.occupied, 0.0, 1e-6) << "s = " << s;
    EXPECT_NEAR(m.free, 0.8, 1e-6) << "s = " << s;
    EXPECT_NEAR(m.unknown(), 0.2, 1e-6) << "s = " << s;
  }
  const ScanMass c = model.clearMass();
  EXPECT_NEAR(c.occupied, 0.0, 1e-7);
  EXPECT_NEAR(c.free, 0.8, 1e-7);
  for (double s : {0.3, 1.0, 10.0}) {
    const ScanMass m = model.inverseMass(s);
    EXPECT_NEAR(m.occupied, 0.0, 1e-6) << "s = " << s;
    EXPECT_NEAR(m.free, 0.0, 1e-6) << "s = " << s;
  }
}

// Always m(Θ) ≥ r: m(o) + m(e) = (1-r) η [m + (1-p_o)β] ≤ 1 - r because m + β ≤ 1. Also m(e)
// never decreases moving towards the sensor (β grows, η grows as pl falls).
TEST(InverseModelTest, UnknownNeverBelowRandomWeight) {
  const BeamModel model(paperConfig(), kRes);
  double previous_free = -1.0;
  for (double s = 1.0; s >= -3.0; s -= 0.0007) {
    const ScanMass m = model.inverseMass(s);
    EXPECT_GE(m.occupied, 0.0f) << "s = " << s;
    EXPECT_GE(m.free, 0.0f) << "s = " << s;
    EXPECT_GE(m.unknown(), 0.2f - 1e-6f) << "s = " << s;
    if (s <= 0.0) {
      EXPECT_GE(m.free, previous_free - 1e-6) << "s = " << s;
      previous_free = m.free;
    }
  }
}

// The model follows its configuration: r = 0.1, p_o = 0.5 at s = 0:
// η = 1/(1 - 0.5*0.31731051) = 1.18857406, m(o) = 0.9*1.18857406*0.68268949 = 0.73028392;
// far in front m(e) = 0.9 * 2 * 0.5 = 0.9 = 1 - r.
TEST(InverseModelTest, FollowsConfiguration) {
  SensorModelConfig config = paperConfig();
  config.random_weight = 0.1;
  config.prior_occupied = 0.5;
  const BeamModel model(config, kRes);
  EXPECT_NEAR(model.inverseMass(0.0).occupied, 0.73028392, 1e-3);
  EXPECT_NEAR(model.inverseMass(-1.0).free, 0.9, 1e-6);
  EXPECT_NEAR(model.clearMass().free, 0.9, 1e-6);
}

// --- Tracing and integration ---------------------------------------------------------------

LaserScan makeScan(const std::vector<float>& ranges, const std::vector<float>& bearings,
                   const std::vector<uint8_t>& valid) {
  LaserScan scan;
  scan.max_range = 30.0f;
  scan.ranges = ranges;
  scan.bearings = bearings;
  scan.valid = valid;
  return scan;
}

// The sensor sits at the centre of cell (0,0), (0.025, 0.025), looking along +x; a beam of 1.0 m
// ends at the centre of cell (20, 0) and cell (i, 0) has s = 0.05 i - 1.0.
const Pose2 kSensor(0.025, 0.025, 0.0);

// One hit beam: traced along row 0 up to a few cells past the hit, distances = 0.05 i.
TEST(IntegrateScanTest, TraceOneBeam) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(kSensor, makeScan({1.0f}, {0.0f}, {1}), &traced);
  ASSERT_EQ(traced.beams.size(), 1u);
  const TracedBeam& b = traced.beams[0];
  EXPECT_TRUE(b.hit);
  EXPECT_NEAR(b.range, 1.0, 1e-6);
  ASSERT_GT(b.end, b.begin);
  int max_x = -1;
  float previous = -1.0f;
  for (uint32_t k = b.begin; k < b.end; ++k) {
    const RayCell& c = traced.cells[k];
    EXPECT_EQ(c.y, 0);
    EXPECT_NEAR(c.distance, 0.05 * c.x, 1e-5);
    EXPECT_GT(c.distance, previous);
    previous = c.distance;
    max_x = std::max(max_x, c.x);
  }
  EXPECT_GE(max_x, 22);  // end cell + 2 beyond (algorithm.md §3)
  EXPECT_LE(max_x, 24);  // only ~3 cells behind the hit
  EXPECT_EQ(traced.rays_bad, 0u);
  EXPECT_EQ(traced.rays_no_return, 0u);
}

// One hit beam integrated into an empty map gives the inverse-model values cell by cell
// (values from InverseModelTest; s = -0.15: m ≈ 2.9e-7, β = 1 - Φ(-2) = 0.97724987,
// m(e) = 0.8 * 5/3 * 0.6 * 0.97724987 = 0.78179975); no conflict; neighbours untouched.
TEST(IntegrateScanTest, SingleBeamMatchesInverseModel) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(kSensor, makeScan({1.0f}, {0.0f}, {1}), &traced);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  EXPECT_NEAR(model.integrateScan(traced, &map, &scratch), 0.0, 1e-9);  // vacuous map: K = 0

  for (int i = 1; i <= 12; ++i) {  // s <= -0.4: (e 0.8, Θ 0.2)
    EXPECT_NEAR(map.cell(i, 0).occupied(), 0.0, 1e-5) << i;
    EXPECT_NEAR(map.cell(i, 0).free(), 0.8, 1e-5) << i;
  }
  EXPECT_NEAR(map.cell(17, 0).free(), 0.78179975, kTable);
  EXPECT_NEAR(map.cell(18, 0).free(), 0.39964043, 5e-3);
  EXPECT_NEAR(map.cell(18, 0).occupied(), 0.00179786, 5e-4);
  EXPECT_NEAR(map.cell(19, 0).occupied(), 0.18983268, kTable);
  EXPECT_NEAR(map.cell(19, 0).free(), 0.01647262, kTable);
  EXPECT_NEAR(map.cell(20, 0).occupied(), 0.62554889, 1e-3);  // the hit cell: ≈ o 0.63, Θ 0.37
  EXPECT_NEAR(map.cell(20, 0).unknown(), 0.37443370, 1e-3);
  EXPECT_NEAR(map.cell(21, 0).occupied(), 0.18983268, kTable);
  EXPECT_NEAR(map.cell(21, 0).free(), 0.0, 1e-5);
  EXPECT_NEAR(map.cell(22, 0).occupied(), 0.00179786, 5e-4);
  EXPECT_LT(map.cell(24, 0).occupied(), 1e-5f);
  for (int i = 25; i < 60; ++i) EXPECT_FALSE(map.cell(i, 0).observed()) << i;
  for (int i = 0; i < 30; ++i) {
    EXPECT_FALSE(map.cell(i, 1).observed()) << i;
    EXPECT_FALSE(map.cell(i, -1).observed()) << i;
  }
  for (int i = 0; i < 30; ++i) EXPECT_EQ(map.cell(i, 0).lambda(), 0.0f) << i;
}

// The sensor pose's heading is applied: heading 90° and bearing 90° point the beam along -x, the
// 1.0 m end point is (-0.975, 0.025) = centre of cell (-20, 0).
TEST(IntegrateScanTest, RotatedSensor) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(Pose2(0.025, 0.025, kPi / 2),
                  makeScan({1.0f}, {static_cast<float>(kPi / 2)}, {1}), &traced);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  model.integrateScan(traced, &map, &scratch);
  EXPECT_NEAR(map.cell(-20, 0).occupied(), 0.62554889, 1e-3);
  EXPECT_NEAR(map.cell(-10, 0).free(), 0.8, 1e-5);
  EXPECT_FALSE(map.cell(20, 0).observed());
}

// Two beams along the same line (1.0 m and 2.0 m) are fused within the scan by Dempster's rule,
// so one scan adds no conflict. Cell 20 gets hit (o .62554889, e 1.741e-5) and clear (e .8):
//   K = 0.62554889 * 0.8 = 0.50043911
//   o = 0.62554889 * 0.2 / 0.49956089 = 0.25043950
//   e = (1.741e-5 + 0.37443370 * 0.8) / 0.49956089 = 0.59965537
// Integrating the same scan again fuses it conjunctively with the map: at cell 20
//   K = 2 * 0.25043950 * 0.59965537 = 0.30035478, λ = -ln(0.69964522) = 0.35718190.
// Summed over all cells (cells 17-23 around the first hit and 37-41 around the second, each
// K_i = 2 m̃_i(o) m̃_i(e) of its fused mass) the second scan adds 0.73323607 bits.
TEST(IntegrateScanTest, DempsterWithinScanConjunctiveBetweenScans) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(kSensor, makeScan({1.0f, 2.0f}, {0.0f, 0.0f}, {1, 1}), &traced);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  EXPECT_NEAR(model.integrateScan(traced, &map, &scratch), 0.0, 1e-9);
  EXPECT_NEAR(map.cell(20, 0).occupied(), 0.25043950, kTable);
  EXPECT_NEAR(map.cell(20, 0).free(), 0.59965537, kTable);
  EXPECT_EQ(map.cell(20, 0).lambda(), 0.0f);
  EXPECT_NEAR(map.cell(40, 0).occupied(), 0.62554889, 1e-3);  // second beam's hit
  EXPECT_NEAR(map.cell(10, 0).free(), 0.96, 1e-5);            // two clear masses: 0.8 + 0.2 * 0.8

  ScanConflict conflict;
  conflict.mass_added = -1.0;
  const double added_bits = model.integrateScan(traced, &map, &scratch, &conflict);
  const double mass_added = conflict.mass_added;
  EXPECT_NEAR(map.cell(20, 0).lambda(), 0.35718190, 5e-3);
  // The map held no conflict before: the m(∅) added is all the m(∅) it holds now (cells 0..50),
  // up to the half-float rounding of the stored λ (relative 2^-11).
  double conflict_mass = 0.0;
  for (int x = 0; x <= 50; ++x) conflict_mass += 1.0 - std::exp(-map.cell(x, 0).lambda());
  EXPECT_NEAR(mass_added, conflict_mass, 5e-4 * conflict_mass);
  EXPECT_GT(mass_added, 0.3);  // cell 20 alone: 1 - exp(-0.357) = 0.30
  EXPECT_NEAR(added_bits, 0.73323607, 0.02 * 0.73323607);
  EXPECT_NEAR(externalConflict(map.cell(10, 0)), 0.0, 1e-9);  // agreeing evidence: no conflict
}

// A no-return ray (valid = 0) clears space up to the usable range (20 m) and adds no obstacle.
// Beam along +y from the centre of cell (0,0): cell (0, j) at distance 0.05 j.
TEST(IntegrateScanTest, NoReturnClearsUpToUsableRange) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(kSensor, makeScan({30.0f}, {static_cast<float>(kPi / 2)}, {0}), &traced);
  EXPECT_EQ(traced.rays_no_return, 1u);
  for (const TracedBeam& b : traced.beams) EXPECT_FALSE(b.hit);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  model.integrateScan(traced, &map, &scratch);
  EXPECT_NEAR(map.cell(0, 100).free(), 0.8, 1e-5);  // 5 m
  EXPECT_NEAR(map.cell(0, 390).free(), 0.8, 1e-5);  // 19.5 m
  EXPECT_FALSE(map.cell(0, 410).observed());        // 20.5 m
  EXPECT_FALSE(map.cell(0, 600).observed());        // 30 m
  for (int j = 0; j < 650; ++j) EXPECT_EQ(map.cell(0, j).occupied(), 0.0f) << j;
}

// A return beyond the usable range (25 m > 20 m) is treated like a no-return: free up to 20 m,
// nothing at 25 m. Beam along -x: cell (-i, 0) has its centre 0.05 i from the sensor.
TEST(IntegrateScanTest, BeyondUsableRangeOnlyClears) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(kSensor, makeScan({25.0f}, {static_cast<float>(kPi)}, {1}), &traced);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  model.integrateScan(traced, &map, &scratch);
  EXPECT_NEAR(map.cell(-100, 0).free(), 0.8, 1e-5);  // centre at -4.975: 5 m away
  EXPECT_NEAR(map.cell(-390, 0).free(), 0.8, 1e-5);  // 19.5 m
  EXPECT_FALSE(map.cell(-410, 0).observed());        // 20.5 m
  EXPECT_FALSE(map.cell(-500, 0).observed());        // 25 m: no obstacle
  for (int i = 0; i < 550; ++i) EXPECT_EQ(map.cell(-i, 0).occupied(), 0.0f) << i;
}

// NaN, inf and negative ranges are bad data: counted, skipped, nothing written.
TEST(IntegrateScanTest, BadRangesAreSkipped) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  model.traceScan(kSensor, makeScan({nan, inf, -1.0f}, {0.0f, 0.5f, 1.0f}, {1, 1, 1}), &traced);
  EXPECT_EQ(traced.rays_bad, 3u);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  model.integrateScan(traced, &map, &scratch);
  EXPECT_TRUE(map.observedBox().empty());
}

// Forward model on traced beams. Empty map, beam of 1.0 m (cell centres at 0.05 i, cell 20 at
// δ = 0): pl = 0.99996162, ln pl = -3.838e-5. On the map this very scan produced (cells 0..23 with
// the inverse masses above) the recursion gives P_0 = 0.97105635, pl = 0.97684508,
// ln pl = -0.02342721.
TEST(IntegrateScanTest, ScanLogPlausibility) {
  const BeamModel model(paperConfig(), kRes);
  TracedScan traced;
  model.traceScan(kSensor, makeScan({1.0f}, {0.0f}, {1}), &traced);
  EvidentialGridMap map(kRes);
  EXPECT_NEAR(model.scanLogPlausibility(map, traced, 1), -3.838e-5, 1e-4);
  ScanAccumulator scratch;
  model.integrateScan(traced, &map, &scratch);
  EXPECT_NEAR(model.scanLogPlausibility(map, traced, 1), -0.02342721, kTable);
}

// Every cell of two grids, compared bit for bit over `box`.
void expectSameCells(const EvidentialGridMap& a, const EvidentialGridMap& b, const CellBox& box) {
  int differing = 0;
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) differing += a.cell(x, y) == b.cell(x, y) ? 0 : 1;
  }
  EXPECT_EQ(differing, 0);
}

// The filter's one-pass weighAndIntegrate gives what traceScan + scanLogPlausibility (on the map
// before the scan) + integrateScan give, bit for bit, on a map that already holds the room seen
// from elsewhere (so the weight and the conflict are not trivial), for beam strides 1 and 3; so
// does the wide-basin match's logPlausibility, which stores no traced cells.
TEST(IntegrateScanTest, WeighAndIntegrateEqualsTheSeparateSteps) {
  const BeamModel model(paperConfig(), kRes);
  EvidentialGridMap base(kRes);
  ScanAccumulator scratch;
  TracedScan traced;
  const Pose2 first(0.3, -0.4, 0.1);
  model.traceScan(first, testing_room::roomScan(first, 0.0, true), &traced);
  model.integrateScan(traced, &base, &scratch);

  const Pose2 second(-0.55, 0.62, 2.0);  // not the pose the scan was taken from: conflict
  const LaserScan scan = testing_room::roomScan(Pose2(-0.5, 0.6, 2.05), 0.0, true);
  for (int stride : {1, 3}) {
    SCOPED_TRACE(testing::Message() << "stride " << stride);
    EvidentialGridMap separate = base, fused = base;
    model.traceScan(second, scan, &traced);
    const double log_pl = model.scanLogPlausibility(separate, traced, stride);
    EXPECT_EQ(model.logPlausibility(base, second, scan, stride), log_pl);
    ScanConflict conflict;
    const double bits = model.integrateScan(traced, &separate, &scratch, &conflict);

    const BeamModel::ScanEvidence e =
        model.weighAndIntegrate(second, scan, &fused, &scratch, stride);
    EXPECT_EQ(e.log_plausibility, log_pl);
    EXPECT_LT(log_pl, -10.0);  // the wrong pose is penalised
    EXPECT_DOUBLE_EQ(e.conflict_added_bits, bits);
    EXPECT_GT(bits, 1.0);
    EXPECT_DOUBLE_EQ(e.conflict.mass_added, conflict.mass_added);
    EXPECT_DOUBLE_EQ(e.conflict.open_space_added, conflict.open_space_added);
    CellBox box = separate.observedBox();
    box.extend(fused.observedBox());
    expectSameCells(separate, fused, box);
  }
}

// The accumulator is laid out in the map's 32 x 32 tiles: a beam crossing tile borders at negative
// coordinates updates every crossed cell once, and cells two beams cross are fused (Dempster).
TEST(IntegrateScanTest, AccumulatorAcrossTilesAndNegativeCells) {
  ScanAccumulator scratch;
  scratch.reset(CellIndex{-1, -1}, 100);
  const ScanMass miss{0.0f, 0.8f};
  for (int x = -70; x <= 40; ++x) EXPECT_TRUE(scratch.add(x, -33, miss));
  EXPECT_TRUE(scratch.add(-33, -33, miss));  // a second beam through (-33, -33)
  EXPECT_FALSE(scratch.add(500, 0, miss));   // outside the window
  EXPECT_EQ(scratch.touched(), 111u);
  EvidentialGridMap map(kRes);
  scratch.applyTo(&map);
  EXPECT_NEAR(map.cell(-33, -33).free(), 0.96, 1e-5);  // 0.8 + 0.2 * 0.8
  EXPECT_NEAR(map.cell(-32, -33).free(), 0.8, 1e-5);
  EXPECT_NEAR(map.cell(-70, -33).free(), 0.8, 1e-5);
  EXPECT_NEAR(map.cell(40, -33).free(), 0.8, 1e-5);
  EXPECT_FALSE(map.cell(-71, -33).observed());
  EXPECT_FALSE(map.cell(0, -32).observed());
  // reset forgets the previous scan.
  scratch.reset(CellIndex{0, 0}, 100);
  EXPECT_EQ(scratch.touched(), 0u);
}

// A tile is cloned for a particle only when the scan changes one of its cells: clearing beams over
// cells already certainly free (m̃(e) = 1) leave a shared tile shared, and the first beam that
// changes a cell of it (an obstacle, or space not yet certain) gets the particle its own copy.
TEST(IntegrateScanTest, UnchangedTilesStayShared) {
  EvidentialGridMap map(kRes);
  for (int x = 0; x < 64; ++x)
    map.mutableCell(x, 3) = storedCell(0.0f, 1.0f);  // tiles (0,0), (1,0)
  map.mutableCell(40, 3) = storedCell(0.0f, 0.5f);   // tile (1, 0)
  EvidentialGridMap particle = map;
  const auto sharedTiles = [&]() {
    return static_cast<int>(map.tile(0, 0) == particle.tile(0, 0)) +
           static_cast<int>(map.tile(1, 0) == particle.tile(1, 0));
  };
  ASSERT_EQ(sharedTiles(), 2);
  ScanAccumulator scratch;
  const ScanMass clear{0.0f, 0.8f};
  scratch.reset(CellIndex{0, 0}, 100);
  for (int x = 0; x < 32; ++x) scratch.add(x, 3, clear);  // certainly free cells only
  EXPECT_EQ(scratch.applyTo(&particle), 0.0);
  EXPECT_EQ(sharedTiles(), 2);
  EXPECT_EQ(particle.cell(5, 3), storedCell(0.0f, 1.0f));

  scratch.reset(CellIndex{0, 0}, 100);
  for (int x = 32; x < 64; ++x) scratch.add(x, 3, clear);  // cell (40, 3) is only half free
  scratch.applyTo(&particle);
  EXPECT_EQ(map.tile(0, 0), particle.tile(0, 0));
  EXPECT_NE(map.tile(1, 0), particle.tile(1, 0));
  EXPECT_NEAR(particle.cell(40, 3).free(), 0.9, 1e-6);  // 0.5 + 0.5 * 0.8
  EXPECT_EQ(particle.cell(39, 3), storedCell(0.0f, 1.0f));
  EXPECT_NEAR(map.cell(40, 3).free(), 0.5, 1e-6);  // the other particle's map is untouched

  scratch.reset(CellIndex{0, 0}, 100);
  scratch.add(5, 3, ScanMass{0.1f, 0.7f});  // a little occupied mass: a certainly free cell changes
  EXPECT_GT(scratch.applyTo(&particle), 0.0);
  EXPECT_NE(map.tile(0, 0), particle.tile(0, 0));
  EXPECT_EQ(map.cell(5, 3), storedCell(0.0f, 1.0f));
}

// Bounded confidence through the whole update (algorithm.md §2.4): with flip_scans = 5, a cell
// that hits on its centre made certainly occupied turns free (BetP(o) < 1/2) at the 5th clearing
// scan, and a cell that clearing scans made certainly free turns occupied after the hits
// scansToFlip counts for the centred hit's mass 0.62554889 (InverseModelTest); unbounded, 30 hits
// leave it free. Cells at the floor under clearing beams are a fixed point: their tiles stay
// shared.
TEST(IntegrateScanTest, BoundedConfidenceFlipsAfterFlipScans) {
  for (const int flip_scans : {0, 5}) {
    SCOPED_TRACE(testing::Message() << "flip_scans " << flip_scans);
    SensorModelConfig config = paperConfig();
    config.flip_scans = flip_scans;
    const BeamModel model(config, kRes);
    EXPECT_NEAR(model.confidenceFloor(), confidenceFloor(flip_scans, 0.62554889, 0.8), 1e-5);
    TracedScan clear, hit;
    model.traceScan(kSensor, makeScan({3.0f}, {0.0f}, {1}), &clear);  // passes cell 20
    model.traceScan(kSensor, makeScan({1.0f}, {0.0f}, {1}), &hit);    // hits cell 20's centre
    EvidentialGridMap map(kRes);
    ScanAccumulator scratch;
    const auto occupied = [&]() { return map.cell(20, 0).occupied() > map.cell(20, 0).free(); };
    if (flip_scans > 0) {
      for (int i = 0; i < 100; ++i) model.integrateScan(hit, &map, &scratch);
      EXPECT_NEAR(map.cell(20, 0).unknown(), model.confidenceFloor(), 1e-6);
      int passes = 0;
      while (occupied() && passes < 30) {
        model.integrateScan(clear, &map, &scratch);
        ++passes;
      }
      EXPECT_EQ(passes, 5);
    }
    for (int i = 0; i < 100; ++i) model.integrateScan(clear, &map, &scratch);
    const Cell& c = map.cell(20, 0);
    EXPECT_EQ(c.occupied(), 0.0f);
    EXPECT_NEAR(c.unknown(), model.confidenceFloor(), 1e-6);
    const EvidentialGridMap before = map;
    model.integrateScan(clear, &map, &scratch);
    EXPECT_EQ(before.tile(0, 0), map.tile(0, 0));  // nothing changed: the tile is not copied

    int hits = 0;
    while (!occupied() && hits < 30) {
      model.integrateScan(hit, &map, &scratch);
      ++hits;
    }
    if (flip_scans == 0) {
      EXPECT_EQ(hits, 30);
      EXPECT_EQ(map.cell(20, 0).occupied(), 0.0f);
    } else {
      EXPECT_EQ(hits, scansToFlip(model.confidenceFloor(), 0.62554889, 30));
      EXPECT_GT(hits, 5);
    }
  }
}

// The map update keeps the tiles' occupied rows (the scan matcher's targets) true: rows built
// before a scan are updated cell by cell as the scan is applied, in place and in the clones a
// particle sharing the tiles gets; the other particle's rows stay those of its cells.
TEST(IntegrateScanTest, UpdateKeepsOccupiedRowsTrue) {
  const BeamModel model(SensorModelConfig(), 0.05);
  constexpr float kThreshold = 0.25f;
  EvidentialGridMap map(0.05);
  ScanAccumulator scratch;
  TracedScan traced;
  const auto integrate = [&](EvidentialGridMap* m, const Pose2& pose) {
    model.traceScan(pose, testing_room::roomScan(pose, 0.0, true), &traced);
    model.integrateScan(traced, m, &scratch);
  };
  // Builds (or reads) every tile's rows and compares them with the cells; the number of tiles.
  const auto checkRows = [&](const EvidentialGridMap& m) {
    int tiles = 0;
    testing_room::forEachAllocatedTile(m, [&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
      ++tiles;
      EvidentialGridMap::Tile::Rows spare{};
      const EvidentialGridMap::Tile::Rows& rows = tile.occupiedRows(kThreshold, &spare);
      EXPECT_NE(&rows, &spare);  // the tile's own rows
      for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) {
        const uint32_t bit = (rows[static_cast<size_t>(k >> EvidentialGridMap::kTileBits)] >>
                              (k & (EvidentialGridMap::kTileSize - 1))) &
                             1u;
        EXPECT_EQ(bit, tile.cells[static_cast<size_t>(k)].occupied() >= kThreshold ? 1u : 0u)
            << tx << " " << ty << " " << k;
      }
    });
    return tiles;
  };
  integrate(&map, Pose2(-0.3, -0.2, 0.2));
  EXPECT_GE(checkRows(map), 9);            // rows built from the cells
  integrate(&map, Pose2(0.4, 0.3, -0.5));  // written in place: rows updated cell by cell
  checkRows(map);
  EvidentialGridMap particle = map;             // shares every tile, and its rows
  integrate(&particle, Pose2(-0.6, 0.5, 1.0));  // clones: the rows come along and are updated
  checkRows(particle);
  checkRows(map);
  // Enough walls seen for the rows to mean something: some targets, not everything.
  size_t targets = 0;
  for (int y = -45; y < 45; ++y) {
    for (int x = -45; x < 45; ++x) targets += particle.cell(x, y).occupied() >= kThreshold;
  }
  EXPECT_GT(targets, 200u);
  EXPECT_LT(targets, 2000u);
}

// Cells in every state the map holds (vacuous, certainly free, certain, mixed, conflicted) against
// scan masses of every kind (clearing, hit, Θ gap, vacuous, certain), seeded.
std::vector<Cell> variedCells(std::mt19937* rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Cell> cells = {Cell{},
                             Cell::fromStored(0.0f, 1.0f, 0.0f),
                             Cell::fromStored(1.0f, 0.0f, 0.0f),
                             Cell::fromStored(1.0f, 0.0f, 7.5f),
                             Cell::fromStored(0.0f, 1.0f, 0.01f),
                             Cell::fromStored(0.3f, 0.3f, 2.0f)};
  while (cells.size() < 4000) {
    if (cells.size() % 10 == 0) {  // space seen free many times: clearing beams leave it as it is
      cells.push_back(Cell::fromStored(0.0f, 1.0f, 0.0f));
      continue;
    }
    const float o = u(*rng), e = u(*rng) * (1.0f - o);
    cells.push_back(Cell::fromStored(o, e, u(*rng) < 0.5f ? 0.0f : 10.0f * u(*rng)));
  }
  return cells;
}
std::vector<ScanMass> variedScanMasses(std::mt19937* rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<ScanMass> masses = {ScanMass{},           ScanMass{0.0f, 0.8f}, ScanMass{0.8f, 0.0f},
                                  ScanMass{1.0f, 0.0f}, ScanMass{0.0f, 1.0f}, ScanMass{0.1f, 0.7f}};
  while (masses.size() < 4000) {
    const float o = u(*rng) < 0.5f ? 0.0f : u(*rng);
    masses.push_back(ScanMass{o, u(*rng) * (1.0f - o)});
  }
  return masses;
}

// applyTo leaves every cell as updateCell leaves it, λ included, and sums the
// λ and m(∅) that updateCell's increments give; it keeps the tile's may-hold-occupied bits true
// (no clear bit on a cell with m̃(o) > 0) and its occupied rows, once built, exact. Unbounded and
// with a confidence floor (algorithm.md §2.4).
TEST(IntegrateScanTest, ApplyToIsUpdateCellPerCell) {
  std::mt19937 rng(11);
  for (const uint32_t floor_steps : {0u, confidenceFloorSteps(confidenceFloor(8, 0.63, 0.8))}) {
    SCOPED_TRACE(testing::Message() << "floor steps " << floor_steps);
    const std::vector<Cell> cells = variedCells(&rng);
    const std::vector<ScanMass> masses = variedScanMasses(&rng);
    EvidentialGridMap map(kRes);
    std::uniform_int_distribution<int> coordinate(-40, 40);
    for (size_t i = 0; i < cells.size(); ++i) {
      map.mutableCell(coordinate(rng), coordinate(rng)) = cells[i];
    }
    EvidentialGridMap::Tile::Rows scratch_rows;
    for (int ty = -2; ty <= 1; ++ty) {
      for (int tx = -2; tx <= 1; ++tx) {
        if (const auto* t = map.tile(tx, ty)) t->occupiedRows(0.2f, &scratch_rows);  // built
      }
    }
    EvidentialGridMap expected = map;
    ScanAccumulator acc;
    acc.reset(CellIndex{0, 0}, 64);
    // The scan's fused mass per cell, fused here in the order of the adds (as the accumulator
    // does).
    std::map<std::pair<int, int>, ScanMass> scan;
    for (size_t i = 0; i < masses.size(); ++i) {
      const int x = coordinate(rng), y = coordinate(rng);
      ASSERT_TRUE(acc.add(x, y, masses[i]));
      const auto [it, first] = scan.emplace(std::make_pair(x, y), masses[i]);
      if (!first) it->second = fuseDempster(it->second, masses[i]);
    }
    EvidentialGridMap applied = map;
    double applied_mass = 0.0;
    const double applied_lambda = acc.applyTo(&applied, &applied_mass, floor_steps);
    double lambda_sum = 0.0, mass_sum = 0.0;
    for (int y = -64; y < 64; ++y) {
      for (int x = -64; x < 64; ++x) {
        const auto it = scan.find(std::make_pair(x, y));
        Cell c = expected.cell(x, y);
        if (it == scan.end()) {
          ASSERT_EQ(applied.cell(x, y), c);
          continue;
        }
        ConflictIncrement inc;
        const float k = updateCell(c, it->second, &inc, floor_steps);
        ASSERT_EQ(applied.cell(x, y), c) << x << "," << y;
        if (k > 0.0f) {
          lambda_sum += inc.lambda_added;
          mass_sum += inc.one_minus_conflict_before * k;
        }
      }
    }
    // Summed in another order here: equal to rounding.
    EXPECT_NEAR(applied_lambda, lambda_sum, 1e-9 * std::max(1.0, lambda_sum));
    EXPECT_NEAR(applied_mass, mass_sum, 1e-9 * std::max(1.0, mass_sum));
    EXPECT_GT(lambda_sum, 1.0);
    for (int ty = -2; ty <= 1; ++ty) {
      for (int tx = -2; tx <= 1; ++tx) {
        const EvidentialGridMap::Tile* t = applied.tile(tx, ty);
        if (t == nullptr) continue;
        EvidentialGridMap::Tile::Rows fresh;
        const auto& rows = t->occupiedRows(0.2f, &fresh);
        for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) {
          const Cell& c = t->cells[static_cast<size_t>(k)];
          if (!t->mayHoldOccupied(k)) {
            ASSERT_EQ(c.occupied(), 0.0f) << k;  // a clear bit is exact
          }
          ASSERT_EQ(((rows[static_cast<size_t>(k >> 5)] >> (k & 31)) & 1u) != 0,
                    c.occupied() >= 0.2f)
              << k;
        }
      }
    }
  }
}

}  // namespace
}  // namespace evidential_slam
