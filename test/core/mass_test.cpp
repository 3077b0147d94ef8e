// Tests of the cell algebra (mass.h): conjunctive and Dempster's rule, scan-mass fusion, the
// normalised cell storage of algorithm.md §2.3 and its long-run invariants.
// All expected numbers are hand-computed from algorithm.md §1 and §2.3; the arithmetic is in the
// comments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "evidential_slam/core/mass.h"
#include "evidential_slam/core/measures.h"

namespace evidential_slam {
namespace {

constexpr double kExact = 1e-12;  // double arithmetic on Mass
constexpr double kFloat = 1e-6;   // values stored as float in ScanMass
// Cell storage: m̃(o), m̃(e) in steps of 2^-23 (float-like near certainty) ...
constexpr double kStored = 5e-5;
// ... and λ as a half float (11 significant bits).
double lambdaTolerance(double lambda) { return 1e-3 * lambda + 1e-7; }
// The explicit masses of a stored cell: both roundings (m(∅) = 1 - exp(-λ) carries λ's).
constexpr double kStoredMass = 3e-4;

void expectMass(const Mass& m, double conflict, double occupied, double free, double unknown,
                double tol) {
  EXPECT_NEAR(m.conflict, conflict, tol);
  EXPECT_NEAR(m.occupied, occupied, tol);
  EXPECT_NEAR(m.free, free, tol);
  EXPECT_NEAR(m.unknown, unknown, tol);
}

double sum(const Mass& m) { return m.conflict + m.occupied + m.free + m.unknown; }

// --- Mass construction -----------------------------------------------------------------------

// Mass::make puts the remainder on Θ: 1 - 0.1 - 0.2 - 0.3 = 0.4. vacuous() is m(Θ) = 1.
TEST(MassTest, MakeAndVacuous) {
  expectMass(Mass::make(0.1, 0.2, 0.3), 0.1, 0.2, 0.3, 0.4, kExact);
  expectMass(Mass::vacuous(), 0.0, 0.0, 0.0, 1.0, 0.0);
}

// --- Conjunctive rule (paper eq. 3/9) ------------------------------------------------------------

// m1 = (∅0, o0.6, e0.1, Θ0.3), m2 = (∅0, o0.2, e0.5, Θ0.3):
//   o' = 0.6*0.2 + 0.6*0.3 + 0.3*0.2 = 0.12 + 0.18 + 0.06 = 0.36
//   e' = 0.1*0.5 + 0.1*0.3 + 0.3*0.5 = 0.05 + 0.03 + 0.15 = 0.23
//   Θ' = 0.3*0.3 = 0.09
//   ∅' = 0.6*0.5 + 0.1*0.2 = 0.30 + 0.02 = 0.32  (= 1 - 0.36 - 0.23 - 0.09)
TEST(MassTest, ConjunctiveWorkedExample) {
  const Mass m1 = Mass::make(0.0, 0.6, 0.1);
  const Mass m2 = Mass::make(0.0, 0.2, 0.5);
  const Mass c = combineConjunctive(m1, m2);
  expectMass(c, 0.32, 0.36, 0.23, 0.09, kExact);
  EXPECT_NEAR(sum(c), 1.0, kExact);
}

// The conjunctive rule is commutative.
TEST(MassTest, ConjunctiveIsCommutative) {
  const Mass m1 = Mass::make(0.0, 0.6, 0.1);
  const Mass m2 = Mass::make(0.0, 0.2, 0.5);
  const Mass a = combineConjunctive(m1, m2);
  const Mass b = combineConjunctive(m2, m1);
  expectMass(a, b.conflict, b.occupied, b.free, b.unknown, kExact);
}

// Conflict already present is kept and new conflict is added:
// m = (∅0.2, o0.4, e0.1, Θ0.3), s = (∅0, o0.5, e0.2, Θ0.3):
//   o' = 0.4*0.5 + 0.4*0.3 + 0.3*0.5 = 0.2 + 0.12 + 0.15 = 0.47
//   e' = 0.1*0.2 + 0.1*0.3 + 0.3*0.2 = 0.02 + 0.03 + 0.06 = 0.11
//   Θ' = 0.3*0.3 = 0.09
//   ∅' = 0.2*1 + 0.4*0.2 + 0.1*0.5 = 0.2 + 0.08 + 0.05 = 0.33
TEST(MassTest, ConjunctiveKeepsExistingConflict) {
  const Mass m = Mass::make(0.2, 0.4, 0.1);
  const Mass s = Mass::make(0.0, 0.5, 0.2);
  expectMass(combineConjunctive(m, s), 0.33, 0.47, 0.11, 0.09, kExact);
}

// The vacuous mass is the neutral element of the conjunctive rule (also for a mass with ∅ > 0).
TEST(MassTest, VacuousIsNeutralForConjunctive) {
  const Mass m = Mass::make(0.2, 0.4, 0.1);
  expectMass(combineConjunctive(Mass::vacuous(), m), 0.2, 0.4, 0.1, 0.3, kExact);
  expectMass(combineConjunctive(m, Mass::vacuous()), 0.2, 0.4, 0.1, 0.3, kExact);
}

// Total conflict: certain occupied with certain free puts everything on ∅ (1*1 = 1).
TEST(MassTest, ConjunctiveTotalConflict) {
  const Mass occ = Mass::make(0.0, 1.0, 0.0);
  const Mass fre = Mass::make(0.0, 0.0, 1.0);
  expectMass(combineConjunctive(occ, fre), 1.0, 0.0, 0.0, 0.0, kExact);
}

// --- Dempster's rule -------------------------------------------------------------------------

// Same example normalised by 1 - ∅' = 0.68:
//   o = 0.36/0.68 = 0.52941176470588, e = 0.23/0.68 = 0.33823529411765,
//   Θ = 0.09/0.68 = 0.13235294117647
TEST(MassTest, DempsterWorkedExample) {
  const Mass m1 = Mass::make(0.0, 0.6, 0.1);
  const Mass m2 = Mass::make(0.0, 0.2, 0.5);
  const Mass d = combineDempster(m1, m2);
  expectMass(d, 0.0, 0.52941176470588, 0.33823529411765, 0.13235294117647, 1e-12);
  EXPECT_NEAR(sum(d), 1.0, kExact);
}

// Vacuous is neutral for Dempster's rule as well.
TEST(MassTest, VacuousIsNeutralForDempster) {
  const Mass m = Mass::make(0.0, 0.6, 0.1);
  expectMass(combineDempster(Mass::vacuous(), m), 0.0, 0.6, 0.1, 0.3, kExact);
  expectMass(combineDempster(m, Mass::vacuous()), 0.0, 0.6, 0.1, 0.3, kExact);
}

// Total conflict: documented (mass.h) to return the vacuous mass, never NaN.
TEST(MassTest, DempsterTotalConflictIsVacuous) {
  const Mass occ = Mass::make(0.0, 1.0, 0.0);
  const Mass fre = Mass::make(0.0, 0.0, 1.0);
  const Mass d = combineDempster(occ, fre);
  expectMass(d, 0.0, 0.0, 0.0, 1.0, kExact);
}

// --- fuseDempster on ScanMass ------------------------------------------------------------------

// hit (o0.63, Θ0.37) with miss (e0.8, Θ0.2):
//   o = 0.63*0.2 = 0.126, e = 0.37*0.8 = 0.296, Θ = 0.37*0.2 = 0.074, K = 0.63*0.8 = 0.504
//   normalised by 0.496: o = 0.25403225806, e = 0.59677419355, Θ = 0.14919354839
TEST(MassTest, FuseDempsterHitAndMiss) {
  const ScanMass hit{0.63f, 0.0f};
  const ScanMass miss{0.0f, 0.8f};
  const ScanMass f = fuseDempster(hit, miss);
  EXPECT_NEAR(f.occupied, 0.25403225806, kFloat);
  EXPECT_NEAR(f.free, 0.59677419355, kFloat);
  EXPECT_NEAR(f.unknown(), 0.14919354839, kFloat);
  const ScanMass g = fuseDempster(miss, hit);  // commutative
  EXPECT_NEAR(g.occupied, 0.25403225806, kFloat);
  EXPECT_NEAR(g.free, 0.59677419355, kFloat);
}

// A scan's mass of a cell that many beams cross, hit by some (a person beside the laser) and
// cleared by the rest, fused beam by beam: it stays a mass. The first value is one a run reached
// (m(Θ) = -1.2e-7 by rounding); fused on with the old rule it went negative, then to inf and NaN.
TEST(MassTest, FuseDempsterStaysInTheSimplexOverManyBeams) {
  const ScanMass hit{0.62183398f, 8.91711443e-06f}, near_hit{0.000141955345f, 0.607165754f};
  const ScanMass miss{0.0f, 0.8f};
  auto inSimplex = [](const ScanMass& m) {
    return std::isfinite(m.occupied) && std::isfinite(m.free) && m.occupied >= 0.0f &&
           m.free >= 0.0f && m.occupied + m.free <= 1.0f + 1e-6f;
  };
  ScanMass m{1.10691966e-13f, 1.00000012f};
  std::mt19937 rng(3);
  for (int i = 0; i < 100000; ++i) {
    const int k = static_cast<int>(rng() % 5);
    m = fuseDempster(m, k == 0 ? hit : k == 1 ? near_hit : miss);
    ASSERT_TRUE(inSimplex(m)) << "beam " << i << ": o " << m.occupied << " e " << m.free;
  }
}

// The m1/m2 worked example on ScanMass: o = 0.36/0.68, e = 0.23/0.68.
TEST(MassTest, FuseDempsterWorkedExample) {
  const ScanMass f = fuseDempster(ScanMass{0.6f, 0.1f}, ScanMass{0.2f, 0.5f});
  EXPECT_NEAR(f.occupied, 0.52941176470588, kFloat);
  EXPECT_NEAR(f.free, 0.33823529411765, kFloat);
  EXPECT_NEAR(f.unknown(), 0.13235294117647, kFloat);
}

// Two agreeing misses: e = 0.8*0.8 + 0.8*0.2 + 0.2*0.8 = 0.64 + 0.16 + 0.16 = 0.96, Θ = 0.04,
// K = 0.
TEST(MassTest, FuseDempsterAgreeingEvidence) {
  const ScanMass f = fuseDempster(ScanMass{0.0f, 0.8f}, ScanMass{0.0f, 0.8f});
  EXPECT_NEAR(f.occupied, 0.0, kFloat);
  EXPECT_NEAR(f.free, 0.96, kFloat);
  EXPECT_NEAR(f.unknown(), 0.04, kFloat);
  // A vacuous scan mass changes nothing.
  const ScanMass v = fuseDempster(ScanMass{}, ScanMass{0.3f, 0.2f});
  EXPECT_NEAR(v.occupied, 0.3, kFloat);
  EXPECT_NEAR(v.free, 0.2, kFloat);
}

// --- Cell storage (§2.3) ----------------------------------------------------------------------

// A default cell is vacuous: all zeros, not observed, toMass() = (∅0, o0, e0, Θ1).
TEST(CellTest, DefaultIsVacuous) {
  const Cell c;
  EXPECT_FALSE(c.observed());
  EXPECT_EQ(c.unknown(), 1.0f);
  expectMass(c.toMass(), 0.0, 0.0, 0.0, 1.0, 0.0);
}

// fromMass stores m̃ = m/(1 - m(∅)) and λ = -ln(1 - m(∅)):
// (∅0.32, o0.36, e0.23, Θ0.09): m̃(o) = 0.36/0.68 = 0.52941176, m̃(e) = 0.23/0.68 = 0.33823529,
// λ = -ln(0.68) = 0.38566248081198
TEST(CellTest, FromMassStoresNormalisedPairAndLambda) {
  const Cell c = Cell::fromMass(Mass::make(0.32, 0.36, 0.23));
  EXPECT_NEAR(c.occupied(), 0.52941176470588, kStored);
  EXPECT_NEAR(c.free(), 0.33823529411765, kStored);
  EXPECT_NEAR(c.unknown(), 0.13235294117647, kStored);
  EXPECT_NEAR(c.lambda(), 0.38566248081198, lambdaTolerance(0.38566248081198));
  EXPECT_TRUE(c.observed());
}

// fromMass followed by toMass returns the original masses (to float precision).
TEST(CellTest, FromMassToMassRoundTrip) {
  const std::vector<Mass> masses = {Mass::make(0.0, 0.0, 0.0),    Mass::make(0.0, 0.6, 0.1),
                                    Mass::make(0.32, 0.36, 0.23), Mass::make(0.5, 0.25, 0.25),
                                    Mass::make(0.0, 1.0, 0.0),    Mass::make(0.9, 0.01, 0.02),
                                    Mass::make(0.2, 0.0, 0.8)};
  for (const Mass& m : masses) {
    const Mass r = Cell::fromMass(m).toMass();
    expectMass(r, m.conflict, m.occupied, m.free, m.unknown, kStoredMass);
    EXPECT_NEAR(sum(r), 1.0, 1e-6);
  }
}

// updateCell on a vacuous cell stores the scan mass itself, with no conflict.
TEST(CellTest, UpdateVacuousCellGivesScanMass) {
  Cell c;
  updateCell(c, ScanMass{0.3f, 0.5f});
  EXPECT_NEAR(c.occupied(), 0.3, kStored);
  EXPECT_NEAR(c.free(), 0.5, kStored);
  EXPECT_NEAR(c.lambda(), 0.0, lambdaTolerance(0.0));
  EXPECT_TRUE(c.observed());
}

// Hand-computed sequence hit, miss, hit with hit = (o0.63, Θ0.37), miss = (e0.8, Θ0.2):
// 1) hit on vacuous: m̃ = (0.63, 0), λ = 0
// 2) miss: K = 0.63*0.8 = 0.504; m̃(o) = 0.63*0.2/0.496 = 0.25403225806,
//    m̃(e) = 0.37*0.8/0.496 = 0.59677419355; λ = -ln 0.496 = 0.70117935226
//    explicit masses: ∅ = 0.504, o = 0.126, e = 0.296, Θ = 0.074; EC = -log2 0.496 = 1.01158797428
// 3) hit: K = 0.59677419*0.63 = 0.37596774; m̃(o) = (0.25403226*1 + 0.14919355*0.63)/0.62403226
//    = 0.55770224864; m̃(e) = 0.59677419*0.37/0.62403226 = 0.35383820109;
//    λ = 0.70117935 - ln 0.62403226 = 1.17273256859
TEST(CellTest, UpdateCellHandSequence) {
  const ScanMass hit{0.63f, 0.0f};
  const ScanMass miss{0.0f, 0.8f};
  Cell c;
  updateCell(c, hit);
  EXPECT_NEAR(c.occupied(), 0.63, kStored);
  EXPECT_NEAR(c.free(), 0.0, kStored);
  EXPECT_NEAR(c.lambda(), 0.0, lambdaTolerance(0.0));

  updateCell(c, miss);
  EXPECT_NEAR(c.occupied(), 0.25403225806, kStored);
  EXPECT_NEAR(c.free(), 0.59677419355, kStored);
  EXPECT_NEAR(c.lambda(), 0.70117935226, lambdaTolerance(0.70117935226));
  expectMass(c.toMass(), 0.504, 0.126, 0.296, 0.074, kStoredMass);
  EXPECT_NEAR(externalConflict(c), 1.01158797428, lambdaTolerance(1.01158797428));

  updateCell(c, hit);
  EXPECT_NEAR(c.occupied(), 0.55770224864, kStored);
  EXPECT_NEAR(c.free(), 0.35383820109, kStored);
  EXPECT_NEAR(c.lambda(), 1.17273256859, lambdaTolerance(1.17273256859));
}

// updateCell (normalised storage) agrees with the explicit unnormalised conjunctive rule applied
// to Mass, step by step, on several sequences; λ equals -ln(1 - m(∅)) of the explicit result.
TEST(CellTest, UpdateCellMatchesExplicitConjunctiveRule) {
  const std::vector<std::vector<ScanMass>> sequences = {
      {{0.63f, 0.0f}, {0.0f, 0.8f}, {0.63f, 0.0f}, {0.0f, 0.8f}, {0.63f, 0.0f}},
      {{0.3f, 0.1f}, {0.05f, 0.7f}, {0.2f, 0.2f}, {0.9f, 0.05f}, {0.0f, 0.8f}, {0.4f, 0.0f}},
      {{0.0f, 0.8f}, {0.0f, 0.8f}, {0.0f, 0.8f}, {0.63f, 0.0f}, {0.63f, 0.0f}, {0.63f, 0.0f}},
      {{0.5f, 0.5f}, {0.1f, 0.0f}, {0.0f, 0.1f}, {0.25f, 0.25f}},
  };
  for (size_t s = 0; s < sequences.size(); ++s) {
    SCOPED_TRACE(testing::Message() << "sequence " << s);
    Cell cell;
    Mass mass = Mass::vacuous();
    for (const ScanMass& scan : sequences[s]) {
      updateCell(cell, scan);
      mass = combineConjunctive(mass, Mass::make(0.0, scan.occupied, scan.free));
      expectMass(cell.toMass(), mass.conflict, mass.occupied, mass.free, mass.unknown, kStoredMass);
      EXPECT_NEAR(cell.lambda(), -std::log(1.0 - mass.conflict),
                  lambdaTolerance(-std::log(1.0 - mass.conflict)));
    }
  }
}

// λ accumulates -ln(1 - K) of each update: two misses then two hits.
// miss on vacuous: e = 0.8; second miss: e = 0.8 + 0.2*0.8 = 0.96, K = 0, λ = 0.
// hit: K = 0.96*0.63 = 0.6048, λ = -ln(0.3952) = 0.92836331; m̃(e) = 0.96*0.37/0.3952 = 0.89878543,
//   m̃(o) = 0.04*0.63/0.3952 = 0.06376518.
// hit: K = 0.89878543*0.63 = 0.56623482, λ = 0.92836331 - ln(0.43376518) = 0.92836331 + 0.83525195
//   = 1.76361526; m̃(o) = (0.06376518 + 0.03745*0.63)/0.43376518 = 0.20139537,
//   m̃(e) = 0.89878543*0.37/0.43376518 = 0.76666044.
TEST(CellTest, LambdaAccumulatesMinusLogOneMinusK) {
  Cell c;
  updateCell(c, ScanMass{0.0f, 0.8f});
  updateCell(c, ScanMass{0.0f, 0.8f});
  EXPECT_NEAR(c.free(), 0.96, kStored);
  EXPECT_NEAR(c.lambda(), 0.0, lambdaTolerance(0.0));
  updateCell(c, ScanMass{0.63f, 0.0f});
  EXPECT_NEAR(c.lambda(), 0.92836331, lambdaTolerance(0.92836331));
  EXPECT_NEAR(c.free(), 0.89878543, kStored);
  EXPECT_NEAR(c.occupied(), 0.06376518, kStored);
  updateCell(c, ScanMass{0.63f, 0.0f});
  EXPECT_NEAR(c.lambda(), 1.76361526, lambdaTolerance(1.76361526));
  EXPECT_NEAR(c.occupied(), 0.20139537, kStored);
  EXPECT_NEAR(c.free(), 0.76666044, kStored);
  // EC in bits = λ / ln 2 = 1.76361526 / 0.69314718 = 2.54435899
  EXPECT_NEAR(externalConflict(c), 2.54435899, lambdaTolerance(2.54435899));
}

// 10^6 alternating hit/miss updates (the failure case of naive float storage, §2.3): no NaN/inf,
// stored masses in [0,1], toMass() sums to 1, EC finite and never decreasing.
// The cell converges to m̃(e) -> 1, so each hit adds K -> 0.63, i.e. -ln(0.37) = 0.994 nats
// (1.434 bits), and each miss adds 0. λ is stored as a half float: once its spacing exceeds twice
// that increment the rounded sum stops growing. Half floats in [2048, 4096) are 2 apart, so λ grows
// to 2048 nats and stays: EC = 2048 / ln 2 = 2954.6 bits (stored exactly).
TEST(CellTest, AlternatingUpdatesNeverSaturate) {
  const ScanMass hit{0.63f, 0.0f};
  const ScanMass miss{0.0f, 0.8f};
  Cell c;
  double previous_ec = 0.0;
  int failures = 0;  // stop reporting after a few failures, the loop is long
  for (int i = 0; i < 1000000 && failures < 5; ++i) {
    updateCell(c, (i % 2 == 0) ? hit : miss);
    const bool finite = std::isfinite(c.occupied()) && std::isfinite(c.free()) &&
                        std::isfinite(c.lambda()) && std::isfinite(c.unknown());
    const bool in_range = c.occupied() >= 0.0f && c.occupied() <= 1.0f && c.free() >= 0.0f &&
                          c.free() <= 1.0f && c.unknown() >= 0.0f && c.unknown() <= 1.0f;
    const Mass m = c.toMass();
    const bool mass_ok = std::isfinite(m.conflict) && std::isfinite(m.occupied) &&
                         std::isfinite(m.free) && std::isfinite(m.unknown) &&
                         std::fabs(sum(m) - 1.0) <= 1e-6 && m.conflict >= 0.0 &&
                         m.conflict <= 1.0 && m.occupied >= -1e-9 && m.free >= -1e-9 &&
                         m.unknown >= -1e-9;  // exact sign: ToMassIsNonNegative...
    const double ec = externalConflict(c);
    const bool ec_ok = std::isfinite(ec) && ec >= previous_ec;
    if (!(finite && in_range && mass_ok && ec_ok)) {
      ++failures;
      ADD_FAILURE() << "update " << i << ": finite=" << finite << " in_range=" << in_range
                    << " mass_ok=" << mass_ok << " ec_ok=" << ec_ok << "; o=" << c.occupied()
                    << " e=" << c.free() << " unknown()=" << c.unknown() << " lambda=" << c.lambda()
                    << "; toMass: conflict=" << m.conflict << " occupied=" << m.occupied
                    << " free=" << m.free << " unknown=" << m.unknown << " sum=" << sum(m)
                    << "; EC=" << ec << " previous EC=" << previous_ec;
    }
    previous_ec = ec;
  }
  EXPECT_NEAR(previous_ec, 2048.0 / std::log(2.0), 1e-9);
  EXPECT_GT(c.free(), 0.99f);  // converged to "free" (misses dominate: 0.8 vs 0.63)
}

// toMass() of a cell whose stored pair sums to 1 (unknown() == 0) must not return a negative m(Θ):
// (o, e) = (0.0011497404f, 0.99885029f) is a state the alternating-update test reached with float
// storage (update 21); stored, the pair rounds to 9645 + 8378963 = 2^23 steps: m̃(Θ) = 0 exactly.
TEST(CellTest, ToMassIsNonNegativeWhenStoredPairSumsToOne) {
  Cell c = Cell::fromStored(0.0011497404193505645f, 0.99885028600692749f, 10.935624122619629f);
  ASSERT_EQ(c.unknown(), 0.0f);
  const Mass m = c.toMass();
  EXPECT_GE(m.unknown, 0.0);
  EXPECT_GE(m.occupied, 0.0);
  EXPECT_GE(m.free, 0.0);
  EXPECT_GE(m.conflict, 0.0);
  EXPECT_NEAR(sum(m), 1.0, 1e-12);
  // Same with no conflict: toMass must give m(Θ) = 0 exactly up to sign, i.e. >= 0.
  c.setLambda(0.0f);
  EXPECT_GE(c.toMass().unknown, 0.0);
}

// A NaN (an update of NaN scan masses, a corrupt input) must not be stored: std::max(NaN, 0) is
// NaN, a NaN λ reads back as NaN EC and NaN 1 - m(∅), and a NaN mass converted to steps is
// undefined. NaN is stored as 0; the clamps of ordinary values are unchanged.
TEST(CellTest, NaNIsStoredAsZero) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Cell c = Cell::fromStored(0.25f, 0.5f, 2.0f);
  c.setLambda(nan);
  EXPECT_EQ(c.lambda(), 0.0f);
  EXPECT_EQ(c.oneMinusConflict(), 1.0);
  EXPECT_FALSE(c.conflicted());
  c.setMasses(nan, 0.5f);
  EXPECT_EQ(c.occupied(), 0.0f);
  EXPECT_EQ(c.free(), 0.5f);
  c.setMasses(0.25f, nan);
  EXPECT_EQ(c.occupied(), 0.25f);
  EXPECT_EQ(c.free(), 0.0f);
  c.setLambda(-1.0f);
  EXPECT_EQ(c.lambda(), 0.0f);
  c.setLambda(std::numeric_limits<float>::infinity());
  EXPECT_EQ(c.lambda(), 65504.0f);
  c.setLambda(1.5f);
  EXPECT_EQ(c.lambda(), 1.5f);
  // An update with a NaN scan mass leaves a finite λ behind.
  Cell u = Cell::fromStored(0.0f, 0.9f, 0.0f);
  updateCell(u, ScanMass{nan, 0.0f});
  EXPECT_FALSE(std::isnan(u.lambda()));
  EXPECT_FALSE(std::isnan(externalConflict(u)));
}

// Same invariants when the evidence is balanced so the cell stays mixed:
// hit (o0.5, Θ0.5) and miss (e0.5, Θ0.5) alternating, 10^6 times. The cycle converges to
// after-miss (0.5, 0.5) -> hit: K = 0.5*0.5 = 0.25, m̃ = (0.5/0.75, 0.25/0.75) = (2/3, 1/3)
// -> miss: K = (2/3)*0.5 = 1/3, m̃ = ((1/3)/(2/3), (1/3)/(2/3)) = (0.5, 0.5).
// Per cycle λ += -ln(0.75) - ln(2/3) = ln 2 (0.288 + 0.405 nats) until the half-float storage of λ
// rounds: in [512, 1024) half floats are 0.5 apart and both increments round up to 0.5; in
// [1024, 2048) they are 1 apart and both round to 0. So λ ends at 1024 nats: EC = 1024 / ln 2.
TEST(CellTest, AlternatingBalancedUpdatesStayFinite) {
  Cell c;
  double previous_lambda = 0.0;
  bool ok = true;
  for (int i = 0; i < 1000000 && ok; ++i) {
    updateCell(c, (i % 2 == 0) ? ScanMass{0.5f, 0.0f} : ScanMass{0.0f, 0.5f});
    const Mass m = c.toMass();
    ok = std::isfinite(c.lambda()) && c.lambda() >= previous_lambda && c.occupied() >= 0.0f &&
         c.occupied() <= 1.0f && c.free() >= 0.0f && c.free() <= 1.0f && c.unknown() >= 0.0f &&
         std::fabs(sum(m) - 1.0) <= 1e-6 && std::isfinite(internalConflict(c)) &&
         std::isfinite(pignistic(c));
    EXPECT_TRUE(ok) << "update " << i << ": o=" << c.occupied() << " e=" << c.free()
                    << " lambda=" << c.lambda();
    previous_lambda = c.lambda();
  }
  EXPECT_NEAR(externalConflict(c), 1024.0 / std::log(2.0), 1e-9);
  EXPECT_NEAR(c.occupied(), 0.5, 1e-3);  // after a miss (even count): the (0.5, 0.5) phase
  EXPECT_NEAR(c.free(), 0.5, 1e-3);
}

// Storage: masses round to the nearest 2^-23 with the pair kept in the simplex (m̃(Θ) >= 0
// exactly), out-of-range inputs are clamped, λ is a half float and never negative.
TEST(CellTest, StorageRoundsIntoTheSimplex) {
  constexpr double kSteps = 8388608.0;
  const Cell a = Cell::fromStored(0.3f, 0.5f, 0.0f);
  // 0.3f (0.30000001) * 2^23 = 2516582.6 -> 2516583; 0.5 * 2^23 = 4194304; the rest: 1677721
  EXPECT_EQ(a.occupied(), static_cast<float>(2516583.0 / kSteps));
  EXPECT_EQ(a.free(), 0.5f);
  EXPECT_EQ(a.unknown(), static_cast<float>(1677721.0 / kSteps));
  // Every stored mass is a float exactly: storing it again changes nothing.
  EXPECT_TRUE(Cell::fromStored(a.occupied(), a.free(), a.lambda()) == a);
  const Cell b = Cell::fromStored(0.6f, 0.6f, 0.0f);  // sums to 1.2: free gets the remainder
  EXPECT_EQ(b.unknown(), 0.0f);
  EXPECT_NEAR(b.occupied(), 0.6, 1e-7);
  EXPECT_NEAR(b.free(), 0.4, 1e-7);
  const Cell c = Cell::fromStored(-0.1f, 1.5f, -2.0f);
  EXPECT_EQ(c.occupied(), 0.0f);
  EXPECT_EQ(c.free(), 1.0f);
  EXPECT_EQ(c.lambda(), 0.0f);
  EXPECT_EQ(Cell::fromStored(0.0f, 0.0f, 1.0f / 3.0f).lambda(), 0.333251953125f);  // 11 bits
  EXPECT_EQ(Cell::fromStored(0.0f, 0.0f, 1e6f).lambda(), 65504.0f);  // the largest half float
  // Near certainty as fine as a float: m̃(Θ) = 1e-6 survives.
  EXPECT_NEAR(Cell::fromStored(0.0f, 1.0f - 1e-6f, 0.0f).unknown(), 1e-6, 1e-7);
  EXPECT_EQ(sizeof(Cell), 8u);
}

// Storing rounds a mass to the nearest step, half-way up (as round(m * 2^23 + 1/2) in exact
// arithmetic), and reading gives the step times 2^-23, whichever float is stored: checked against
// double arithmetic (exact here) on floats around every power of two from 2^-24 to 1, where float
// rounding of m * 2^23 + 1/2 could differ, and on 100 000 spread over [0, 1].
TEST(CellTest, StorageRoundsLikeExactArithmetic) {
  constexpr double kSteps = 8388608.0;
  const auto expectStored = [&](float m) {
    const double steps = std::floor(std::min(static_cast<double>(m), 1.0) * kSteps + 0.5);
    const Cell c = Cell::fromStored(m, 0.0f, 0.0f);
    ASSERT_EQ(static_cast<double>(c.occupied()), steps / kSteps) << m;
  };
  for (int e = -24; e <= 0; ++e) {
    const float p = std::ldexp(1.0f, e);
    float below = p, above = p;
    for (int i = 0; i < 64; ++i) {
      expectStored(below);
      expectStored(above);
      below = std::nextafter(below, 0.0f);
      above = std::nextafter(above, 2.0f);
    }
    expectStored(0.5f * p + std::ldexp(1.0f, -25));  // odd multiples of half a step
  }
  for (int i = 0; i <= 100000; ++i) expectStored(static_cast<float>(i) / 100000.0f + 1e-9f);
}

// A certainly free cell (m̃(e) = 1) is a fixed point of every scan mass without m(o): updateCell
// skips it with the same result the formulas give; a hit still conflicts with it.
TEST(CellTest, CertainlyFreeCellIsAFixedPointOfMisses) {
  Cell c = Cell::fromStored(0.0f, 1.0f, 0.25f);
  const Cell before = c;
  EXPECT_EQ(updateCell(c, ScanMass{0.0f, 0.8f}), 0.0f);
  EXPECT_TRUE(c == before);
  ConflictIncrement increment;
  EXPECT_NEAR(updateCell(c, ScanMass{0.63f, 0.0f}, &increment), 0.63f, 1e-6f);
  EXPECT_EQ(increment.one_minus_conflict_before, std::exp(-static_cast<double>(before.lambda())));
  EXPECT_NEAR(increment.lambda_added, -std::log(0.37), 1e-6);
  EXPECT_NEAR(c.lambda(), 0.25 - std::log(0.37), lambdaTolerance(1.244));
  EXPECT_EQ(c.free(), 1.0f);  // K normalises the hit away: m̃ stays (0, 1)
}

// A certain, opposite update (K = 1) caps K at the largest float below 1: λ grows by
// -ln(2^-24) = 24 ln 2 = 16.6355 nats instead of becoming infinite; the masses stay finite.
TEST(CellTest, TotalConflictKeepsLambdaFinite) {
  Cell c = Cell::fromStored(1.0f, 0.0f, 0.0f);
  ConflictIncrement increment;
  increment.one_minus_conflict_before = -1.0;
  EXPECT_EQ(updateCell(c, ScanMass{0.0f, 1.0f}, &increment), 1.0f);
  EXPECT_EQ(increment.one_minus_conflict_before, 1.0);
  EXPECT_NEAR(increment.lambda_added, 24.0 * std::log(2.0), 1e-5);
  EXPECT_TRUE(std::isfinite(c.lambda()));
  EXPECT_NEAR(c.lambda(), 24.0 * std::log(2.0), lambdaTolerance(16.6355));
  EXPECT_TRUE(std::isfinite(c.occupied()) && std::isfinite(c.free()));
  EXPECT_TRUE(std::isfinite(externalConflict(c)));
}

// The tabulated e^{-λ} is std::exp's double for every λ a cell can hold (a half float: every
// finite non-negative one, checked exhaustively), and e^{-65504} = 0 at the clamp's maximum.
TEST(CellTest, OneMinusConflictIsExpOfMinusLambda) {
  EXPECT_EQ(Cell{}.oneMinusConflict(), 1.0);
  EXPECT_EQ(Cell::fromStored(0.2f, 0.3f, 0.5f).oneMinusConflict(), std::exp(-0.5));
  int checked = 0;
  for (uint32_t bits = 0; bits < 0x7C00u; ++bits) {  // 0x7C00: +infinity
    const float lambda = static_cast<float>(
        Eigen::half(Eigen::half_impl::raw_uint16_to_half(static_cast<uint16_t>(bits))));
    const Cell c = Cell::fromStored(0.0f, 0.0f, lambda);
    ASSERT_EQ(c.lambda(), lambda);
    ASSERT_EQ(c.oneMinusConflict(), std::exp(-static_cast<double>(lambda))) << lambda;
    ++checked;
  }
  EXPECT_EQ(checked, 0x7C00);
  EXPECT_EQ(Cell::fromStored(0.0f, 0.0f, 1e9f).oneMinusConflict(), std::exp(-65504.0));
}

// --- Bounded confidence (algorithm.md §2.4) -----------------------------------------------------

// A cell held free at the floor f (m̃ = (0, 1 - f, f)); scans of mass h on {o} (the same holds for
// an occupied cell and h on {e}). One scan: m̃(o) : m̃(e) = f h : (1 - f)(1 - h), so one scan flips
// it iff f > 1 - h. Two (each discounted back to f, D = f h + (1 - f)(1 - h)): flips iff
//   (1 - f) f h / D + f h > (1 - f)² (1 - h)² / D.
// h = 0.63: 0.6031 f² - 1.1369 f + 0.1369 < 0, i.e. f > (1.1369 - √0.96228405) / 1.2062
//   = (1.1369 - 0.98096078) / 1.2062 = 0.12928140.
// h = 0.8 (the stronger mass, which sets the floor): 0.36 f² - 1.04 f + 0.04 < 0, i.e.
//   f > (1.04 - √1.024) / 0.72 = (1.04 - 1.01192885) / 0.72 = 0.03898771.
// The floor for exactly two scans of 0.8 is the geometric middle √(0.2 · 0.03898771) = 0.08830369.
TEST(BoundedConfidenceTest, FloorForTwoScansIsHandComputed) {
  EXPECT_NEAR(confidenceFloor(2, 0.63, 0.8), 0.08830369, 1e-7);
  EXPECT_NEAR(confidenceFloor(1, 0.63, 0.8), std::sqrt(0.2), 1e-9);  // between 1 - h and 1
  EXPECT_EQ(scansToFlip(0.36, 0.63, 10), 2);
  EXPECT_EQ(scansToFlip(0.38, 0.63, 10), 1);
  EXPECT_EQ(scansToFlip(0.1292, 0.63, 10), 3);
  EXPECT_EQ(scansToFlip(0.1294, 0.63, 10), 2);
  EXPECT_EQ(scansToFlip(0.0389, 0.8, 10), 3);
  EXPECT_EQ(scansToFlip(0.0391, 0.8, 10), 2);
  // The stronger mass sets the floor, whichever it is.
  EXPECT_EQ(confidenceFloor(2, 0.63, 0.8), confidenceFloor(2, 0.8, 0.63));
  // 0 turns it off.
  EXPECT_EQ(confidenceFloor(0, 0.63, 0.8), 0.0);
  EXPECT_EQ(confidenceFloorSteps(0.0), 0u);
}

// Stored cells with the floor of N passes (e 0.8) and hits (o 0.63): a cell made certainly
// occupied by hits turns free (BetP(o) < 1/2, i.e. m̃(e) > m̃(o)) after exactly N passes, and a cell
// made certainly free by passes turns occupied after the hits scansToFlip counts (more than N);
// m̃(Θ) is never below the floor; λ grows only on the contradicting updates.
TEST(BoundedConfidenceTest, ConfidentCellsFlipAfterTheirScans) {
  const ScanMass hit{0.63f, 0.0f}, pass{0.0f, 0.8f};
  for (int n = 1; n <= 9; ++n) {
    SCOPED_TRACE(testing::Message() << "N = " << n);
    const double floor = confidenceFloor(n, hit.occupied, pass.free);
    const uint32_t floor_steps = confidenceFloorSteps(floor);
    ASSERT_GT(floor_steps, 0u);
    Cell o;
    for (int i = 0; i < 200; ++i) updateCell(o, hit, nullptr, floor_steps);
    EXPECT_EQ(o.freeSteps(), 0u);
    EXPECT_EQ(o.unknownSteps(), floor_steps);
    EXPECT_EQ(o.lambda(), 0.0f);  // no contradiction: no conflict
    int passes = 0;
    while (o.free() <= o.occupied() && passes < 100) {
      updateCell(o, pass, nullptr, floor_steps);
      EXPECT_GE(o.unknownSteps(), floor_steps);
      ++passes;
    }
    EXPECT_EQ(passes, n);
    EXPECT_GT(o.lambda(), 0.0f);

    Cell c;
    for (int i = 0; i < 200; ++i) updateCell(c, pass, nullptr, floor_steps);
    EXPECT_EQ(c.occupiedSteps(), 0u);
    EXPECT_EQ(c.unknownSteps(), floor_steps);
    EXPECT_EQ(c.lambda(), 0.0f);
    int hits = 0;
    while (c.occupied() <= c.free() && hits < 100) {
      updateCell(c, hit, nullptr, floor_steps);
      EXPECT_GE(c.unknownSteps(), floor_steps);
      ++hits;
    }
    EXPECT_EQ(hits, scansToFlip(floor, hit.occupied, 100));
    EXPECT_GE(hits, n);
    if (n >= 2) {
      EXPECT_GT(hits, n);  // hits are weaker than passes
    }
  }
}

// Without a floor the same cell never flips: 50 hits on a certainly free cell leave m̃(o) = 0
// (the conjunctive rule moves each hit's mass to m(∅): λ grows by -ln(1 - 0.63) = 0.994 a hit).
TEST(BoundedConfidenceTest, UnboundedCellNeverFlips) {
  Cell c;
  for (int i = 0; i < 200; ++i) updateCell(c, ScanMass{0.0f, 0.8f});
  ASSERT_EQ(c.free(), 1.0f);
  for (int i = 0; i < 50; ++i) updateCell(c, ScanMass{0.63f, 0.0f});
  EXPECT_EQ(c.occupied(), 0.0f);
  EXPECT_NEAR(c.lambda(), 50 * 0.99425227, 0.5);  // half-float λ, rounded at each of 50 adds
}

// On random sequences of scan masses: the floor is never violated after an update; a floor of 0 is
// the unbounded update bit for bit; λ's increment is -ln(1 - K) of the discounted cell, so updates
// without contradiction (K = 0) leave λ as it was.
TEST(BoundedConfidenceTest, FloorHoldsOnRandomUpdates) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const uint32_t floor_steps = confidenceFloorSteps(confidenceFloor(8, 0.63, 0.8));
  for (int run = 0; run < 200; ++run) {
    Cell bounded, unbounded, zero;
    for (int i = 0; i < 100; ++i) {
      const float o = u(rng) < 0.5f ? 0.0f : u(rng);
      const ScanMass s{o, u(rng) < 0.5f ? 0.0f : u(rng) * (1.0f - o)};
      const float lambda_before = bounded.lambda();
      const float k = updateCell(bounded, s, nullptr, floor_steps);
      ASSERT_GE(bounded.unknownSteps(), floor_steps);
      if (k == 0.0f) {
        ASSERT_EQ(bounded.lambda(), lambda_before);
      }
      updateCell(unbounded, s);
      updateCell(zero, s, nullptr, 0);
      ASSERT_EQ(zero, unbounded);
    }
  }
}

}  // namespace
}  // namespace evidential_slam
