// Tests of the combination rules (core/fusion/combination.h). Expected numbers are hand-computed;
// the arithmetic is in the comments. Masses are written (m(∅), m(o), m(e)), m(Θ) the remainder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "evidential_slam/core/fusion/combination.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kExact = 1e-12;

Belief belief(double conflict, double occupied, double free) {
  return Belief::fromMass(Mass::make(conflict, occupied, free));
}

void expectMass(const Belief& b, double conflict, double occupied, double free, double unknown,
                double tol = kExact) {
  const Mass m = b.toMass();
  EXPECT_NEAR(m.conflict, conflict, tol);
  EXPECT_NEAR(m.occupied, occupied, tol);
  EXPECT_NEAR(m.free, free, tol);
  EXPECT_NEAR(m.unknown, unknown, tol);
}

void expectSame(const Belief& a, const Belief& b, double tol = kExact) {
  const Mass m = b.toMass();
  expectMass(a, m.conflict, m.occupied, m.free, m.unknown, tol);
}

// A random belief with every mass non-zero; about half of them carry conflict.
Belief randomBelief(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.02, 1.0);
  double c = u(rng) < 0.5 ? 0.0 : u(rng), o = u(rng), e = u(rng), t = u(rng);
  const double sum = c + o + e + t;
  return belief(c / sum, o / sum, e / sum);
}

const Rule kAllRules[] = {Rule::kConjunctive, Rule::kDempster, Rule::kYager, Rule::kDisjunctive,
                          Rule::kCautious};

// --- Names ----------------------------------------------------------------------------------

TEST(CombinationTest, RuleNamesRoundTrip) {
  for (const Rule rule : kAllRules) {
    Rule parsed = Rule::kConjunctive;
    ASSERT_TRUE(parseRule(ruleName(rule), &parsed)) << ruleName(rule);
    EXPECT_EQ(parsed, rule);
  }
  Rule parsed = Rule::kCautious;
  EXPECT_FALSE(parseRule("max", &parsed));
  EXPECT_FALSE(parseRule("Cautious", &parsed));
  EXPECT_EQ(ruleName(Rule::kCautious), "cautious");
}

// --- Storage form ---------------------------------------------------------------------------

// (∅0.2, o0.4, e0.1, Θ0.3): m̃ = (0.5, 0.125, 0.375), λ = -ln 0.8.
TEST(CombinationTest, BeliefFromMassSplitsOffTheConflict) {
  const Belief b = belief(0.2, 0.4, 0.1);
  EXPECT_NEAR(b.normal.conflict, 0.0, kExact);
  EXPECT_NEAR(b.normal.occupied, 0.5, kExact);
  EXPECT_NEAR(b.normal.free, 0.125, kExact);
  EXPECT_NEAR(b.normal.unknown, 0.375, kExact);
  EXPECT_NEAR(b.lambda, -std::log(0.8), kExact);
  EXPECT_NEAR(b.conflict(), 0.2, kExact);
  expectMass(b, 0.2, 0.4, 0.1, 0.3);
}

// λ = 100 nats: 1 - m(∅) = e^-100 is below double precision next to 1, but m̃ is kept; a cell
// stores it within its rounding.
TEST(CombinationTest, BeliefKeepsTheConflictFreePartOfAHeavilyConflictedCell) {
  const Cell cell = Cell::fromStored(0.75f, 0.125f, 100.0f);
  const Belief b = Belief::fromCell(cell);
  EXPECT_DOUBLE_EQ(b.normal.occupied, 0.75);
  EXPECT_DOUBLE_EQ(b.normal.free, 0.125);
  EXPECT_DOUBLE_EQ(b.lambda, 100.0);
  EXPECT_EQ(b.toCell(), cell);
  EXPECT_EQ(b.toMass().conflict, 1.0);
}

TEST(CombinationTest, TotalConflictIsInfiniteLambdaAndStoresAsTheLargestCellLambda) {
  const Belief b = belief(1.0, 0.0, 0.0);
  EXPECT_TRUE(std::isinf(b.lambda));
  expectMass(b, 1.0, 0.0, 0.0, 0.0);
  EXPECT_FLOAT_EQ(b.toCell().lambda(), 65504.0f);
}

// --- Conjunctive and Dempster (mass.h's rules on the storage form) ----------------------------

