// Dempster-Shafer masses of one grid cell over the frame {o (occupied), e (empty)}, the combination
// rules, and the non-saturating cell storage of algorithm.md §2.3.
#pragma once

#include <algorithm>
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
inline ScanMass fuseDempster(const ScanMass& a, const ScanMass& b) {
  const float a_u = a.unknown(), b_u = b.unknown();
  const float conflict = a.occupied * b.free + a.free * b.occupied;
  const float norm = std::max(1.0f - conflict, 1e-12f);
  ScanMass r;
  r.occupied = (a.occupied * b.occupied + a.occupied * b_u + a_u * b.occupied) / norm;
  r.free = (a.free * b.free + a.free * b_u + a_u * b.free) / norm;
  return r;
}

// Stored belief of one cell (algorithm.md §2.3): the normalised pair m̃(o), m̃(e) (m̃(Θ) = 1 - both)
// and lambda = -ln(1 - m(∅)). This never saturates: alternating contradicting updates grow lambda
// instead of driving the stored masses to rounding noise. Quantised to 6 bytes (half of three
// floats; the grid is memory-bound and its tiles are most of the memory): m̃(o) and m̃(e) as
// multiples of 1/65535 whose sum never exceeds 1, so m̃(Θ) >= 0 exactly, and lambda as an IEEE
// half float (11 significant bits, up to 65504 nats). A vacuous cell is all zeros.
class Cell {
 public:
  static constexpr float kMassStep = 1.0f / 65535.0f;

  float occupied() const { return static_cast<float>(occupied_) * kMassStep; }  // m̃(o)
  float free() const { return static_cast<float>(free_) * kMassStep; }          // m̃(e)
  float unknown() const {                                                       // m̃(Θ)
    return static_cast<float>(65535 - occupied_ - free_) * kMassStep;
  }
  float lambda() const { return static_cast<float>(lambda_); }  // external conflict, nats
  bool observed() const { return (occupied_ | free_) != 0 || lambda_.x != 0; }
  // m̃(e) = 1: a scan mass without m(o) leaves the cell as it is.
  bool isCertainlyFree() const { return free_ == 65535; }

  // Rounds to the nearest representable pair; values outside the simplex are clamped into it.
  void setMasses(float occupied, float free) {
    const float o = std::min(std::max(occupied, 0.0f), 1.0f);
    const float e = std::min(std::max(free, 0.0f), 1.0f);
    occupied_ = static_cast<uint16_t>(o * 65535.0f + 0.5f);
    free_ = static_cast<uint16_t>(std::min(e * 65535.0f + 0.5f, 65535.0f - occupied_));
  }
  // Clamped to [0, 65504], the largest finite half float.
  void setLambda(float lambda) {
    lambda_ = Eigen::half(std::min(std::max(lambda, 0.0f), 65504.0f));
  }

  Mass toMass() const;  // the explicit masses m(∅), m(o), m(e), m(Θ)
  static Cell fromMass(const Mass& m);
  static Cell fromStored(float occupied, float free, float lambda) {
    Cell c;
    c.setMasses(occupied, free);
    c.setLambda(lambda);
    return c;
  }
  bool operator==(const Cell& o) const {
    return occupied_ == o.occupied_ && free_ == o.free_ && lambda_.x == o.lambda_.x;
  }

 private:
  uint16_t occupied_ = 0;
  uint16_t free_ = 0;
  Eigen::half lambda_{0.0f};
};

// Conjunctive update of a stored cell by a scan mass (algorithm.md §2.3); exact up to the storage's
// rounding, never NaN. Returns the conflict K of this update (lambda grew by -ln(1 - K)) and, when
// K > 0 and asked, lambda before the update.
inline float updateCell(Cell& cell, const ScanMass& scan, float* lambda_before = nullptr) {
  if (cell.isCertainlyFree() && scan.occupied == 0.0f) return 0.0f;  // a fixed point: no change
  const float s_u = scan.unknown();
  const float c_o = cell.occupied(), c_e = cell.free(), c_u = cell.unknown();
  const float k = c_o * scan.free + c_e * scan.occupied;
  const float norm = std::max(1.0f - k, 1e-9f);
  cell.setMasses((c_o * (scan.occupied + s_u) + c_u * scan.occupied) / norm,
                 (c_e * (scan.free + s_u) + c_u * scan.free) / norm);
  if (k > 0.0f) {
    // K = 1 (certain, opposite masses) would make λ infinite: capped at the largest float below 1
    // (λ += 16.6 nats).
    constexpr float kMaxConflict = 1.0f - 1.0f / (1 << 24);
    const float before = cell.lambda();
    if (lambda_before != nullptr) *lambda_before = before;
    cell.setLambda(before - std::log1p(-std::min(k, kMaxConflict)));
  }
  return k;
}

}  // namespace evidential_slam
