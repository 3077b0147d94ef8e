// Dempster-Shafer masses of one grid cell over the frame {o (occupied), e (empty)}, the combination
// rules, and the non-saturating cell storage of algorithm.md §2.3.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace evidential_slam {

// An explicit mass function: m(∅) + m(o) + m(e) + m(Θ) = 1.
struct Mass {
  double conflict = 0.0;  // m(∅)
  double occupied = 0.0;  // m(o)
  double free = 0.0;      // m(e)
  double unknown = 1.0;   // m(Θ)

  static Mass vacuous() { return Mass{}; }
  static Mass make(double conflict, double occupied, double free);  // m(Θ) is the remainder
};

// The explicit masses of a stored belief (algorithm.md §2.3): m(X) = (1 - m(∅)) m̃(X) with
// 1 - m(∅) = exp(-lambda); m̃(Θ) = 1 - m̃(o) - m̃(e), never below 0.
Mass massFromNormalised(double occupied, double free, double lambda);

// Unnormalised conjunctive rule (paper eq. 3/9): all disagreement goes to m(∅).
Mass combineConjunctive(const Mass& a, const Mass& b);
// Dempster's rule: conjunctive rule, then the conflict is normalised away (m(∅) = 0).
// Total conflict (both singletons opposite and certain) returns the vacuous mass.
Mass combineDempster(const Mass& a, const Mass& b);

// A scan's evidence for one cell: conflict-free, m(Θ) = 1 - occupied - free.
struct ScanMass {
  float occupied = 0.0f;
  float free = 0.0f;
  float unknown() const { return 1.0f - occupied - free; }
};

// Dempster's rule for two conflict-free scan masses (used to fuse beams within one scan).
// The result is kept in the simplex: in float, a cell that many beams of one scan cross (a person
// beside the laser) drifted to m(Θ) < 0, the next fusions amplified the drift, and the scan's mass
// there became inf, then NaN (and so did the map cell's λ). Inside the simplex the clamps change
// nothing.
inline ScanMass fuseDempster(const ScanMass& a, const ScanMass& b) {
  const float a_u = std::max(a.unknown(), 0.0f), b_u = std::max(b.unknown(), 0.0f);
  ScanMass r;
  r.occupied = a.occupied * b.occupied + a.occupied * b_u + a_u * b.occupied;
  r.free = a.free * b.free + a.free * b_u + a_u * b.free;
  const float conflict = a.occupied * b.free + a.free * b.occupied;
  if (conflict != 0.0f) {  // most cells: clearing beams only (dividing by 1 is exact)
    const float norm = std::max(1.0f - conflict, 1e-12f);
    r.occupied /= norm;
    r.free /= norm;
  }
  r.occupied = std::max(r.occupied, 0.0f);
  r.free = std::max(r.free, 0.0f);
  const float sum = r.occupied + r.free;
  if (sum > 1.0f) {
    r.occupied /= sum;
    r.free = 1.0f - r.occupied;
  }
  return r;
}

namespace detail {
// exp(-λ) for every non-negative half-float λ, indexed by its bits: the forward model and the
// map update need 1 - m(∅) of many conflicted cells per scan, and std::exp was ~5 % of the time
// on Freiburg 079 (a table entry is the same double, bit for bit).
extern const std::array<double, 1u << 15> kExpMinusHalf;
}  // namespace detail

// Stored belief of one cell (algorithm.md §2.3): the normalised pair m̃(o), m̃(e) (m̃(Θ) = 1 - both)
// and lambda = -ln(1 - m(∅)). This never saturates: alternating contradicting updates grow lambda
// instead of driving the stored masses to rounding noise. Quantised to 8 bytes (12 as three
// floats; the grid is memory-bound and its tiles are most of the memory): m̃(o) and m̃(e) as 24-bit
// multiples of 2^-23 whose sum never exceeds 1, so m̃(Θ) >= 0 exactly and every stored mass is a
// float exactly, and lambda as an IEEE half float (11 significant bits, up to 65504 nats). Near
// certainty the masses are about as fine as floats: 16-bit masses, which round m̃(Θ) to 0 sooner,
// cost accuracy on noisy lasers (range_030_bearing_015.rawlog: ATE 0.40-0.55 m against
// 0.29-0.39 m). A vacuous cell is all zeros.
class Cell {
 public:
  static constexpr uint32_t kMassSteps = 1u << 23;  // a mass of 1