// m1 = (0, 0.6, 0.1), m2 = (0, 0.2, 0.5): o' = 0.36, e' = 0.23, Θ' = 0.09, ∅' = 0.32
// (mass_test.cpp's worked example).
TEST(CombinationTest, ConjunctiveWorkedExample) {
  expectMass(combine(Rule::kConjunctive, belief(0, 0.6, 0.1), belief(0, 0.2, 0.5)), 0.32, 0.36,
             0.23, 0.09);
}

// With conflict already there: m = (0.2, 0.4, 0.1), s = (0, 0.5, 0.2) → (0.33, 0.47, 0.11, 0.09),
// the same as combineConjunctive on the explicit masses.
TEST(CombinationTest, ConjunctiveKeepsTheSourcesConflictLikeMassH) {
  const Mass m = Mass::make(0.2, 0.4, 0.1), s = Mass::make(0.0, 0.5, 0.2);
  const Belief r = combine(Rule::kConjunctive, Belief::fromMass(m), Belief::fromMass(s));
  expectMass(r, 0.33, 0.47, 0.11, 0.09);
  expectSame(r, Belief::fromMass(combineConjunctive(m, s)));
}

// Dempster: the worked example's (0.36, 0.23, 0.09) divided by 1 - 0.32 = 0.68.
TEST(CombinationTest, DempsterWorkedExample) {
  const Belief r = combine(Rule::kDempster, belief(0, 0.6, 0.1), belief(0, 0.2, 0.5));
  expectMass(r, 0.0, 0.36 / 0.68, 0.23 / 0.68, 0.09 / 0.68);
  const Mass m = Mass::make(0.2, 0.4, 0.1), s = Mass::make(0.0, 0.5, 0.2);
  expectSame(combine(Rule::kDempster, Belief::fromMass(m), Belief::fromMass(s)),
             Belief::fromMass(combineDempster(m, s)));
}

// --- Yager ----------------------------------------------------------------------------------

// The worked example's ∅' = 0.32 goes to Θ: (0, 0.36, 0.23, 0.41). With the source's own conflict
// (0.2, 0.4, 0.1) ∩ (0, 0.5, 0.2) = (0.33, 0.47, 0.11, 0.09): all 0.33 goes to Θ → Θ = 0.42.
TEST(CombinationTest, YagerMovesTheConflictToIgnorance) {
  expectMass(combine(Rule::kYager, belief(0, 0.6, 0.1), belief(0, 0.2, 0.5)), 0.0, 0.36, 0.23,
             0.41);
  expectMass(combine(Rule::kYager, belief(0.2, 0.4, 0.1), belief(0, 0.5, 0.2)), 0.0, 0.47, 0.11,
             0.42);
}

// --- Disjunctive ----------------------------------------------------------------------------

// m1 = (0, 0.6, 0.1), m2 = (0, 0.2, 0.5): o = 0.6·0.2 = 0.12, e = 0.1·0.5 = 0.05, Θ the rest 0.83
// (= 0.3 + 0.3 - 0.09 + 0.6·0.5 + 0.1·0.2).
TEST(CombinationTest, DisjunctiveWorkedExample) {
  expectMass(combine(Rule::kDisjunctive, belief(0, 0.6, 0.1), belief(0, 0.2, 0.5)), 0.0, 0.12,
             0.05, 0.83);
}

// ∅ ∪ B = B. m1 = (0.2, 0.4, 0.1, Θ0.3), m2 = (0.1, 0.5, 0.2, Θ0.2):
//   ∅ = 0.2·0.1 = 0.02
//   o = 0.4·0.5 + 0.2·0.5 + 0.4·0.1 = 0.20 + 0.10 + 0.04 = 0.34
//   e = 0.1·0.2 + 0.2·0.2 + 0.1·0.1 = 0.02 + 0.04 + 0.01 = 0.07
//   Θ = 0.3 + 0.2 - 0.06 + 0.4·0.2 + 0.1·0.5 = 0.57
TEST(CombinationTest, DisjunctiveWithConflictedSources) {
  expectMass(combine(Rule::kDisjunctive, belief(0.2, 0.4, 0.1), belief(0.1, 0.5, 0.2)), 0.02,
             0.34, 0.07, 0.57);
}

// --- Canonical conjunctive weights -------------------------------------------------------------

