#include "evidential_slam/core/fusion/combination.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

const std::array<std::string, kRuleCount>& ruleNames() {
  static const std::array<std::string, kRuleCount> names = {"conjunctive", "dempster", "yager",
                                                            "disjunctive", "cautious"};
  return names;
}

// A Mass without conflict from its three other masses divided by `keep` (their sum); vacuous when
// nothing is left.
Mass normalised(const Mass& m, double keep) {
  if (!(keep > 0.0)) return Mass::vacuous();
  Mass r;
  r.occupied = m.occupied / keep;
  r.free = m.free / keep;
  r.unknown = m.unknown / keep;
  return r;
}

// -ln(keep), +∞ for keep = 0.
double lambdaOf(double keep) { return keep > 0.0 ? -std::log(keep) : kInfinity; }

// Unnormalised conjunctive rule on the storage form: m̃ by Dempster's rule on the conflict-free
// parts, λ = λ_a + λ_b - ln(1 - K) (algorithm.md §2.3 factorises 1 - m(∅) this way).
Belief conjunctive(const Belief& a, const Belief& b) {
  const Mass c = combineConjunctive(a.normal, b.normal);
  // 1 - K as the sum of what is left, not 1 - K: no cancellation when K is near 1.
  const double keep = c.occupied + c.free + c.unknown;
  Belief r;
  r.normal = normalised(c, keep);
  r.lambda = a.lambda + b.lambda + lambdaOf(keep);
  return r;
}

// Moves all of m(∅) to Θ (Yager).
Belief conflictToIgnorance(const Belief& b) {
  const double keep = std::exp(-b.lambda);
  Belief r;
  r.normal.occupied = keep * b.normal.occupied;
  r.normal.free = keep * b.normal.free;
  r.normal.unknown = keep * b.normal.unknown - std::expm1(-b.lambda);
  return r;
}

// Disjunctive rule: m(C) = Σ_{A ∪ B = C} m_a(A) m_b(B). ∅ ∪ B = B, so m(∅) = m_a(∅) m_b(∅) and
// 1 - m(∅) = k_a + k_b - k_a k_b with k = e^{-λ}.
Belief disjunctive(const Belief& a, const Belief& b) {
  const double ka = std::exp(-a.lambda), kb = std::exp(-b.lambda);
  const double da = -std::expm1(-a.lambda), db = -std::expm1(-b.lambda);  // m(∅)
  const double ao = ka * a.normal.occupied, ae = ka * a.normal.free, au = ka * a.normal.unknown;
  const double bo = kb * b.normal.occupied, be = kb * b.normal.free, bu = kb * b.normal.unknown;
  Mass m;
  m.occupied = ao * bo + da * bo + ao * db;
  m.free = ae * be + da * be + ae * db;
  m.unknown = au + bu - au * bu + ao * be + ae * bo;
  const double keep = ka + kb - ka * kb;
  Belief r;
  r.normal = normalised(m, keep);
  r.lambda = lambdaOf(keep);
  return r;
}

// The weights of a belief's conflict-free part and their complements, computed apart so that
// neither loses precision near 0 or 1: w(o) = m̃(Θ)/(m̃(o) + m̃(Θ)), 1 - w(o) = m̃(o)/(m̃(o) + m̃(Θ)),
// and f = 1 - (1 - w(o))(1 - w(e)) = w(o) + w(e)(1 - w(o)).
struct Weights {
  double w_o = 1.0, u_o = 0.0;  // w(o), 1 - w(o)
  double w_e = 1.0, u_e = 0.0;  // w(e), 1 - w(e)
  double f() const { return w_o + w_e * u_o; }
};

Weights weightsOf(const Mass& normal) {
  double o = normal.occupied, e = normal.free, u = normal.unknown;
  if (u < kDogmaticFloor) {  // dogmatic: discounted by the floor (docs/fusion.md)
    const double scale = (1.0 - kDogmaticFloor) / (o + e);
    o *= scale;
    e *= scale;
    u = kDogmaticFloor;
  }
  Weights w;
  if (o > 0.0) {
    w.w_o = u / (o + u);
    w.u_o = o / (o + u);
  }
  if (e > 0.0) {
    w.w_e = u / (e + u);
    w.u_e = e / (e + u);
  }
  return w;
}

// Cautious rule over all sources at once (docs/fusion.md): the conflict-free part by Denœux's
// normalised cautious rule (the minimum weights of {o} and {e}) and
//   λ = max_i λ_i + ln(min_i f_i) - ln f,
// f_i and f being 1 - the conflict of {o}^w(o) ∩ {e}^w(e) for source i and for the minimum weights.
Belief cautious(const std::vector<Belief>& sources) {
  Weights w;
  double lambda = 0.0, f_min = 1.0;
  for (const Belief& s : sources) {
    const Weights ws = weightsOf(s.normal);
    if (ws.w_o < w.w_o) {
      w.w_o = ws.w_o;
      w.u_o = ws.u_o;
    }
    if (ws.w_e < w.w_e) {
      w.w_e = ws.w_e;
      w.u_e = ws.u_e;
    }
    lambda = std::max(lambda, s.lambda);
    f_min = std::min(f_min, ws.f());
  }
  const double f = w.f();
  Belief r;
  r.normal.occupied = w.u_o * w.w_e / f;
  r.normal.free = w.w_o * w.u_e / f;
  r.normal.unknown = w.w_o * w.w_e / f;
  // f ≤ f_min in exact arithmetic (the weights only decrease); never below the largest λ.
  r.lambda = lambda + std::max(0.0, std::log(f_min) - std::log(f));
  return r;
}

}  // namespace

