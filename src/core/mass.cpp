#include "evidential_slam/core/mass.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {
namespace {
// Smallest 1 - K we divide by; K reaches 1 only for two certain, opposite masses.
constexpr double kMinNormaliser = 1e-12;
}  // namespace

Mass Mass::make(double conflict, double occupied, double free) {
  Mass m;
  m.conflict = conflict;
  m.occupied = occupied;
  m.free = free;
  m.unknown = 1.0 - conflict - occupied - free;
  return m;
}

Mass combineConjunctive(const Mass& a, const Mass& b) {
  Mass r;
  r.occupied = a.occupied * b.occupied + a.occupied * b.unknown + a.unknown * b.occupied;
  r.free = a.free * b.free + a.free * b.unknown + a.unknown * b.free;
  r.unknown = a.unknown * b.unknown;
  r.conflict = 1.0 - r.occupied - r.free - r.unknown;
  return r;
}

Mass combineDempster(const Mass& a, const Mass& b) {
  const Mass c = combineConjunctive(a, b);
  const double norm = 1.0 - c.conflict;
  if (norm < kMinNormaliser) return Mass::vacuous();
  Mass r;
  r.occupied = c.occupied / norm;
  r.free = c.free / norm;
  r.unknown = c.unknown / norm;
  r.conflict = 0.0;
  return r;
}

ScanMass fuseDempster(const ScanMass& a, const ScanMass& b) {
  const float a_u = a.unknown(), b_u = b.unknown();
  const float conflict = a.occupied * b.free + a.free * b.occupied;
  const float norm = std::max(1.0f - conflict, 1e-12f);
  ScanMass r;
  r.occupied = (a.occupied * b.occupied + a.occupied * b_u + a_u * b.occupied) / norm;
  r.free = (a.free * b.free + a.free * b_u + a_u * b.free) / norm;
  return r;
}

Mass Cell::toMass() const {
  // m(X) = (1 - m(∅)) m̃(X) with 1 - m(∅) = exp(-lambda); expm1 keeps small conflicts exact.
  const double keep = std::exp(-static_cast<double>(lambda));
  Mass m;
  m.conflict = -std::expm1(-static_cast<double>(lambda));
  m.occupied = keep * occupied;
  m.free = keep * free;
  // The float pair may sum to a hair above 1 in double arithmetic; m(Θ) is never negative.
  m.unknown = keep * std::max(0.0, 1.0 - static_cast<double>(occupied) - static_cast<double>(free));
  return m;
}

Cell Cell::fromMass(const Mass& m) {
  Cell c;
  const double keep = 1.0 - m.conflict;
  if (keep <= kMinNormaliser) {
    c.lambda = static_cast<float>(-std::log(kMinNormaliser));
    return c;
  }
  c.occupied = static_cast<float>(m.occupied / keep);
  c.free = static_cast<float>(m.free / keep);
  c.lambda = static_cast<float>(-std::log1p(-m.conflict));
  return c;
}

void updateCell(Cell& cell, const ScanMass& scan) {
  // algorithm.md §2.3: conjunctive combination in the normalised form; the conflict of this update
  // K goes into lambda, the normalised masses stay well inside [0, 1].
  const float s_u = scan.unknown();
  const float c_u = cell.unknown();
  const float k = cell.occupied * scan.free + cell.free * scan.occupied;
  const float norm = std::max(1.0f - k, 1e-9f);
  float o = (cell.occupied * (scan.occupied + s_u) + c_u * scan.occupied) / norm;
  float e = (cell.free * (scan.free + s_u) + c_u * scan.free) / norm;
  // Rounding can push the pair a hair outside the simplex; clamp so m̃(Θ) >= 0.
  o = std::min(std::max(o, 0.0f), 1.0f);
  e = std::min(std::max(e, 0.0f), 1.0f - o);
  cell.occupied = o;
  cell.free = e;
  if (k > 0.0f) cell.lambda -= std::log1p(-std::min(k, 1.0f - 1e-9f));
}

}  // namespace evidential_slam