// (0, 0.6, 0.1, Θ0.3): q(o) = 0.9, q(e) = 0.4, q(Θ) = 0.3 → w(o) = 0.3/0.9 = 1/3,
// w(e) = 0.3/0.4 = 0.75, w(∅) = 0.9·0.4/0.3 = 1.2 (above 1: not separable).
// (0.2, 0.4, 0.1, Θ0.3): q(o) = 0.7, q(e) = 0.4, q(Θ) = 0.3 → 3/7, 0.75, 0.7·0.4/0.3 = 14/15.
TEST(CombinationTest, ConjunctiveWeightsFromCommonalities) {
  const ConjunctiveWeights w = conjunctiveWeights(belief(0, 0.6, 0.1));
  EXPECT_NEAR(w.occupied, 1.0 / 3.0, kExact);
  EXPECT_NEAR(w.free, 0.75, kExact);
  EXPECT_NEAR(w.empty, 1.2, kExact);
  const ConjunctiveWeights v = conjunctiveWeights(belief(0.2, 0.4, 0.1));
  EXPECT_NEAR(v.occupied, 3.0 / 7.0, kExact);
  EXPECT_NEAR(v.free, 0.75, kExact);
  EXPECT_NEAR(v.empty, 14.0 / 15.0, kExact);
  // No support for a focal set: its weight is 1.
  const ConjunctiveWeights f = conjunctiveWeights(belief(0, 0, 0.4));
  EXPECT_EQ(f.occupied, 1.0);
  EXPECT_NEAR(f.free, 0.6, kExact);
  EXPECT_NEAR(f.empty, 1.0, kExact);
}

// The decomposition gives the mass back: ∅^w(∅) ∩ {o}^w(o) ∩ {e}^w(e) by combineConjunctive
// (bilinear, so a weight above 1, a negative "mass", is no obstacle).
TEST(CombinationTest, ConjunctiveWeightsRecomposeTheMass) {
  for (const Belief& b : {belief(0, 0.6, 0.1), belief(0.2, 0.4, 0.1), belief(0.05, 0.1, 0.7)}) {
    const ConjunctiveWeights w = conjunctiveWeights(b);
    const Mass m = combineConjunctive(
        combineConjunctive(Mass::make(1.0 - w.empty, 0, 0), Mass::make(0, 1.0 - w.occupied, 0)),
        Mass::make(0, 0, 1.0 - w.free));
    expectSame(Belief::fromMass(m), b);
  }
}

// --- Cautious ---------------------------------------------------------------------------------

// A = (0, 0.6, 0.1): w = (1/3, 3/4), f_A = 1 - (2/3)(1/4) = 5/6.
// B = (0, 0.2, 0.5): w = (0.6, 0.375), f_B = 1 - (0.4)(0.625) = 3/4.
// Minimum weights (1/3, 3/8): f = 1 - (2/3)(5/8) = 7/12;
//   m̃(o) = (2/3)(3/8)/f = 3/7, m̃(e) = (1/3)(5/8)/f = 5/14, m̃(Θ) = (1/3)(3/8)/f = 3/14;
//   λ = 0 + ln(min(5/6, 3/4)) - ln(7/12) = ln(9/7): 1 - m(∅) = 7/9.
// Explicit: ∅ 2/9, o 1/3, e 5/18, Θ 1/6.
TEST(CombinationTest, CautiousWorkedExample) {
  const Belief r = combine(Rule::kCautious, belief(0, 0.6, 0.1), belief(0, 0.2, 0.5));
  EXPECT_NEAR(r.normal.occupied, 3.0 / 7.0, kExact);
  EXPECT_NEAR(r.normal.free, 5.0 / 14.0, kExact);
  EXPECT_NEAR(r.lambda, std::log(9.0 / 7.0), kExact);
  expectMass(r, 2.0 / 9.0, 1.0 / 3.0, 5.0 / 18.0, 1.0 / 6.0);
}

// The sources' own conflict combines by the maximum: A with λ = ln 2 (m(∅) = 0.5) and the same m̃:
// λ = ln 2 + ln(9/7), 1 - m(∅) = (1/2)(7/9) = 7/18.
TEST(CombinationTest, CautiousKeepsTheLargerStoredConflict) {
  Belief a = belief(0, 0.6, 0.1);
  a.lambda = std::log(2.0);
  const Belief r = combine(Rule::kCautious, a, belief(0, 0.2, 0.5));
  EXPECT_NEAR(r.lambda, std::log(2.0) + std::log(9.0 / 7.0), kExact);
  EXPECT_NEAR(r.conflict(), 11.0 / 18.0, kExact);
  EXPECT_NEAR(r.normal.occupied, 3.0 / 7.0, kExact);
}

