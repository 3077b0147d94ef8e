// Evidential laser models (algorithm.md §3-§4): the forward model gives a beam's plausibility
// pl(z | x, Y) on a particle's map (its weight); the inverse model, derived from it through the
// generalised Bayesian theorem, gives the scan's local evidential map. Beams are traced once per
// scan and pose; the same traced cells serve the weight and the map update.
#pragma once

#include <cstdint>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/mass.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

// A cell crossed by a beam and the distance of its centre along the beam from the sensor.
struct RayCell {
  int x;
  int y;
  float distance;
};

// A beam's slice of TracedScan::cells. `hit`: the beam ends on an obstacle at `range`;
// otherwise it only clears space up to `range`.
struct TracedBeam {
  uint32_t begin;
  uint32_t end;
  float range;
  bool hit;
};

struct TracedScan {
  std::vector<RayCell> cells;
  std::vector<TracedBeam> beams;
  uint64_t rays_bad = 0;        // NaN / inf / negative ranges (skipped)
  uint64_t rays_no_return = 0;  // valid == 0
  void clear();
};

// What integrating one scan did to a map's conflict (the conflict alarm's inputs, conflict_alarm.h).
struct ScanConflict {
  // Σ over the touched cells of the increase of m(∅) = 1 - exp(-λ): e^{-λ} K per cell, with
  // K = m̃(o)s(e) + m̃(e)s(o) the conflict of that cell's update.
  double mass_added = 0.0;
  // The part of it added on cells where the scan puts an obstacle into the map's open space:
  // m̃(e)s(o) >= 1/2 and every cell within BeamModel::openSpaceRadius() (the cell included) is
  // believed more free than occupied, m̃(e) > m̃(o). A correctly placed scan of a static world
  // adds (almost) none of it: its hits fall on or next to surfaces the map holds.
  double open_space_added = 0.0;
};

// Dense scratch for fusing one scan's beams cell by cell (Dempster's rule) before the single
// conjunctive update of each touched map cell. One per worker thread.
class ScanAccumulator {
 public:
  void reset(const CellIndex& center, int half_size);
  // Dempster-fuses `m` into the scan's mass of cell (x, y); false if outside the window.
  bool add(int x, int y, const ScanMass& m) {
    const int lx = x - origin_x_, ly = y - origin_y_;
    if (static_cast<unsigned>(lx) >= static_cast<unsigned>(side_) ||
        static_cast<unsigned>(ly) >= static_cast<unsigned>(side_)) {
      return false;
    }
    Slot& slot = slots_[static_cast<size_t>(ly) * side_ + lx];
    if (slot.stamp != stamp_) {
      slot.stamp = stamp_;
      slot.index = static_cast<uint32_t>(touched_.size());
      touched_.push_back(Touched{x, y, m});
    } else {
      ScanMass& acc = touched_[slot.index].mass;
      acc = fuseDempster(acc, m);
    }
    return true;
  }
  // Applies every touched cell to `map` with the conjunctive rule; returns the external conflict
  // added (nats, summed over cells) and, if asked, the conflict mass m(∅) added (summed).
  double applyTo(EvidentialGridMap* map, double* conflict_mass_added = nullptr) const;
  size_t touched() const { return touched_.size(); }
  // Before applyTo: the conflict mass applying the scan will add on cells where it puts an obstacle
  // into `map`'s open space (ScanConflict::open_space_added), with open space checked `radius`
  // cells around each cell. Reads the map only, and only around strongly contradicted hits.
  double openSpaceConflict(const EvidentialGridMap& map, int radius) const;

 private:
  struct Slot {
    uint32_t stamp = 0;
    uint32_t index = 0;
  };
  struct Touched {
    int x;
    int y;
    ScanMass mass;
  };
  int origin_x_ = 0;
  int origin_y_ = 0;
  int half_ = -1;
  int side_ = 0;
  uint32_t stamp_ = 0;
  std::vector<Slot> slots_;
  std::vector<Touched> touched_;
};

class BeamModel {
 public:
  BeamModel(const SensorModelConfig& config, double resolution);

  const SensorModelConfig& config() const { return config_; }
  double resolution() const { return resolution_; }

  // Forward hit window g(δ) = Φ(δ/σ_f + k_f) - Φ(δ/σ_f - k_f), tabulated.
  float hitWindow(double delta) const;
  // Inverse-model mass of a cell whose centre lies `s` metres beyond the hit (s < 0: in front).
  ScanMass inverseMass(double s) const;
  // Mass of a cell on a beam that only clears space: e = 1 - r, Θ = r.
  ScanMass clearMass() const;

  // pl(z) of one beam over `cells` (ordered outwards from the sensor), algorithm.md §3.
  double beamPlausibility(const EvidentialGridMap& map, const RayCell* cells, size_t n,
                          double z) const;
  // Σ log pl over the hit beams of a traced scan (every `stride`-th beam).
  double scanLogPlausibility(const EvidentialGridMap& map, const TracedScan& traced,
                             int stride) const;

  // Traces every usable ray of `scan` from the sensor pose `sensor_in_map`.
  void traceScan(const Pose2& sensor_in_map, const LaserScan& scan, TracedScan* out) const;
  // Inverse model of a traced scan, fused within the scan by Dempster's rule, into `map` by the
  // conjunctive rule, each touched cell once. Returns the external conflict added (bits) and, if
  // asked, the conflict mass m(∅) added over the touched cells and its open-space part
  // (ScanConflict). EC is unbounded: a cell that already conflicts gains many bits from every
  // contradicting scan; m(∅) stays in [0, 1] per cell, so its sum says how many cells newly
  // conflict.
  double integrateScan(const TracedScan& traced, EvidentialGridMap* map, ScanAccumulator* scratch,
                       ScanConflict* conflict = nullptr) const;

  // Cells around a hit within which the forward model's hit window reaches,
  // ceil(forward_window * forward_sigma / resolution): a hit this close to a cell the map does not
  // hold free is plausible, farther in open space it is not (ScanConflict::open_space_added).
  int openSpaceRadius() const { return open_space_radius_; }

  // Distance past the hit that a hit beam is traced (and its cells updated).
  double traceBeyondHit() const { return beyond_hit_; }

 private:
  void traceRay(const Eigen::Vector2d& origin, double angle, double length,
                std::vector<RayCell>* out) const;

  SensorModelConfig config_;
  double resolution_;
  double beyond_hit_;
  int open_space_radius_;
  // g(δ) on [-g_half_, g_half_] with step table_step_.
  double g_half_;
  double table_step_;
  double inv_table_step_;
  std::vector<float> g_table_;
  // inverse masses for s in [s_min_, s_max_]; in front of s_min_: clearMass(), beyond s_max_:
  // vacuous.
  double s_min_, s_max_;
  std::vector<ScanMass> inverse_table_;
};

}  // namespace evidential_slam
