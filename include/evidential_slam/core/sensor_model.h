// Evidential laser models (algorithm.md §3-§4): the forward model gives a beam's plausibility
// pl(z | x, Y) on a particle's map (its weight); the inverse model, derived from it through the
// generalised Bayesian theorem, gives the scan's local evidential map. Beams are traced once per
// scan and pose; the same traced cells serve the weight and the map update.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "evidential_slam/core/anomaly.h"
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

// What integrating one scan did to a map's conflict (`contradiction` is the conflict alarm's input,
// conflict_alarm.h).
struct ScanConflict {
  // Σ over the touched cells of the increase of m(∅) = 1 - exp(-λ): e^{-λ} K per cell, with
  // K = m̃(o)s(e) + m̃(e)s(o) the conflict of that cell's update.
  double mass_added = 0.0;
  // The part of it added on cells where the scan puts an obstacle into the map's open space:
  // m̃(e)s(o) >= 1/2 and every cell within BeamModel::openSpaceRadius() (the cell included) is
  // believed more free than occupied, m̃(e) > m̃(o). A correctly placed scan of a static world
  // adds (almost) none of it: its hits fall on or next to surfaces the map holds.
  double open_space_added = 0.0;
  // Σ K over the cells whose confident evidence the scan contradicts, before the update
  // (contradictionOf the scan's anomaly cells, anomaly.h): hits in open space and passes through
  // obstacles, undiluted by the conflict already there (the alarm's input).
  double contradiction = 0.0;
};

// Scratch for fusing one scan's beams cell by cell (Dempster's rule) before the single
// conjunctive update of each touched map cell. Sparse and laid out in the map's tiles: a block per
// map tile the scan touches, so the map is then updated tile by tile (one copy-on-write check per
// tile, cells in memory order). One per worker thread.
class ScanAccumulator {
 public:
  static constexpr int kTileBits = EvidentialGridMap::kTileBits;
  static constexpr int kTileSize = EvidentialGridMap::kTileSize;
  static constexpr int kTileCells = EvidentialGridMap::kTileCells;

  // Starts a scan whose cells lie within `half_size` cells of `center`.
  void reset(const CellIndex& center, int half_size);
  // Dempster-fuses `m` into the scan's mass of cell (x, y); false if outside the window.
  bool add(int x, int y, const ScanMass& m) {
    // Consecutive cells of a ray mostly lie in one tile: its block is kept at hand.
    if ((x >> kTileBits) != last_tile_x_ || (y >> kTileBits) != last_tile_y_) {
      if (!findBlock(x >> kTileBits, y >> kTileBits)) return false;
    }
    Block& block = *last_block_;
    const int k = EvidentialGridMap::cellInTile(x, y);
    uint64_t& word = block.touched[k >> 6];
    const uint64_t bit = uint64_t{1} << (k & 63);
    if ((word & bit) == 0) {
      word |= bit;
      block.mass[k] = m;
    } else {
      block.mass[k] = fuseDempster(block.mass[k], m);
    }
    return true;
  }
  // Applies every touched cell to `map` with the conjunctive rule, each cell's m̃(Θ) kept at least
  // `floor_steps` (updateCell); returns the external conflict added (nats, summed over cells) and,
  // if asked, the conflict mass m(∅) added (summed).
  double applyTo(EvidentialGridMap* map, double* conflict_mass_added = nullptr,
                 uint32_t floor_steps = 0) const;
  size_t touched() const;
  // Before applyTo: the conflict mass applying the scan will add on cells where it puts an obstacle
  // into `map`'s open space (ScanConflict::open_space_added), with open space checked `radius`
  // cells around each cell. Reads the map only, and only around strongly contradicted hits.
  double openSpaceConflict(const EvidentialGridMap& map, int radius) const;
  // The scan's mass of cell (x, y); nullptr when the scan does not touch it.
  const ScanMass* find(int x, int y) const {
    const int tx = (x >> kTileBits) - tile_x0_, ty = (y >> kTileBits) - tile_y0_;
    if (half_ < 0 || static_cast<unsigned>(tx) >= static_cast<unsigned>(tiles_side_) ||
        static_cast<unsigned>(ty) >= static_cast<unsigned>(tiles_side_)) {
      return nullptr;
    }
    const Slot& slot = slots_[static_cast<size_t>(ty) * tiles_side_ + tx];
    if (slot.stamp != stamp_ || slot.block >= used_blocks_) return nullptr;
    const Block& block = blocks_[slot.block];
    const int k = EvidentialGridMap::cellInTile(x, y);
    if (((block.touched[static_cast<size_t>(k >> 6)] >> (k & 63)) & 1u) == 0) return nullptr;
    return &block.mass[static_cast<size_t>(k)];
  }
  // fn(x, y, mass) for every cell the scan touches, tile by tile.
  template <typename Fn>
  void forEachCell(Fn&& fn) const {
    for (uint32_t b = 0; b < used_blocks_; ++b) {
      const Block& block = blocks_[b];
      for (size_t w = 0; w < block.touched.size(); ++w) {
        for (uint64_t bits = block.touched[w]; bits != 0; bits &= bits - 1) {
          const size_t k = w * 64 + static_cast<size_t>(__builtin_ctzll(bits));
          // Tiles west and south of the origin are negative: multiply, do not shift left (UB).
          fn(block.tile_x * kTileSize + static_cast<int>(k & (kTileSize - 1)),
             block.tile_y * kTileSize + static_cast<int>(k >> kTileBits), block.mass[k]);
        }
      }
    }
  }