  float occupied() const { return toMass(occupiedSteps()); }    // m̃(o)
  float free() const { return toMass(freeSteps()); }            // m̃(e)
  float unknown() const { return toMass(unknownSteps()); }      // m̃(Θ)
  float lambda() const { return static_cast<float>(lambda_); }  // external conflict, nats
  // 1 - m(∅) = e^{-λ}, equal to std::exp(-static_cast<double>(lambda())).
  double oneMinusConflict() const { return detail::kExpMinusHalf[lambda_.x & 0x7FFFu]; }
  bool conflicted() const { return lambda_.x != 0; }  // λ > 0: m(∅) > 0
  bool observed() const { return (occupiedSteps() | freeSteps()) != 0 || conflicted(); }

  // Rounds to the nearest representable pair; values outside the simplex are clamped into it (NaN
  // as 0).
  void setMasses(float occupied, float free) {
    const uint32_t o = toSteps(occupied);
    setSteps(o, std::min(toSteps(free), kMassSteps - o));
  }
  // Clamped to [0, 65504], the largest finite half float; NaN is stored as 0 (std::max and
  // std::min pass a NaN first argument through, and a NaN λ would make every read of the cell NaN).
  void setLambda(float lambda) {
    lambda_ = Eigen::half(lambda > 0.0f ? std::min(lambda, 65504.0f) : 0.0f);
  }

  Mass toMass() const;  // the explicit masses m(∅), m(o), m(e), m(Θ)
  static Cell fromMass(const Mass& m);
  static Cell fromStored(float occupied, float free, float lambda) {
    Cell c;
    c.setMasses(occupied, free);
    c.setLambda(lambda);
    return c;
  }
  // The stored bits (lossless map files): m̃(o) and m̃(e) in steps of 2^-23 (a mass of 1 is
  // kMassSteps) and λ's IEEE half-float bits.
  uint32_t occupiedSteps() const { return (uint32_t{occupied_hi_} << 8) | occupied_lo_; }
  uint32_t freeSteps() const { return (uint32_t{free_hi_} << 8) | free_lo_; }
  uint32_t unknownSteps() const { return kMassSteps - occupiedSteps() - freeSteps(); }
  // Bounded confidence (algorithm.md §2.4): Shafer discounting of m̃ towards Θ, just enough that
  // m̃(Θ) is at least `floor_steps` steps (m̃(o) and m̃(e) scaled by one factor, their ratio kept
  // up to rounding; λ untouched). A cell already at or above the floor is left as it is.
  void boundConfidence(uint32_t floor_steps) {
    const uint32_t o = occupiedSteps(), e = freeSteps();
    const uint32_t keep = kMassSteps - std::min(floor_steps, kMassSteps);
    if (o + e <= keep) return;
    const uint32_t o_kept = static_cast<uint32_t>(
        std::llround(static_cast<double>(o) * keep / static_cast<double>(o + e)));
    setSteps(o_kept, keep - o_kept);
  }
  uint16_t lambdaBits() const { return lambda_.x; }
  // The largest λ bits a cell holds: 65504, the largest finite half float (setLambda's cap).
  static constexpr uint16_t kMaxLambdaBits = 0x7BFF;
  // The cell with these stored bits; false (and `out` untouched) for bits no cell holds: masses
  // summing above 1, λ negative, infinite, NaN or above the cap.
  static bool fromBits(uint32_t occupied_steps, uint32_t free_steps, uint16_t lambda_bits,
                       Cell* out) {
    if (occupied_steps > kMassSteps || free_steps > kMassSteps - occupied_steps ||
        lambda_bits > kMaxLambdaBits) {
      return false;
    }
    out->setSteps(occupied_steps, free_steps);
    out->lambda_.x = lambda_bits;
    return true;
  }
  bool operator==(const Cell& o) const {
    return occupiedSteps() == o.occupiedSteps() && freeSteps() == o.freeSteps() &&
           lambda_.x == o.lambda_.x;
  }