// Two simple supports for opposite singletons: the cautious rule is the conjunctive rule there.
// {o}^0.5 and {e}^0.5: (0.25 ∅, 0.25 o, 0.25 e, 0.25 Θ).
TEST(CombinationTest, CautiousOfOppositeSimpleSupportsIsConjunctive) {
  const Belief a = belief(0, 0.5, 0), b = belief(0, 0, 0.5);
  expectMass(combine(Rule::kCautious, a, b), 0.25, 0.25, 0.25, 0.25);
  expectSame(combine(Rule::kCautious, a, b), combine(Rule::kConjunctive, a, b));
}

// Two simple supports for the same singleton: the stronger one, not their product.
TEST(CombinationTest, CautiousOfTwoSupportsForOccupiedIsTheStronger) {
  expectMass(combine(Rule::kCautious, belief(0, 0.5, 0), belief(0, 0.8, 0)), 0.0, 0.8, 0.0, 0.2);
  expectMass(combine(Rule::kConjunctive, belief(0, 0.5, 0), belief(0, 0.8, 0)), 0.0, 0.9, 0.0,
             0.1);
}

// Dogmatic masses are discounted by kDogmaticFloor = ε first. Certainly occupied with certainly
// free: weights (ε, 1) and (1, ε), minimum (ε, ε), f = ε + ε(1 - ε) ≈ 2ε → m̃ ≈ (1/2, 1/2) and
// λ = -ln f ≈ -ln(2ε) ≈ 20.0 nats: finite, where the conjunctive rule's is infinite.
TEST(CombinationTest, CautiousOfOppositeCertainCellsHasFiniteConflict) {
  const double eps = kDogmaticFloor;
  const Belief r = combine(Rule::kCautious, belief(0, 1, 0), belief(0, 0, 1));
  EXPECT_NEAR(r.normal.occupied, 0.5, 1e-8);
  EXPECT_NEAR(r.normal.free, 0.5, 1e-8);
  EXPECT_NEAR(r.lambda, -std::log(eps + eps * (1 - eps)), 1e-6);
  EXPECT_TRUE(std::isinf(combine(Rule::kConjunctive, belief(0, 1, 0), belief(0, 0, 1)).lambda));
}

// Bayesian sources (m̃(Θ) = 0), as the floor goes to 0: w(o) ≈ ε/m̃(o), w(e) ≈ ε/m̃(e), so
// m̃(o) → max m̃(o) / (max m̃(o) + max m̃(e)). (0.7, 0.3) and (0.4, 0.6): 0.7/1.3 and 0.6/1.3.
TEST(CombinationTest, CautiousOfBayesianSourcesTakesTheLargestOfEachSingleton) {
  const Belief r = combine(Rule::kCautious, belief(0, 0.7, 0.3), belief(0, 0.4, 0.6));
  EXPECT_NEAR(r.normal.occupied, 0.7 / 1.3, 1e-7);
  EXPECT_NEAR(r.normal.free, 0.6 / 1.3, 1e-7);
  EXPECT_LT(r.normal.unknown, 1e-8);
}

// --- Laws ------------------------------------------------------------------------------------

// Idempotence: cautious(A, A) = A, conflicted and dogmatic A too.
TEST(CombinationTest, CautiousIsIdempotent) {
  std::mt19937_64 rng(7);
  std::vector<Belief> all = {belief(0, 0.6, 0.1), belief(0.3, 0.2, 0.4), belief(0, 1, 0),
                             belief(0, 0.7, 0.3), belief(0.5, 0.3, 0.2)};
  for (int i = 0; i < 50; ++i) all.push_back(randomBelief(rng));
  for (const Belief& a : all) expectSame(combine(Rule::kCautious, a, a), a, 1e-9);
}

