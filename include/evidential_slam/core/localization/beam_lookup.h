// The evidential forward model (BeamModel, algorithm.md §3) at lookup cost, for localization on a
// map that does not change. Built once per map: per cell of the observed box its masses (m̃(o),
// m̃(Θ), 1 - m(∅), observed) in a dense array, and the distance to the nearest "opaque" cell, one
// whose m̃(o) >= kOpaque (an exact Euclidean distance transform). A beam is then marched, not
// traced: where the distance field says no opaque cell is near, the march jumps ahead by that
// distance (sphere tracing, as rangelibc's ray marching); near one it steps cell by cell, so every
// opaque cell the beam crosses multiplies the beam's chance to get through by 1 - m̃(o), as in the
// traced model. Cells with m̃(o) < kOpaque are taken as transparent. The hit window around the
// measured range is visited as the traced model visits it, but for runs of certain cells (a
// second distance field), which hold nothing it could collect. Directions are exact (no angular
// bins, unlike a lookup table or CDDT): docs/decisions.md.
//
// Two readings on top of the traced model's plausibility (Options):
// - unobserved_collects false: a beam ending in never-observed space is weighed by the random
//   component only (never-observed cells collect nothing in the hit window; the traced model lets
//   their m(Θ) = 1 collect). The Localizer's default is the traced reading
//   (laser_unobserved_random_only false: docs/decisions.md);
// - a beam ending short, in confident free space with no opaque cell before it, is an unexpected
//   obstacle (amcl's "short" component, the anomaly layer's hit in open space): it is plausible
//   with the rate of such beams, `short_rate`, which the Localizer measures at its estimate rather
//   than taking a constant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/core/sensor_model.h"

namespace evidential_slam {

// What one beam met, besides its plausibility.
struct LookupBeam {
  double plausibility = 0.0;
  // The beam ended short: no opaque cell before its hit window and the cell of its endpoint
  // confidently free (BetP(o) < 1/4, NS < 1/2).
  bool short_reading = false;
};

class BeamLookup {
 public:
  // m̃(o) from which a cell stops beams in the march; below, a beam goes through at no cost outside
  // its hit window. A beam crossing k such cells would lose at most 1 - 0.9^k in the traced model.
  static constexpr float kOpaque = 0.1f;
  // Cells with m̃(o) and m̃(Θ) below this are certain: the hit window passes them as the traced
  // model would pass a cell of m̃(o) = m̃(Θ) = 0 (a free cell seen a few times holds about 1e-6).
  static constexpr float kCertain = 1e-4f;

  struct Options {
    bool unobserved_collects = false;  // true: the traced model's reading of never-observed cells
    double short_rate = 0.0;           // plausibility (before r) of a short reading
  };

  // `conflict_as_unknown`: read a cell's m(∅) as ignorance (SensorModelConfig's
  // forward_conflict_as_unknown; the model given to beam() must agree). Throws
  // std::invalid_argument for a map without an observed cell.
  BeamLookup(const EvidentialGridMap& map, bool conflict_as_unknown);

  bool conflictAsUnknown() const { return conflict_as_unknown_; }

  const CellBox& box() const { return box_; }
  double resolution() const { return resolution_; }
  // Bytes held (the dense cells and the distance field).
  size_t memoryBytes() const;

  // Distance (m) from `origin` along `angle` to where the ray enters the first opaque cell it
  // crosses, or `max_range` when there is none closer (the range a perfect laser would measure
  // on the map's opaque cells).
  double firstOpaque(const Eigen::Vector2d& origin, double angle, double max_range) const;

  // pl(z) of one hit beam of range z from `origin` along `angle`, with `model`'s hit window,
  // random weight and reading of conflict (its other settings are not used).
  LookupBeam beam(const BeamModel& model, const Eigen::Vector2d& origin, double angle, double z,
                  const Options& options) const;
  // Σ ln pl over the beams of `beams` (hits only: ParticleFilter::hitBeamSubset), seen from
  // `sensor_in_map`; `shorts`, if given, counts the short readings.
  double logPlausibility(const BeamModel& model, const Pose2& sensor_in_map, const LaserScan& beams,
                         const Options& options, size_t* shorts = nullptr) const;

 private:
  // A cell's masses as the forward model reads them (m(∅) moved to Θ when conflict_as_unknown).
  struct CellMasses {
    float occupied = 0.0f;  // m̃(o)
    float unknown = 1.0f;   // m̃(Θ)
    uint8_t observed = 0;
    uint8_t free = 0;  // confidently free: BetP(o) < 1/4 and NS < 1/2
  };
  static const CellMasses kVacuous;
  // The cell (cx, cy) (map cells), vacuous off the box.
  const CellMasses& at(int cx, int cy) const;

  CellBox box_;
  double resolution_ = 0.05;
  bool conflict_as_unknown_ = true;
  std::vector<CellMasses> cells_;  // row-major over box_
  // Whole cells (saturated at 255) to the nearest opaque cell, and to the nearest cell that is
  // not certain (never observed, off the box included); row-major over box_.
  std::vector<uint8_t> opaque_distance_;
  std::vector<uint8_t> uncertain_distance_;
};

}  // namespace evidential_slam
