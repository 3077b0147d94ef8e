// Dempster-Shafer masses of one grid cell over the frame {o (occupied), e (empty)}, the combination
// rules, and the non-saturating cell storage of algorithm.md §2.3.
#pragma once

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
ScanMass fuseDempster(const ScanMass& a, const ScanMass& b);

// Stored belief of one cell: the normalised pair m̃(o), m̃(e) (m̃(Θ) = 1 - both) and
// lambda = -ln(1 - m(∅)). A vacuous cell is all zeros. This never saturates: alternating
// contradicting updates grow lambda instead of driving the stored masses to rounding noise.
struct Cell {
  float occupied = 0.0f;  // m̃(o)
  float free = 0.0f;      // m̃(e)
  float lambda = 0.0f;    // -ln(1 - m(∅)), external conflict in nats

  float unknown() const { return 1.0f - occupied - free; }  // m̃(Θ)
  bool observed() const { return occupied != 0.0f || free != 0.0f || lambda != 0.0f; }
  Mass toMass() const;  // the explicit masses m(∅), m(o), m(e), m(Θ)
  static Cell fromMass(const Mass& m);
};

// Conjunctive update of a stored cell by a scan mass (algorithm.md §2.3); exact, never NaN.
void updateCell(Cell& cell, const ScanMass& scan);

}  // namespace evidential_slam