 private:
  struct Slot {
    uint32_t stamp = 0;
    uint32_t block = 0;
  };
  struct Block {
    int tile_x = 0;
    int tile_y = 0;
    std::array<uint64_t, kTileCells / 64> touched{};
    std::array<ScanMass, kTileCells> mass;
  };
  uint32_t newBlock(int tile_x, int tile_y);
  // Makes the block of tile (tile_x, tile_y) the one at hand (created at its first cell); false
  // outside the window.
  bool findBlock(int tile_x, int tile_y);
  // fn(block, k) for every touched cell k of every block of this scan, block by block.
  template <typename Fn>
  void forEachTouched(Fn&& fn) const;

  int tile_x0_ = 0;
  int tile_y0_ = 0;
  int half_ = -1;
  int tiles_side_ = 0;
  uint32_t stamp_ = 0;
  std::vector<Slot> slots_;
  std::vector<Block> blocks_;  // the first used_blocks_ belong to the current scan
  uint32_t used_blocks_ = 0;
  // The block add() last wrote to and its tile (none after reset()).
  int last_tile_x_ = std::numeric_limits<int>::min(), last_tile_y_ = 0;
  Block* last_block_ = nullptr;
};

class BeamModel {
 public:
  BeamModel(const SensorModelConfig& config, double resolution);

  const SensorModelConfig& config() const { return config_; }
  double resolution() const { return resolution_; }

  // Forward hit window g(δ) = Φ(δ/σ_f + k_f) - Φ(δ/σ_f - k_f), tabulated.
  float hitWindow(double delta) const {
    if (delta <= -g_half_ || delta >= g_half_) return 0.0f;
    return g_table_[static_cast<size_t>((delta + g_half_) * inv_table_step_ + 0.5)];
  }
  // Inverse-model mass of a cell whose centre lies `s` metres beyond the hit (s < 0: in front).
  ScanMass inverseMass(double s) const {
    if (s <= s_min_) return clearMass();
    if (s >= s_max_) return ScanMass{};
    return inverse_table_[static_cast<size_t>((s - s_min_) * inv_table_step_ + 0.5)];
  }
  // Mass of a cell on a beam that only clears space: e = 1 - r, Θ = r.
  ScanMass clearMass() const { return clear_mass_; }
  // Bounded confidence (algorithm.md §2.4): the floor on every updated cell's m̃(Θ), derived from
  // flip_scans clearing beams (s(e) = 1 - r, the same for every laser) as the contradicting scans.
  double confidenceFloor() const { return confidence_floor_; }

  // pl(z) of one beam over `cells` (ordered outwards from the sensor), algorithm.md §3.
  double beamPlausibility(const EvidentialGridMap& map, const RayCell* cells, size_t n,
                          double z) const;
  // Σ log pl over the hit beams of a traced scan (every `stride`-th beam). The filter uses the
  // one-pass forms below (logPlausibility, weighAndIntegrate); the tests check them against this.
  double scanLogPlausibility(const EvidentialGridMap& map, const TracedScan& traced,
                             int stride) const;

  // traceScan then scanLogPlausibility, in one traversal that stores no cells (the same sum).
  double logPlausibility(const EvidentialGridMap& map, const Pose2& sensor_in_map,
                         const LaserScan& scan, int stride) const;

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
  // The first half of integrateScan: the scan's evidence in `scratch`, fused within the scan, not
  // applied to any map (for its anomaly against a map that stays as it is).
  void accumulateScan(const TracedScan& traced, ScanAccumulator* scratch) const;

