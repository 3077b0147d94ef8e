// Combination rules for one cell's belief from several sources (maps of several robots or days):
// conjunctive, Dempster, Yager, disjunctive and Denœux's cautious rule, with Shafer discounting per
// source. The maths, the cautious rule's weights on {o, e} and the treatment of conflict already
// stored in a cell are derived in docs/fusion.md.
#pragma once

#include <string>
#include <vector>

#include "evidential_slam/core/mass.h"

namespace evidential_slam {
namespace fusion {

enum class Rule {
  kConjunctive,  // unnormalised: the sources' conflict is kept as m(∅) (λ grows)
  kDempster,     // conjunctive, then normalised: the result has no conflict
  kYager,        // conjunctive, then all of m(∅) goes to Θ
  kDisjunctive,  // at least one source is right: unions of focal sets
  kCautious,     // Denœux 2008 on the conflict-free parts: idempotent, for overlapping evidence
};
constexpr int kRuleCount = 5;
// "conjunctive", "dempster", "yager", "disjunctive", "cautious".
const std::string& ruleName(Rule rule);
// False for any other name.
bool parseRule(const std::string& name, Rule* rule);

// A cell's belief in the grid's storage form (algorithm.md §2.3), in double: the conflict-free part
// m̃ (a Mass with m̃(∅) = 0) and λ = -ln(1 - m(∅)), so m(X) = e^{-λ} m̃(X) for X ≠ ∅. The rules work
// on this form, which stays exact where 1 - m(∅) is below double precision (λ > 37 nats). λ may be
// +∞ (total conflict; m̃ is then vacuous).
struct Belief {
  Mass normal;  // m̃: conflict 0, occupied + free + unknown = 1
  double lambda = 0.0;

  static Belief vacuous() { return Belief{}; }
  static Belief fromMass(const Mass& m);
  static Belief fromCell(const Cell& c);
  Mass toMass() const;
  // Rounded to the cell's storage (λ clamped to its largest value).
  Cell toCell() const;
  // m(∅) = 1 - e^{-λ}.
  double conflict() const;
};

// Shafer discounting of a source with discount rate `alpha` in [0, 1] (its reliability is
// 1 - alpha): m^α(A) = (1 - α) m(A) for every A ≠ Θ, ∅ included, and m^α(Θ) = (1 - α) m(Θ) + α.
// α = 0 leaves the belief as it is, α = 1 makes it vacuous.
Belief discount(const Belief& b, double alpha);

// The weights of the canonical conjunctive decomposition (Smets 1995, Denœux 2008) on {o, e}:
// m = ∅^{w(∅)} ∩ {o}^{w(o)} ∩ {e}^{w(e)}, with A^w the simple mass m(A) = 1 - w, m(Θ) = w. From
// the commonalities: w(o) = q(Θ)/q(o), w(e) = q(Θ)/q(e), w(∅) = q(o) q(e) / (q(∅) q(Θ)). w(o) and
// w(e) are in (0, 1]; w(∅) may exceed 1. A dogmatic belief (m̃(Θ) < kDogmaticFloor) is first
// given m̃(Θ) = kDogmaticFloor, its m̃(o) and m̃(e) scaled to keep the sum (docs/fusion.md).
struct ConjunctiveWeights {
  double empty = 1.0;     // w(∅)
  double occupied = 1.0;  // w(o)
  double free = 1.0;      // w(e)
};
constexpr double kDogmaticFloor = 1e-9;
ConjunctiveWeights conjunctiveWeights(const Belief& b);

// Combines two sources by `rule`.
Belief combine(Rule rule, const Belief& a, const Belief& b);
// Combines any number of sources at once (none: vacuous). For the conjunctive, Dempster and
// disjunctive rules this is the left fold of the two-source rule. Yager's rule is the conjunctive
// combination of all sources with its m(∅) moved to Θ once (the binary rule is not associative).
// The cautious rule takes the minimum weights and the largest conflicts over all sources at once,
// so the result does not depend on the order of the sources (its binary form is not associative
// in λ; docs/fusion.md).
Belief combine(Rule rule, const std::vector<Belief>& sources);

// The conflict K in [0, 1] that the conjunctive combination of the sources' conflict-free parts
// creates: how much the sources contradict each other, whatever rule then handles it.
double conflictBetween(const std::vector<Belief>& sources);
double conflictBetween(const Belief& a, const Belief& b);

}  // namespace fusion
}  // namespace evidential_slam