// ... and the rules that count evidence twice are not idempotent: A = (0, 0.6, 0.1):
// A ∩ A = (0.12, 0.72, 0.07, 0.09) (o = 0.36 + 0.18 + 0.18, e = 0.01 + 0.03 + 0.03).
TEST(CombinationTest, ConjunctiveOfASourceWithItselfIsNotIt) {
  const Belief a = belief(0, 0.6, 0.1);
  expectMass(combine(Rule::kConjunctive, a, a), 0.12, 0.72, 0.07, 0.09);
  EXPECT_GT(std::abs(combine(Rule::kDempster, a, a).normal.occupied - 0.6), 0.1);
}

// The vacuous mass is neutral for the conjunctive and cautious rules, conflicted A included; for
// Dempster's and Yager's rules on a conflict-free A (they act on A's own conflict).
TEST(CombinationTest, VacuousIsNeutral) {
  std::mt19937_64 rng(11);
  const Belief vacuous = Belief::vacuous();
  for (int i = 0; i < 50; ++i) {
    const Belief a = randomBelief(rng);
    Belief normal = a;
    normal.lambda = 0.0;
    for (const Rule rule : {Rule::kConjunctive, Rule::kCautious}) {
      expectSame(combine(rule, a, vacuous), a);
      expectSame(combine(rule, vacuous, a), a);
    }
    for (const Rule rule : {Rule::kDempster, Rule::kYager}) {
      expectSame(combine(rule, normal, vacuous), normal);
    }
  }
}

// Not for the disjunctive rule: the vacuous mass absorbs (one source knowing nothing and possibly
// the reliable one leaves nothing known); its neutral element is total conflict, m(∅) = 1.
TEST(CombinationTest, DisjunctiveVacuousAbsorbsAndTotalConflictIsNeutral) {
  const Belief a = belief(0.2, 0.4, 0.1);
  expectSame(combine(Rule::kDisjunctive, a, Belief::vacuous()), Belief::vacuous());
  expectSame(combine(Rule::kDisjunctive, a, belief(1.0, 0, 0)), a);
}

TEST(CombinationTest, EveryRuleIsCommutative) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 50; ++i) {
    const Belief a = randomBelief(rng), b = randomBelief(rng);
    for (const Rule rule : kAllRules) {
      expectSame(combine(rule, a, b), combine(rule, b, a), 1e-12);
    }
  }
}

TEST(CombinationTest, ConjunctiveDempsterAndDisjunctiveAreAssociative) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 50; ++i) {
    const Belief a = randomBelief(rng), b = randomBelief(rng), c = randomBelief(rng);
    for (const Rule rule : {Rule::kConjunctive, Rule::kDempster, Rule::kDisjunctive}) {
      const Belief left = combine(rule, combine(rule, a, b), c);
      expectSame(left, combine(rule, a, combine(rule, b, c)), 1e-12);
      expectSame(left, combine(rule, std::vector<Belief>{a, b, c}), 1e-12);
    }
  }
}

// Yager's binary rule is not associative. a = {o}^0.5, b = c = {e}^0.5:
//   Y(a, b) = (o 0.25, e 0.25, Θ 0.5); ∩ c: o 0.125, e 0.5, Θ 0.25, ∅ 0.125 → (0.125, 0.5, 0.375).
//   Y(b, c) = (e 0.75, Θ 0.25);  a ∩: o 0.125, e 0.375, Θ 0.125, ∅ 0.375 → (0.125, 0.375, 0.5).
// The N-source rule (conjunctive of all, then ∅ to Θ once) is a ∩ b ∩ c = (∅ .375, o .125,
// e .375, Θ .125) → (0.125, 0.375, 0.5).
TEST(CombinationTest, YagerIsNotAssociative) {
  const Belief a = belief(0, 0.5, 0), b = belief(0, 0, 0.5), c = belief(0, 0, 0.5);
  expectMass(combine(Rule::kYager, combine(Rule::kYager, a, b), c), 0.0, 0.125, 0.5, 0.375);
  expectMass(combine(Rule::kYager, a, combine(Rule::kYager, b, c)), 0.0, 0.125, 0.375, 0.5);
  expectMass(combine(Rule::kYager, std::vector<Belief>{a, b, c}), 0.0, 0.125, 0.375, 0.5);
}