  // Cells around a hit within which the forward model's hit window reaches,
  // ceil(forward_window * forward_sigma / resolution): a hit this close to a cell the map does not
  // hold free is plausible, farther in open space it is not (ScanConflict::open_space_added).
  int openSpaceRadius() const { return open_space_radius_; }

  // What weighAndIntegrate found.
  struct ScanEvidence {
    double log_plausibility = 0.0;  // as scanLogPlausibility, on the map before this scan
    double conflict_added_bits = 0.0;
    ScanConflict conflict;
  };
  // traceScan, scanLogPlausibility (every `stride`-th hit beam) and integrateScan in one traversal
  // of the beams, with the same results: the weight reads the map before the scan is applied.
  // It never stores the traced cells. = weighAndAccumulate, then applyScan. With `anomaly`, the
  // scan's anomaly against the map before the scan is appended to it (anomaly.h).
  ScanEvidence weighAndIntegrate(const Pose2& sensor_in_map, const LaserScan& scan,
                                 EvidentialGridMap* map, ScanAccumulator* scratch, int stride,
                                 std::vector<AnomalyCell>* anomaly = nullptr) const;
  // weighAndIntegrate in two halves. weighAndAccumulate: the traversal, returning the scan's log
  // plausibility on `map` (every `stride`-th hit beam) and leaving the scan's evidence in
  // `scratch`; `map` is not written.
  double weighAndAccumulate(const Pose2& sensor_in_map, const LaserScan& scan,
                            const EvidentialGridMap& map, ScanAccumulator* scratch,
                            int stride) const;
  // The scan's evidence in `scratch` for its anomaly (scanAnomaly) alone: as weighAndAccumulate
  // leaves it on every cell of a tile that holds a cell the map does not believe free (not in
  // `free_tiles`) or that a hit beam's occupied mass reaches; the other tiles get none. A cell of
  // those others can add to the anomaly only through a fused m(o) of at least kScanSurfaceMass,
  // and masses below ε = kScanSurfaceMass / (4 N) from each of a scan's N rays fuse to at most
  // N ε / (1 - N ε) < kScanSurfaceMass / 2. The cells kept get the same masses in the same order.
  void accumulateForAnomaly(const Pose2& sensor_in_map, const LaserScan& scan,
                            const BelievedFreeTiles& free_tiles, ScanAccumulator* scratch) const;
  // applyScan: applies the evidence in `scratch` to `map` (the map it was accumulated on);
  // returns the EC added (bits) and, if asked, the conflict measures (ScanConflict).
  double applyScan(const ScanAccumulator& scratch, EvidentialGridMap* map,
                   ScanConflict* conflict) const;

  // Distance past the hit that a hit beam is traced (and its cells updated).
  double traceBeyondHit() const { return beyond_hit_; }

 private:
  // One usable ray of a scan: from the sensor along `angle` for `length`; `range` and `hit` as in
  // TracedBeam.
  struct Ray {
    double angle;
    double length;
    float range;
    bool hit;
  };
  // Calls fn(ray) for every usable ray of `scan` (rules of traceScan); counts the others.
  template <typename Fn>
  void forEachRay(const Pose2& sensor_in_map, const LaserScan& scan, uint64_t* rays_bad,
                  uint64_t* rays_no_return, Fn&& fn) const;
  // Amanatides-Woo traversal: fn(cx, cy, distance of the cell centre along the ray) for every cell
  // the ray crosses, outwards, up to `length`; stops early where an fn returning bool says false.
  template <typename Fn>
  void traverse(const Eigen::Vector2d& origin, double angle, double length, Fn&& fn) const;
  // The scan's evidence for one cell of a ray: clear mass, or the inverse model at `distance` from
  // the sensor for a hit at `range`.
  // Inlined into the traversals (a call per traversed cell was ~10 % of the map update).
  void addEvidence(ScanAccumulator* scratch, int cx, int cy, float distance, double range,
                   bool hit) const {
    if (!hit) {
      scratch->add(cx, cy, clearMass());
      return;
    }
    const ScanMass m = inverseMass(distance - range);
    if (m.occupied == 0.0f && m.free == 0.0f) return;  // vacuous: nothing to add
    scratch->add(cx, cy, m);
  }
  // Half of the accumulator window: the longest ray, in cells.
  int windowHalfCells() const;

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
  ScanMass clear_mass_;
  double confidence_floor_ = 0.0;
  uint32_t floor_steps_ = 0;  // confidence_floor_ in the cell's steps
};

}  // namespace evidential_slam
