// Tests of the uncertainty measures (measures.h) on the prototype belief states of the paper
// (§4, Fig. 3) and of the layer names / values. Expected numbers are hand-computed from
// algorithm.md §2 (paper eqs. 10, 11, 13, 15/16, 18); the arithmetic is in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "evidential_slam/core/mass.h"
#include "evidential_slam/core/measures.h"
#include "cell_support.h"

namespace evidential_slam {
namespace {

using namespace testing_cells;

// Cells store m̃ in steps of 2^-23 and λ as a half float (2^-11 relative): a measure of a cell
// made from nominal masses is that close to the hand-computed value (EC = 1 bit: within 3.5e-4).
constexpr double kTol = 5e-4;

// Binary Shannon entropy in bits with 0 log 0 = 0 (reference formula, eq. 11).
double binaryEntropy(double p) {
  double h = 0.0;
  if (p > 0.0) h -= p * std::log2(p);
  if (p < 1.0) h -= (1.0 - p) * std::log2(1.0 - p);
  return h;
}

// Vacuous cell, m(Θ) = 1 (Fig. 3: maximal non-specificity):
// BetP = (0 + 1/2)/1 = 0.5, H = 1, NS = 1, IC = 0 (both m̃ terms are 0), EC = -log2(1) = 0.
TEST(MeasuresTest, VacuousPrototype) {
  const Cell c;
  EXPECT_NEAR(pignistic(c), 0.5, kTol);
  EXPECT_NEAR(entropyBits(c), 1.0, kTol);
  EXPECT_NEAR(nonSpecificity(c), 1.0, kTol);
  EXPECT_NEAR(internalConflict(c), 0.0, kTol);
  EXPECT_NEAR(externalConflict(c), 0.0, kTol);
}

// Balanced Bayesian o = e = 0.5 (Fig. 3: maximal internal conflict):
// BetP = 0.5, H = 1, NS = 0, IC = -(0.5 log2 0.5 + 0.5 log2 0.5) = 1, EC = 0.
TEST(MeasuresTest, BalancedBayesianPrototype) {
  const Cell c = cellWithConflict(0.5, 0.5, 0.0);
  EXPECT_NEAR(pignistic(c), 0.5, kTol);
  EXPECT_NEAR(entropyBits(c), 1.0, kTol);
  EXPECT_NEAR(nonSpecificity(c), 0.0, kTol);
  EXPECT_NEAR(internalConflict(c), 1.0, kTol);
  EXPECT_NEAR(externalConflict(c), 0.0, kTol);
}

// Certain occupied m(o) = 1: BetP = 1, H = 0, NS = 0, IC = -(1 * log2 1) = 0, EC = 0.
TEST(MeasuresTest, CertainOccupiedPrototype) {
  const Cell c = cellWithConflict(1.0, 0.0, 0.0);
  EXPECT_NEAR(pignistic(c), 1.0, kTol);
  EXPECT_NEAR(entropyBits(c), 0.0, kTol);
  EXPECT_NEAR(nonSpecificity(c), 0.0, kTol);
  EXPECT_NEAR(internalConflict(c), 0.0, kTol);
  EXPECT_NEAR(externalConflict(c), 0.0, kTol);
}

// Certain free m(e) = 1: BetP = 0, H = 0, IC = 0.
TEST(MeasuresTest, CertainFreePrototype) {
  const Cell c = cellWithConflict(0.0, 1.0, 0.0);
  EXPECT_NEAR(pignistic(c), 0.0, kTol);
  EXPECT_NEAR(entropyBits(c), 0.0, kTol);
  EXPECT_NEAR(internalConflict(c), 0.0, kTol);
}

// Half non-specific, half conflicting: o = e = 0.25, Θ = 0.5.
// BetP = 0.25 + 0.25 = 0.5, H = 1, NS = 0.5,
// IC = -(0.25 log2 0.75 + 0.25 log2 0.75) = -0.5 log2 0.75 = 0.5 * 0.41503750 = 0.20751875.
TEST(MeasuresTest, QuarterQuarterHalfPrototype) {
  const Cell c = cellWithConflict(0.25, 0.25, 0.0);
  EXPECT_NEAR(pignistic(c), 0.5, kTol);
  EXPECT_NEAR(entropyBits(c), 1.0, kTol);
  EXPECT_NEAR(nonSpecificity(c), 0.5, kTol);
  EXPECT_NEAR(internalConflict(c), 0.20751874963942, kTol);
  EXPECT_NEAR(externalConflict(c), 0.0, kTol);
}

// An asymmetric conflict-free mass (∅0, o0.6, e0.1, Θ0.3):
// BetP = 0.6 + 0.15 = 0.75; H = -(0.75 log2 0.75 + 0.25 log2 0.25) = 0.31127812 + 0.5 = 0.81127812;
// IC = -(0.6 log2 0.9 + 0.1 log2 0.4) = 0.6*0.15200309 + 0.1*1.32192809 = 0.22339467.
TEST(MeasuresTest, AsymmetricMass) {
  const Cell c = cellWithConflict(0.6, 0.1, 0.0);
  EXPECT_NEAR(pignistic(c), 0.75, kTol);
  EXPECT_NEAR(entropyBits(c), 0.81127812445913, kTol);
  EXPECT_NEAR(nonSpecificity(c), 0.3, kTol);
  EXPECT_NEAR(internalConflict(c), 0.22339466555577, kTol);
}

// With conflict m(∅) = 0.5 and o = e = 0.25, Θ = 0: EC = -log2(1 - 0.5) = 1 bit exactly;
// normalised m̃ = (0.5, 0.5) has dissonance 1, scaled by 1 - m(∅): IC = 0.5;
// BetP = 0.25/0.5 = 0.5, H = 1; NS = m(Θ) = 0.
TEST(MeasuresTest, ConflictHalfPrototype) {
  const Cell c = cellWithConflict(0.5, 0.5, 0.5);
  EXPECT_NEAR(externalConflict(c), 1.0, kTol);
  EXPECT_NEAR(internalConflict(c), 0.5, kTol);
  EXPECT_NEAR(pignistic(c), 0.5, kTol);
  EXPECT_NEAR(entropyBits(c), 1.0, kTol);
  EXPECT_NEAR(nonSpecificity(c), 0.0, kTol);
}

// (∅0.5, o0.3, e0.1, Θ0.1): m̃ = (0.6, 0.2, Θ0.2), pl̃(o) = 0.8, pl̃(e) = 0.4.
// IC = -0.5 (0.6 log2 0.8 + 0.2 log2 0.4) = 0.5 (0.19315686 + 0.26438562) = 0.22877124.
// BetP = (0.3 + 0.05)/0.5 = 0.7; H = -(0.7 log2 0.7 + 0.3 log2 0.3) = 0.88129090; EC = 1;
// NS = m(Θ) = 0.1 (eq. 13 is on the raw mass m, not on m̃).
TEST(MeasuresTest, ConflictAsymmetricMass) {
  const Cell c = cellWithConflict(0.6, 0.2, 0.5);
  EXPECT_NEAR(internalConflict(c), 0.22877123795494, kTol);
  EXPECT_NEAR(pignistic(c), 0.7, kTol);
  EXPECT_NEAR(entropyBits(c), 0.88129089923069, kTol);
  EXPECT_NEAR(externalConflict(c), 1.0, kTol);
  EXPECT_NEAR(nonSpecificity(c), 0.1, kTol);
}

// EC for m(∅) = 0.75 is -log2(0.25) = 2 bits; m(∅) = 0.875 gives 3 bits.
TEST(MeasuresTest, ExternalConflictIsLogarithmic) {
  EXPECT_NEAR(externalConflict(cellWithConflict(0.5, 0.5, 0.75)), 2.0, 2.0 * kTol);  // λ's relative error
  EXPECT_NEAR(externalConflict(cellWithConflict(0.5, 0.5, 0.875)), 3.0, 3.0 * kTol);
  // λ = 100 nats -> EC = 100/ln 2 = 144.26950409 bits (unbounded, no saturation at m(∅) ≈ 1).
  Cell c = cellWithConflict(0.5, 0.5, 0.0);
  c.setLambda(100.0f);
  EXPECT_NEAR(externalConflict(c), 144.26950408889634, 1e-4);
  EXPECT_NEAR(internalConflict(c), 0.0, 1e-9);  // scaled by 1 - m(∅) = e^-100
  EXPECT_NEAR(pignistic(c), 0.5, kTol);         // BetP reads m̃, still defined
}

// IC of a Bayesian mass (m(Θ) = m(∅) = 0) equals the Shannon entropy of p = m(o), and so does
// entropyBits; p = 0 and p = 1 exercise the "term with m̃ = 0 contributes 0" rule.
TEST(MeasuresTest, InternalConflictEqualsEntropyForBayesian) {
  for (int k = 0; k <= 20; ++k) {
    const double p = k / 20.0;
    SCOPED_TRACE(testing::Message() << "p = " << p);
    const Cell c = cellWithConflict(p, 1.0 - p, 0.0);
    // The identity holds exactly for the stored p (1e-6: float arithmetic).
    const double stored_p = c.occupied();
    EXPECT_NEAR(internalConflict(c), binaryEntropy(stored_p), 1e-6);
    EXPECT_NEAR(entropyBits(c), binaryEntropy(stored_p), 1e-6);
    EXPECT_NEAR(internalConflict(c), binaryEntropy(p), kTol);
    EXPECT_NEAR(pignistic(c), p, kTol);
    EXPECT_TRUE(std::isfinite(internalConflict(c)));
  }
  // Spot values: H(0.1) = 0.46899559, H(0.25) = 0.81127812.
  EXPECT_NEAR(internalConflict(cellWithConflict(0.1, 0.9, 0.0)), 0.46899559358929, kTol);
  EXPECT_NEAR(internalConflict(cellWithConflict(0.25, 0.75, 0.0)), 0.81127812445913, kTol);
}

// Layer names, order and spelling, exactly as the output files / topics use them.
TEST(LayerNamesTest, OrderAndSpelling) {
  const auto& names = layerNames();
  ASSERT_EQ(names.size(), 10u);
  EXPECT_EQ(names[0], "occupied");
  EXPECT_EQ(names[1], "free");
  EXPECT_EQ(names[2], "unknown");
  EXPECT_EQ(names[3], "conflict");
  EXPECT_EQ(names[4], "pignistic");
  EXPECT_EQ(names[5], "nonspecificity");
  EXPECT_EQ(names[6], "internal_conflict");
  EXPECT_EQ(names[7], "external_conflict");
  EXPECT_EQ(names[8], "entropy");
  EXPECT_EQ(names[9], "anomaly");
  EXPECT_EQ(layerName(Layer::kOccupied), "occupied");
  EXPECT_EQ(layerName(Layer::kExternalConflict), "external_conflict");
  EXPECT_EQ(layerName(Layer::kEntropy), "entropy");
  EXPECT_EQ(layerName(Layer::kAnomaly), "anomaly");
  for (int i = 0; i < kLayerCount; ++i) {
    EXPECT_EQ(layerName(static_cast<Layer>(i)), names[i]);
  }
}

// layerValue on (∅0.5, o0.3, e0.1, Θ0.1), i.e. m̃ = (0.6, 0.2), λ = ln 2 (values as in
// ConflictAsymmetricMass): raw masses m(o) = 0.6*0.5 = 0.3, m(e) = 0.2*0.5 = 0.1,
// m(Θ) = 0.2*0.5 = 0.1, m(∅) = 0.5.
TEST(LayerValueTest, EveryLayerOfAConflictingCell) {
  const Cell c = cellWithConflict(0.6, 0.2, 0.5);
  EXPECT_NEAR(layerValue(c, Layer::kOccupied), 0.3, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kFree), 0.1, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kUnknown), 0.1, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kConflict), 0.5, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kPignistic), 0.7, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kNonspecificity), 0.1, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kInternalConflict), 0.22877123795494, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kExternalConflict), 1.0, kTol);
  EXPECT_NEAR(layerValue(c, Layer::kEntropy), 0.88129089923069, kTol);
  EXPECT_EQ(layerValue(c, Layer::kAnomaly), 0.0);  // held beside the map, not by the cell
}