// The cautious rule's conflict-free part is associative (minimum weights); its binary λ is not.
// 1 = {o}^0.5, 2 = {e}^0.5, 3 with weights (0.4, 0.4): m̃3 = (0.375, 0.375, 0.25), f3 = 0.64.
//   (1 2): weights (0.5, 0.5), f = 0.75, λ = ln(1/0.75); then 3: λ = ln(4/3) + ln 0.64 - ln 0.64.
//   (2 3): weights (0.4, 0.4), λ = ln 0.64 - ln 0.64 = 0; then 1: λ = 0 + ln 0.64 - ln 0.64 = 0.
// All three at once: max λ = 0, min f = 0.64, f = 0.64: λ = 0, independent of their order.
TEST(CombinationTest, CautiousConflictIsNotAssociativeButTheNSourceRuleIsOrderFree) {
  const Belief s1 = belief(0, 0.5, 0), s2 = belief(0, 0, 0.5), s3 = belief(0, 0.375, 0.375);
  const Belief left = combine(Rule::kCautious, combine(Rule::kCautious, s1, s2), s3);
  const Belief right = combine(Rule::kCautious, s1, combine(Rule::kCautious, s2, s3));
  for (const Belief& r : {left, right}) {
    EXPECT_NEAR(r.normal.occupied, 0.375, kExact);
    EXPECT_NEAR(r.normal.free, 0.375, kExact);
  }
  EXPECT_NEAR(left.lambda, std::log(4.0 / 3.0), kExact);
  EXPECT_NEAR(right.lambda, 0.0, kExact);
  const Belief sources[3] = {s1, s2, s3};
  int order[3] = {0, 1, 2};
  do {
    const Belief r = combine(Rule::kCautious, std::vector<Belief>{sources[order[0]],
                                                                  sources[order[1]],
                                                                  sources[order[2]]});
    expectMass(r, 0.0, 0.375, 0.375, 0.25);
  } while (std::next_permutation(order, order + 3));
}

TEST(CombinationTest, NoSourcesIsVacuousAndOneSourceIsItself) {
  const Belief a = belief(0.2, 0.4, 0.1);
  for (const Rule rule : kAllRules) expectSame(combine(rule, std::vector<Belief>{}), Belief{});
  for (const Rule rule : {Rule::kConjunctive, Rule::kDisjunctive, Rule::kCautious}) {
    expectSame(combine(rule, std::vector<Belief>{a}), a);
  }
  expectMass(combine(Rule::kDempster, std::vector<Belief>{a}), 0.0, 0.5, 0.125, 0.375);
  expectMass(combine(Rule::kYager, std::vector<Belief>{a}), 0.0, 0.4, 0.1, 0.5);
}

// --- Discounting --------------------------------------------------------------------------------

// α = 0.25 on (0.2, 0.4, 0.1, Θ0.3): every mass but Θ times 0.75 → (0.15, 0.3, 0.075), Θ 0.475.
TEST(CombinationTest, DiscountScalesEveryMassButIgnorance) {
  expectMass(discount(belief(0.2, 0.4, 0.1), 0.25), 0.15, 0.3, 0.075, 0.475);
  expectSame(discount(belief(0.2, 0.4, 0.1), 0.0), belief(0.2, 0.4, 0.1));
}

TEST(CombinationTest, DiscountOneGivesVacuous) {
  std::mt19937_64 rng(13);
  for (int i = 0; i < 20; ++i) expectSame(discount(randomBelief(rng), 1.0), Belief::vacuous());
  expectSame(discount(belief(1.0, 0, 0), 1.0), Belief::vacuous());
  // Total conflict discounted by 0.5: (0.5 ∅, 0.5 Θ).
  expectMass(discount(belief(1.0, 0, 0), 0.5), 0.5, 0.0, 0.0, 0.5);
}

// --- Conflict between sources -----------------------------------------------------------------

// K of the worked example: 0.6·0.5 + 0.1·0.2 = 0.32, whatever conflict the sources store.
TEST(CombinationTest, ConflictBetweenIsTheConjunctiveConflictOfTheConflictFreeParts) {
  EXPECT_NEAR(conflictBetween(belief(0, 0.6, 0.1), belief(0, 0.2, 0.5)), 0.32, kExact);
  Belief a = belief(0, 0.6, 0.1);
  a.lambda = 3.0;
  EXPECT_NEAR(conflictBetween(a, belief(0, 0.2, 0.5)), 0.32, kExact);
  EXPECT_EQ(conflictBetween({a}), 0.0);
  EXPECT_NEAR(conflictBetween(a, a), 0.12, kExact);
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