const std::string& ruleName(Rule rule) { return ruleNames()[static_cast<size_t>(rule)]; }

bool parseRule(const std::string& name, Rule* rule) {
  const auto& names = ruleNames();
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) {
      *rule = static_cast<Rule>(i);
      return true;
    }
  }
  return false;
}

Belief Belief::fromMass(const Mass& m) {
  const double keep = m.occupied + m.free + m.unknown;
  Belief b;
  b.normal = normalised(m, keep);
  // log1p keeps a small conflict exact, the sum of the rest a conflict near 1.
  b.lambda = m.conflict < 0.5 ? -std::log1p(-m.conflict) : lambdaOf(keep);
  return b;
}

Belief Belief::fromCell(const Cell& c) {
  Belief b;
  b.normal.occupied = c.occupied();
  b.normal.free = c.free();
  b.normal.unknown = c.unknown();
  b.lambda = c.lambda();
  return b;
}

Mass Belief::toMass() const {
  const double keep = std::exp(-lambda);
  Mass m;
  m.conflict = -std::expm1(-lambda);
  m.occupied = keep * normal.occupied;
  m.free = keep * normal.free;
  m.unknown = keep * normal.unknown;
  return m;
}

Cell Belief::toCell() const {
  return Cell::fromStored(static_cast<float>(normal.occupied), static_cast<float>(normal.free),
                          static_cast<float>(std::min(lambda, 65504.0)));
}

double Belief::conflict() const { return -std::expm1(-lambda); }

Belief discount(const Belief& b, double alpha) {
  if (alpha <= 0.0) return b;
  if (alpha >= 1.0) return Belief::vacuous();
  const double kept = (1.0 - alpha) * std::exp(-b.lambda);  // (1 - α) e^{-λ}
  const double keep = alpha + kept;                         // 1 - m^α(∅)
  Belief r;
  r.normal.occupied = kept * b.normal.occupied / keep;
  r.normal.free = kept * b.normal.free / keep;
  r.normal.unknown = (kept * b.normal.unknown + alpha) / keep;
  r.lambda = -std::log(keep);
  return r;
}

ConjunctiveWeights conjunctiveWeights(const Belief& b) {
  const Weights w = weightsOf(b.normal);
  ConjunctiveWeights r;
  r.occupied = w.w_o;
  r.free = w.w_e;
  r.empty = std::exp(-b.lambda) / w.f();
  return r;
}

Belief combine(Rule rule, const Belief& a, const Belief& b) {
  switch (rule) {
    case Rule::kConjunctive:
      return conjunctive(a, b);
    case Rule::kDempster: {
      Belief r = conjunctive(a, b);
      r.lambda = 0.0;
      return r;
    }
    case Rule::kYager:
      return conflictToIgnorance(conjunctive(a, b));
    case Rule::kDisjunctive:
      return disjunctive(a, b);
    case Rule::kCautious:
      return cautious({a, b});
  }
  return Belief::vacuous();
}

Belief combine(Rule rule, const std::vector<Belief>& sources) {
  if (sources.empty()) return Belief::vacuous();
  // One source: every rule but Dempster's and Yager's (which act on its conflict) returns it.
  if (sources.size() == 1 && rule != Rule::kDempster && rule != Rule::kYager) {
    return sources.front();
  }
  if (rule == Rule::kCautious) return cautious(sources);
  // Dempster's and Yager's rules handle the conflict of the conjunctive combination once, at the
  // end (for Dempster's rule the same as at every step).
  const Rule step = rule == Rule::kDisjunctive ? Rule::kDisjunctive : Rule::kConjunctive;
  Belief r = sources.front();
  for (size_t i = 1; i < sources.size(); ++i) r = combine(step, r, sources[i]);
  if (rule == Rule::kDempster) r.lambda = 0.0;
  if (rule == Rule::kYager) r = conflictToIgnorance(r);
  return r;
}

double conflictBetween(const std::vector<Belief>& sources) {
  if (sources.size() < 2) return 0.0;
  Belief r;
  r.normal = sources.front().normal;
  for (size_t i = 1; i < sources.size(); ++i) {
    Belief s;
    s.normal = sources[i].normal;
    r = conjunctive(r, s);
  }
  return -std::expm1(-r.lambda);
}

double conflictBetween(const Belief& a, const Belief& b) { return conflictBetween({a, b}); }

}  // namespace fusion
}  // namespace evidential_slam
