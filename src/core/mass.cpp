#include "evidential_slam/core/mass.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {
namespace {
// Smallest 1 - K we divide by; K reaches 1 only for two certain, opposite masses.
constexpr double kMinNormaliser = 1e-12;
}  // namespace

namespace detail {
const std::array<double, 1u << 15> kExpMinusHalf = [] {
  std::array<double, 1u << 15> table{};
  for (uint32_t bits = 0; bits < table.size(); ++bits) {
    table[bits] = std::exp(-static_cast<double>(static_cast<float>(
        Eigen::half(Eigen::half_impl::raw_uint16_to_half(static_cast<uint16_t>(bits))))));
  }
  return table;
}();
}  // namespace detail

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

Mass massFromNormalised(double occupied, double free, double lambda) {
  const double keep = std::exp(-lambda);
  Mass m;
  m.conflict = -std::expm1(-lambda);  // expm1 keeps small conflicts exact
  m.occupied = keep * occupied;
  m.free = keep * free;
  m.unknown = keep * std::max(0.0, 1.0 - occupied - free);
  return m;
}

// The stored masses are multiples of 2^-23 summing to at most 1: 1 - m̃(o) - m̃(e) is exact in
// double and equals unknown().
Mass Cell::toMass() const { return massFromNormalised(occupied(), free(), lambda()); }

Cell Cell::fromMass(const Mass& m) {
  Cell c;
  const double keep = 1.0 - m.conflict;
  if (keep <= kMinNormaliser) {
    c.setLambda(static_cast<float>(-std::log(kMinNormaliser)));
    return c;
  }
  c.setMasses(static_cast<float>(m.occupied / keep), static_cast<float>(m.free / keep));
  c.setLambda(static_cast<float>(-std::log1p(-m.conflict)));
  return c;
}

int scansToFlip(double floor, double mass, int limit) {
  // The cell (in the scans' direction): m̃(to) = 0, m̃(from) = 1 - floor, m̃(Θ) = floor.
  double to = 0.0, from = 1.0 - floor, unknown = floor;
  for (int n = 1; n <= limit; ++n) {
    const double norm = 1.0 - from * mass;  // 1 - K
    to = (to + unknown * mass) / norm;
    from = from * (1.0 - mass) / norm;
    unknown = unknown * (1.0 - mass) / norm;
    if (unknown < floor) {  // discounted back to the floor, the ratio kept
      const double scale = (1.0 - floor) / (to + from);
      to *= scale;
      from *= scale;
      unknown = floor;
    }
    if (to > from) return n;  // BetP(to) = m̃(to) + m̃(Θ)/2 > 1/2
  }
  return limit + 1;
}

double confidenceFloor(int flip_scans, double hit_mass, double pass_mass) {
  if (flip_scans <= 0) return 0.0;
  const double mass = std::max(hit_mass, pass_mass);
  if (!(mass > 0.0 && mass < 1.0)) return 0.0;
  // The smallest floor at which at most n scans flip the cell (the count falls as the floor grows),
  // by bisection on a log scale.
  auto smallestFloorFlippingIn = [&](int n) {
    if (n <= 0) return 1.0;
    double lo = 1e-300, hi = 1.0;
    for (int i = 0; i < 200; ++i) {
      const double mid = std::sqrt(lo * hi);
      (scansToFlip(mid, mass, n) <= n ? hi : lo) = mid;
    }
    return hi;
  };
  return std::sqrt(smallestFloorFlippingIn(flip_scans) * smallestFloorFlippingIn(flip_scans - 1));
}

uint32_t confidenceFloorSteps(double floor) {
  if (!(floor > 0.0)) return 0;
  const double steps = std::round(std::min(floor, 1.0) * Cell::kMassSteps);
  return std::max<uint32_t>(1, static_cast<uint32_t>(steps));
}

}  // namespace evidential_slam