// layerValue of a vacuous cell: m(o)=0, m(e)=0, m(Θ)=1, m(∅)=0, BetP 0.5, NS 1, IC 0, EC 0, H 1,
// anomaly 0.
TEST(LayerValueTest, EveryLayerOfAVacuousCell) {
  const Cell c;
  const double expected[kLayerCount] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.0, 0.0, 1.0, 0.0};
  for (int i = 0; i < kLayerCount; ++i) {
    EXPECT_NEAR(layerValue(c, static_cast<Layer>(i)), expected[i], kTol) << layerNames()[i];
  }
}

// layerValue on a conflict-free cell (∅0, o0.6, e0.1, Θ0.3), values from AsymmetricMass.
TEST(LayerValueTest, EveryLayerOfAConflictFreeCell) {
  const Cell c = cellWithConflict(0.6, 0.1, 0.0);
  const double expected[kLayerCount] = {
      0.6, 0.1, 0.3, 0.0, 0.75, 0.3, 0.22339466555577, 0.0, 0.81127812445913};
  for (int i = 0; i < kLayerCount; ++i) {
    EXPECT_NEAR(layerValue(c, static_cast<Layer>(i)), expected[i], kTol) << layerNames()[i];
  }
}

}  // namespace
}  // namespace evidential_slam