 private:
  void setSteps(uint32_t o, uint32_t e) {
    occupied_hi_ = static_cast<uint16_t>(o >> 8);
    occupied_lo_ = static_cast<uint8_t>(o);
    free_hi_ = static_cast<uint16_t>(e >> 8);
    free_lo_ = static_cast<uint8_t>(e);
  }
  // Exact in float arithmetic (no double round trip): steps < 2^24 is a float, scaling by 2^±23
  // is exact, and so is the fraction x - floor(x); rounds half-way up.
  static float toMass(uint32_t steps) {
    return static_cast<float>(steps) * (1.0f / static_cast<float>(kMassSteps));
  }
  static uint32_t toSteps(float mass) {
    // NaN as 0: converting a NaN float to an integer is undefined.
    const float x = (mass > 0.0f ? std::min(mass, 1.0f) : 0.0f) * static_cast<float>(kMassSteps);
    const uint32_t whole = static_cast<uint32_t>(x);
    return whole + static_cast<uint32_t>(x - static_cast<float>(whole) >= 0.5f);
  }
  // 24 bits each, split so that the cell packs into 8 bytes with 2-byte alignment.
  uint16_t occupied_hi_ = 0;
  uint16_t free_hi_ = 0;
  uint8_t occupied_lo_ = 0;
  uint8_t free_lo_ = 0;
  Eigen::half lambda_{0.0f};
};

// The conflict K of one update is capped here, the largest float below 1 (λ += 16.6 nats): K = 1
// (certain, opposite masses) would make λ infinite.
constexpr float kMaxUpdateConflict = 1.0f - 1.0f / (1 << 24);

// The floor on m̃(Θ) (algorithm.md §2.4) at which `flip_scans` scans of the stronger of the two
// masses (`hit_mass` on {o}, `pass_mass` on {e}) turn a cell held the other way with full (bounded)
// confidence to BetP > 1/2; scans of the weaker mass take more (scansToFlip). The floor lies in
// the middle (geometric) of the floors for which exactly `flip_scans` scans flip the cell, so
// rounding does not move the count. 0 for flip_scans = 0 (unbounded confidence). The inverse
// model's hit is never stronger than its clearing beam (s(o) <= 1 - r): the beam sets it.
double confidenceFloor(int flip_scans, double hit_mass, double pass_mass);
// The floor in the cell's steps of 2^-23 (0: unbounded).
uint32_t confidenceFloorSteps(double floor);
// How many scans of mass `mass` on one singleton turn a cell at floor `floor`, fully confident in
// the other, to BetP > 1/2 (exact arithmetic; `limit` + 1 if more than `limit`).
int scansToFlip(double floor, double mass, int limit);

// True when updating `cell` by `scan` leaves it as it is: a scan mass without m(o) on a cell that
// is certainly free (m̃(e) = 1 - floor, where space observed free many times ends up).
inline bool updateLeavesCell(const Cell& cell, const ScanMass& scan, uint32_t floor_steps = 0) {
  return scan.occupied == 0.0f && cell.occupiedSteps() == 0 &&
         cell.freeSteps() == Cell::kMassSteps - floor_steps;
}

// What an update that conflicts (K > 0) did to a cell's conflict, for callers that sum it.
struct ConflictIncrement {
  double one_minus_conflict_before = 1.0;  // e^{-λ} before the update
  float lambda_added = 0.0f;               // -ln(1 - K), K capped at kMaxUpdateConflict
};

// Conjunctive update of a stored cell by a scan mass (algorithm.md §2.3); exact up to the storage's
// rounding, never NaN. Returns the conflict K of this update; when K > 0 and asked, `increment`
// says what λ was and how much it grew. With `floor_steps` > 0 the updated masses are then
// discounted so that m̃(Θ) stays at least that floor (bounded confidence, §2.4); 0 is the
// unbounded update.
inline float updateCell(Cell& cell, const ScanMass& scan, ConflictIncrement* increment = nullptr,
                        uint32_t floor_steps = 0) {
  if (updateLeavesCell(cell, scan, floor_steps)) return 0.0f;  // a fixed point: no change
  const float s_u = scan.unknown();
  const float c_o = cell.occupied(), c_e = cell.free(), c_u = cell.unknown();
  const float k = c_o * scan.free + c_e * scan.occupied;
  const float occupied = c_o * (scan.occupied + s_u) + c_u * scan.occupied;
  const float free = c_e * (scan.free + s_u) + c_u * scan.free;
  if (k == 0.0f) {  // no conflict (dividing by 1 is exact)
    cell.setMasses(occupied, free);
    if (floor_steps != 0) cell.boundConfidence(floor_steps);
    return 0.0f;
  }
  const float norm = std::max(1.0f - k, 1e-9f);
  cell.setMasses(occupied / norm, free / norm);
  if (floor_steps != 0) cell.boundConfidence(floor_steps);
  const float added = -std::log1p(-std::min(k, kMaxUpdateConflict));
  if (increment != nullptr) {
    increment->one_minus_conflict_before = cell.oneMinusConflict();
    increment->lambda_added = added;
  }
  cell.setLambda(cell.lambda() + added);
  return k;
}

}  // namespace evidential_slam
