#include "evidential_slam/core/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

#include "evidential_slam/core/profile.h"

namespace evidential_slam {
namespace {

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// Beams are traced this many table steps per σ (tables are nearest-neighbour).
constexpr double kTableStepsPerSigma = 64.0;
// The forward pass stops once past the hit and the window is below this.
constexpr float kNegligibleWindow = 1e-6f;
constexpr double kLn2 = 0.69314718055994530942;

// Reads a map's cells along a ray, keeping the tile of the last read at hand (consecutive cells
// of a ray mostly share one).
class CellReader {
 public:
  explicit CellReader(const EvidentialGridMap& map) : map_(map) {}
  const Cell& at(int cx, int cy) {
    const EvidentialGridMap::Tile* t = tileOf(cx, cy);
    return t != nullptr ? t->cells[EvidentialGridMap::cellInTile(cx, cy)]
                        : EvidentialGridMap::vacuousCell();
  }
  // False when the cell certainly holds no m̃(o) (Tile::mayHoldOccupied), without reading it.
  bool mayHoldOccupied(int cx, int cy) {
    const EvidentialGridMap::Tile* t = tileOf(cx, cy);
    return t != nullptr && t->mayHoldOccupied(EvidentialGridMap::cellInTile(cx, cy));
  }

 private:
  const EvidentialGridMap::Tile* tileOf(int cx, int cy) {
    const int tx = cx >> EvidentialGridMap::kTileBits, ty = cy >> EvidentialGridMap::kTileBits;
    if (tx != tile_x_ || ty != tile_y_) {
      tile_x_ = tx;
      tile_y_ = ty;
      tile_ = map_.tile(tx, ty);
    }
    return tile_;
  }
  const EvidentialGridMap& map_;
  int tile_x_ = std::numeric_limits<int>::min(), tile_y_ = 0;  // no tile read yet
  const EvidentialGridMap::Tile* tile_ = nullptr;
};

// One outward pass of the recursion P_i = m̃o g_i + m̃e P_{i+1} + m̃Θ (g_i + P_{i+1} - g_i P_{i+1})
// (algorithm.md §3), on the cell's masses with its conflict m(∅) moved to Θ if asked
// (forward_conflict_as_unknown: m(o), m(e) scaled by 1 - m(∅) = e^{-λ}): `passed` is the
// probability that the beam got past every cell so far, `collected` the plausibility collected.
struct ForwardPass {
  explicit ForwardPass(const SensorModelConfig& config)
      : conflict_as_unknown(config.forward_conflict_as_unknown) {}
  bool conflict_as_unknown;
  double passed = 1.0;
  double collected = 0.0;
  bool stopped = false;
  // Visits the next cell outwards, at distance d with window g; stops past the hit.
  void visit(const Cell& c, double d, float g, double z) {
    if (g == 0.0f) {
      // Outside the hit window (most cells of a beam): nothing is collected and Θ does not stop
      // the beam, so only m̃(o) matters (the general form below gives the same doubles).
      if (d > z) {
        stopped = true;
        return;
      }
      double mo = c.occupied();
      if (conflict_as_unknown && c.conflicted()) mo *= c.oneMinusConflict();
      passed *= 1.0 - mo;
      return;
    }
    double mo = c.occupied(), mu = c.unknown();
    if (conflict_as_unknown && c.conflicted()) {
      const double keep = c.oneMinusConflict();
      mu += (1.0 - keep) * (mo + c.free());
      mo *= keep;
    }
    collected += passed * g * (mo + mu);
    if (d > z && g < kNegligibleWindow) {
      stopped = true;
      return;
    }
    passed *= 1.0 - mo - mu * g;
  }
  // visit() of cell (cx, cy) read through `cells`; a cell that holds no m̃(o) outside the hit
  // window changes nothing (`passed` times 1) and is not read.
  void visit(CellReader& cells, int cx, int cy, double d, float g, double z) {
    if (g == 0.0f && d <= z && !cells.mayHoldOccupied(cx, cy)) return;
    visit(cells.at(cx, cy), d, g, z);
  }
  // pl(z) = (1 - r) S + r, S completed by the virtual obstacle at z_max (window `tail_window`)
  // unless the pass stopped.
  double plausibility(float tail_window, double r) const {
    const double s = stopped ? collected : collected + passed * tail_window;
    return (1.0 - r) * s + r;
  }
};

}  // namespace

void TracedScan::clear() {
  cells.clear();
  beams.clear();
  rays_bad = 0;
  rays_no_return = 0;
}

void ScanAccumulator::reset(const CellIndex& center, int half_size) {
  if (half_size != half_) {
    half_ = half_size;
    const int reach = (half_ + EvidentialGridMap::kTileSize - 1) >> kTileBits;
    tiles_side_ = 2 * reach + 1;
    slots_.assign(static_cast<size_t>(tiles_side_) * tiles_side_, Slot{});
    stamp_ = 0;
  }
  const int reach = tiles_side_ / 2;
  tile_x0_ = (center.x >> kTileBits) - reach;
  tile_y0_ = (center.y >> kTileBits) - reach;
  used_blocks_ = 0;
  last_tile_x_ = std::numeric_limits<int>::min();  // no tile's x (tile coordinates are >> 5)
  last_block_ = nullptr;
  if (++stamp_ == 0) {  // wrapped: forget every old stamp
    for (Slot& slot : slots_) slot.stamp = 0;
    stamp_ = 1;
  }
}

bool ScanAccumulator::findBlock(int tile_x, int tile_y) {
  const int tx = tile_x - tile_x0_, ty = tile_y - tile_y0_;
  if (static_cast<unsigned>(tx) >= static_cast<unsigned>(tiles_side_) ||
      static_cast<unsigned>(ty) >= static_cast<unsigned>(tiles_side_)) {
    return false;
  }
  Slot& slot = slots_[static_cast<size_t>(ty) * tiles_side_ + tx];
  if (slot.stamp != stamp_) {
    slot.stamp = stamp_;
    slot.block = newBlock(tile_x, tile_y);
  }
  last_tile_x_ = tile_x;
  last_tile_y_ = tile_y;
  last_block_ = &blocks_[slot.block];
  return true;
}

uint32_t ScanAccumulator::newBlock(int tile_x, int tile_y) {
  if (used_blocks_ == blocks_.size()) blocks_.emplace_back();
  Block& block = blocks_[used_blocks_];
  block.tile_x = tile_x;
  block.tile_y = tile_y;
  block.touched.fill(0);
  return used_blocks_++;
}

template <typename Fn>
void ScanAccumulator::forEachTouched(Fn&& fn) const {
  for (uint32_t b = 0; b < used_blocks_; ++b) {
    const Block& block = blocks_[b];
    for (size_t w = 0; w < block.touched.size(); ++w) {
      for (uint64_t bits = block.touched[w]; bits != 0; bits &= bits - 1) {
        fn(block, w * 64 + static_cast<size_t>(__builtin_ctzll(bits)));
      }
    }
  }
}

size_t ScanAccumulator::touched() const {
  size_t n = 0;
  forEachTouched([&](const Block&, size_t) { ++n; });
  return n;
}

double ScanAccumulator::applyTo(EvidentialGridMap* map, double* conflict_mass_added,
                                uint32_t floor_steps) const {
  double added = 0.0, mass = 0.0;
  {
    const ProfileTimer timer(ProfileSection::kApplyScan);
    const Block* tile_block = nullptr;
    const EvidentialGridMap::Tile* shared = nullptr;
    EvidentialGridMap::Tile* tile = nullptr;
    forEachTouched([&](const Block& block, size_t k) {
      if (&block != tile_block) {  // the blocks' cells come together: one tile lookup per block
        tile_block = &block;
        shared = map->tile(block.tile_x, block.tile_y);
        tile = nullptr;
      }
      if (tile == nullptr) {
        // A tile is taken for writing (cloned if shared) only at its first cell that the update
        // changes: space observed free many times stays as it is under clearing beams, and a
        // tile holding only such cells is neither copied nor written.
        if (shared != nullptr && updateLeavesCell(shared->cells[k], block.mass[k], floor_steps)) {
          return;
        }
        tile = &map->mutableTile(block.tile_x, block.tile_y);
      }
      ConflictIncrement increment;
      const float conflict = updateCell(tile->cells[k], block.mass[k], &increment, floor_steps);
      tile->cellWritten(static_cast<int>(k));
      if (conflict <= 0.0f) return;
      // This update multiplies 1 - m(∅) = exp(-λ) by 1 - K: λ grows by -ln(1 - K) and m(∅) by
      // exp(-λ) K (exact increments; the stored λ is rounded).
      added += increment.lambda_added;
      if (conflict_mass_added != nullptr) mass += increment.one_minus_conflict_before * conflict;
    });
  }
  if (conflict_mass_added != nullptr) *conflict_mass_added = mass;
  if (Profiler* profiler = Profiler::active()) {
    profiler->count(ProfileCounter::kGroupsApplied);
    profiler->count(ProfileCounter::kAppliedCells, touched());
  }
  return added;
}

double ScanAccumulator::openSpaceConflict(const EvidentialGridMap& map, int radius) const {
  auto believedFree = [](const Cell& c) { return c.free() > c.occupied(); };
  double mass = 0.0;
  forEachTouched([&](const Block& block, size_t k) {
    const ScanMass& m = block.mass[k];
    if (m.occupied < 0.5f) return;  // m̃(e) s(o) >= 1/2 needs s(o) >= 1/2
    // Tile coordinates are negative west and south of the origin: multiply, do not shift left
    // (a left shift of a negative value is undefined behaviour).
    const int x = block.tile_x * kTileSize + static_cast<int>(k & (kTileSize - 1));
    const int y = block.tile_y * kTileSize + static_cast<int>(k >> kTileBits);
    const Cell& c = map.cell(x, y);
    if (static_cast<double>(c.free()) * m.occupied < 0.5) return;
    bool open = true;
    for (int dy = -radius; dy <= radius && open; ++dy) {
      for (int dx = -radius; dx <= radius && open; ++dx) {
        open = believedFree(map.cell(x + dx, y + dy));
      }
    }
    if (!open) return;
    // The m(∅) applyTo will add to this cell: e^{-λ} K.
    const double conflict =
        static_cast<double>(c.occupied()) * m.free + static_cast<double>(c.free()) * m.occupied;
    mass += c.oneMinusConflict() * conflict;
  });
  return mass;
}

BeamModel::BeamModel(const SensorModelConfig& config, double resolution)
    : config_(config), resolution_(resolution) {
  const double sf = config_.forward_sigma, kf = config_.forward_window;
  const double si = config_.hit_sigma, ki = config_.free_gap;
  const double half_cell = 0.5 * resolution_;
  // A hit beam is traced until the forward window has fallen off and a few cells past the hit.
  beyond_hit_ = std::max(2.5 * resolution_, (kf + 4.0) * sf);
  open_space_radius_ = std::max(1, static_cast<int>(std::ceil(kf * sf / resolution_ - 1e-9)));

  table_step_ = std::min(sf, si) / kTableStepsPerSigma;
  inv_table_step_ = 1.0 / table_step_;
  g_half_ = (kf + 8.0) * sf;
  const int g_n = static_cast<int>(std::ceil(2.0 * g_half_ / table_step_)) + 1;
  g_table_.resize(g_n);
  for (int i = 0; i < g_n; ++i) {
    const double d = -g_half_ + i * table_step_;
    g_table_[i] = static_cast<float>(normalCdf(d / sf + kf) - normalCdf(d / sf - kf));
  }

  // Inverse model (algorithm.md §4) as a function of s = cell centre - hit point along the beam.
  const double r = config_.random_weight, po = config_.prior_occupied;
  s_min_ = -(ki * si + half_cell + 8.0 * si);
  s_max_ = half_cell + 8.0 * si;
  const int s_n = static_cast<int>(std::ceil((s_max_ - s_min_) / table_step_)) + 1;
  inverse_table_.resize(s_n);
  for (int i = 0; i < s_n; ++i) {
    const double s = s_min_ + i * table_step_;
    const double m_hit = normalCdf((s + half_cell) / si) - normalCdf((s - half_cell) / si);
    const double beyond = 1.0 - normalCdf((s + ki * si + half_cell) / si);
    const double pl = m_hit;
    const double eta = 1.0 / (1.0 - po * (1.0 - pl));
    ScanMass m;
    m.occupied = static_cast<float>((1.0 - r) * eta * (po * pl + (1.0 - po) * m_hit));
    m.free = static_cast<float>((1.0 - r) * eta * (1.0 - po) * beyond);
    inverse_table_[i] = m;
  }
  clear_mass_.free = static_cast<float>(1.0 - r);
  // The contradicting scans: a clearing beam, the stronger of the inverse model's two typical
  // masses and the same for every laser (a hit centred in a cell, the largest m(o), is weaker:
  // 0.63 at the defaults, ~0.09 for a 0.3 m laser, whose hits then take more scans to flip a cell).
  float hit_mass = 0.0f;
  for (const ScanMass& m : inverse_table_) hit_mass = std::max(hit_mass, m.occupied);
  confidence_floor_ =
      evidential_slam::confidenceFloor(config_.flip_scans, hit_mass, clear_mass_.free);
  floor_steps_ = confidenceFloorSteps(confidence_floor_);
}

double BeamModel::beamPlausibility(const EvidentialGridMap& map, const RayCell* cells, size_t n,
                                   double z) const {
  ForwardPass pass(config_);
  for (size_t i = 0; i < n && !pass.stopped; ++i) {
    const double d = cells[i].distance;
    pass.visit(map.cell(cells[i].x, cells[i].y), d, hitWindow(z - d), z);
  }
  return pass.plausibility(hitWindow(z - config_.usable_range), config_.random_weight);
}

double BeamModel::scanLogPlausibility(const EvidentialGridMap& map, const TracedScan& traced,
                                      int stride) const {
  double sum = 0.0;
  int k = 0;
  for (const TracedBeam& b : traced.beams) {
    if (!b.hit) continue;
    if (k++ % stride != 0) continue;
    sum += std::log(beamPlausibility(map, traced.cells.data() + b.begin, b.end - b.begin, b.range));
  }
  return sum;
}

template <typename Fn>
void BeamModel::traverse(const Eigen::Vector2d& origin, double angle, double length,
                         Fn&& fn) const {
  // Amanatides-Woo traversal in cell units.
  const double ox = origin.x() / resolution_, oy = origin.y() / resolution_;
  const double dx = std::cos(angle), dy = std::sin(angle);
  const double t_end = length / resolution_;
  int cx = static_cast<int>(std::floor(ox)), cy = static_cast<int>(std::floor(oy));
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double adx = std::abs(dx), ady = std::abs(dy);
  double t_max_x = adx > 1e-12 ? (step_x > 0 ? cx + 1 - ox : ox - cx) / adx : kInf;
  double t_max_y = ady > 1e-12 ? (step_y > 0 ? cy + 1 - oy : oy - cy) / ady : kInf;
  const double t_delta_x = adx > 1e-12 ? 1.0 / adx : kInf;
  const double t_delta_y = ady > 1e-12 ? 1.0 / ady : kInf;
  // Distance of the cell centre along the beam, updated incrementally as the traversal steps.
  double dist = ((cx + 0.5 - ox) * dx + (cy + 0.5 - oy) * dy) * resolution_;
  const double dist_step_x = step_x * dx * resolution_, dist_step_y = step_y * dy * resolution_;
  for (;;) {
    if constexpr (std::is_same_v<decltype(fn(cx, cy, 0.0f)), bool>) {
      if (!fn(cx, cy, static_cast<float>(dist))) break;
    } else {
      fn(cx, cy, static_cast<float>(dist));
    }
    if (t_max_x < t_max_y) {
      if (t_max_x > t_end) break;
      cx += step_x;
      t_max_x += t_delta_x;
      dist += dist_step_x;
    } else {
      if (t_max_y > t_end) break;
      cy += step_y;
      t_max_y += t_delta_y;
      dist += dist_step_y;
    }
  }
}

double BeamModel::logPlausibility(const EvidentialGridMap& map, const Pose2& sensor_in_map,
                                  const LaserScan& scan, int stride) const {
  const ProfileTimer timer(ProfileSection::kWideMatchForward);
  const Eigen::Vector2d origin = sensor_in_map.translation();
  double sum = 0.0;
  int hit_beams = 0;
  uint64_t rays_bad = 0, rays_no_return = 0;
  forEachRay(sensor_in_map, scan, &rays_bad, &rays_no_return, [&](const Ray& ray) {
    if (!ray.hit || hit_beams++ % stride != 0) return;
    const double z = ray.range;
    ForwardPass pass(config_);
    CellReader cells(map);
    traverse(origin, ray.angle, ray.length, [&](int cx, int cy, float d) {
      pass.visit(cells, cx, cy, d, hitWindow(z - d), z);
      return !pass.stopped;
    });
    sum += std::log(pass.plausibility(hitWindow(z - config_.usable_range), config_.random_weight));
  });
  return sum;
}

template <typename Fn>
void BeamModel::forEachRay(const Pose2& sensor_in_map, const LaserScan& scan, uint64_t* rays_bad,
                           uint64_t* rays_no_return, Fn&& fn) const {
  const double usable = config_.usable_range;
  const double sensor_max = scan.max_range > 0.0f ? scan.max_range : usable;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const float z = scan.ranges[i];
    Ray ray;
    ray.angle = sensor_in_map.theta + scan.bearings[i];
    const bool no_return = !scan.valid.empty() && scan.valid[i] == 0;
    if (no_return) {
      ++*rays_no_return;
      if (!config_.clear_no_return) continue;
      ray.length = usable;
      ray.hit = false;
    } else if (!std::isfinite(z) || z < 0.0f) {
      ++*rays_bad;
      continue;
    } else if (z < config_.min_range) {
      continue;
    } else if (z >= usable || z >= sensor_max) {
      ray.length = std::min(static_cast<double>(z), usable);
      ray.hit = false;
    } else {
      ray.length = z + beyond_hit_;
      ray.hit = true;
    }
    ray.range = ray.hit ? z : static_cast<float>(ray.length);
    fn(ray);
  }
}

void BeamModel::traceScan(const Pose2& sensor_in_map, const LaserScan& scan,
                          TracedScan* out) const {
  out->clear();
  const Eigen::Vector2d origin = sensor_in_map.translation();
  forEachRay(sensor_in_map, scan, &out->rays_bad, &out->rays_no_return, [&](const Ray& ray) {
    TracedBeam b;
    b.begin = static_cast<uint32_t>(out->cells.size());
    // No reserve of this beam's cells: it would reallocate the whole scan's cells at every beam
    // when `out` starts empty (quadratic in the beams); push_back grows geometrically.
    traverse(origin, ray.angle, ray.length, [&](int cx, int cy, float d) {
      out->cells.push_back(RayCell{cx, cy, d});
    });
    b.end = static_cast<uint32_t>(out->cells.size());
    b.range = ray.range;
    b.hit = ray.hit;
    out->beams.push_back(b);
  });
}

int BeamModel::windowHalfCells() const {
  return static_cast<int>(std::ceil((config_.usable_range + beyond_hit_) / resolution_)) + 2;
}

double BeamModel::integrateScan(const TracedScan& traced, EvidentialGridMap* map,
                                ScanAccumulator* scratch, ScanConflict* conflict) const {
  if (conflict != nullptr) *conflict = ScanConflict{};
  if (traced.cells.empty()) return 0.0;
  accumulateScan(traced, scratch);
  return applyScan(*scratch, map, conflict);
}

void BeamModel::accumulateScan(const TracedScan& traced, ScanAccumulator* scratch) const {
  // The window is centred on the first traced cell (the sensor's) and covers the longest beam.
  const RayCell first = traced.cells.empty() ? RayCell{0, 0, 0.0f} : traced.cells.front();
  scratch->reset(CellIndex{first.x, first.y}, windowHalfCells());
  for (const TracedBeam& b : traced.beams) {
    for (uint32_t i = b.begin; i < b.end; ++i) {
      const RayCell& c = traced.cells[i];
      addEvidence(scratch, c.x, c.y, c.distance, b.range, b.hit);
    }
  }
}

double BeamModel::applyScan(const ScanAccumulator& scratch, EvidentialGridMap* map,
                            ScanConflict* conflict) const {
  if (conflict == nullptr) return scratch.applyTo(map, nullptr, floor_steps_) / kLn2;
  // Before the update: it reads the neighbours of the cells the update changes.
  {
    const ProfileTimer timer(ProfileSection::kOpenSpace);
    conflict->open_space_added = scratch.openSpaceConflict(*map, open_space_radius_);
  }
  return scratch.applyTo(map, &conflict->mass_added, floor_steps_) / kLn2;
}

BeamModel::ScanEvidence BeamModel::weighAndIntegrate(const Pose2& sensor_in_map,
                                                     const LaserScan& scan, EvidentialGridMap* map,
                                                     ScanAccumulator* scratch, int stride,
                                                     std::vector<AnomalyCell>* anomaly) const {
  ScanEvidence out;
  out.log_plausibility = weighAndAccumulate(sensor_in_map, scan, *map, scratch, stride);
  if (anomaly != nullptr) scanAnomaly(*scratch, *map, open_space_radius_, anomaly);
  out.conflict_added_bits = applyScan(*scratch, map, &out.conflict);
  return out;
}

double BeamModel::weighAndAccumulate(const Pose2& sensor_in_map, const LaserScan& scan,
                                     const EvidentialGridMap& map, ScanAccumulator* scratch,
                                     int stride) const {
  std::optional<ProfileTimer> timer(std::in_place, ProfileSection::kWeighAccumulate);
  const Eigen::Vector2d origin = sensor_in_map.translation();
  const CellIndex sensor_cell = map.worldToCell(origin.x(), origin.y());
  scratch->reset(sensor_cell, windowHalfCells());
  double log_plausibility = 0.0;
  int hit_beams = 0;
  uint64_t rays_bad = 0, rays_no_return = 0;  // counted by the engine (SlamEngine::stats)
  forEachRay(sensor_in_map, scan, &rays_bad, &rays_no_return, [&](const Ray& ray) {
    const double z = ray.range;
    const bool weigh = ray.hit && hit_beams++ % stride == 0;
    ForwardPass pass(config_);
    pass.stopped = !weigh;
    CellReader cells(map);
    traverse(origin, ray.angle, ray.length, [&](int cx, int cy, float d) {
      if (!pass.stopped) pass.visit(cells, cx, cy, d, hitWindow(z - d), z);
      addEvidence(scratch, cx, cy, d, z, ray.hit);
    });
    if (!weigh) return;
    log_plausibility +=
        std::log(pass.plausibility(hitWindow(z - config_.usable_range), config_.random_weight));
  });
  if (Profiler* profiler = Profiler::active()) {
    // The cells visited, counted by traversing the rays again (outside the timed section): a
    // counter in the loop above cost the filter about 2 % when not profiling.
    timer.reset();
    uint64_t visited = 0;
    forEachRay(sensor_in_map, scan, &rays_bad, &rays_no_return, [&](const Ray& ray) {
      traverse(origin, ray.angle, ray.length, [&](int, int, float) { ++visited; });
    });
    profiler->count(ProfileCounter::kVisitedCells, visited);
    profiler->count(ProfileCounter::kGroupsWeighed);
  }
  return log_plausibility;
}

void BeamModel::accumulateForAnomaly(const Pose2& sensor_in_map, const LaserScan& scan,
                                     const BelievedFreeTiles& free_tiles,
                                     ScanAccumulator* scratch) const {
  const ProfileTimer timer(ProfileSection::kWeighAccumulate);
  const Eigen::Vector2d origin = sensor_in_map.translation();
  const int half = windowHalfCells();
  const CellIndex sensor_cell{static_cast<int>(std::floor(origin.x() / resolution_)),
                              static_cast<int>(std::floor(origin.y() / resolution_))};
  scratch->reset(sensor_cell, half);
  // The tiles kept, over the tiles of the accumulator's window (one more each side).
  constexpr int kBits = EvidentialGridMap::kTileBits;
  const int reach = ((half + EvidentialGridMap::kTileSize - 1) >> kBits) + 1;
  const int side = 2 * reach + 1;
  const int tx0 = (sensor_cell.x >> kBits) - reach, ty0 = (sensor_cell.y >> kBits) - reach;
  std::vector<uint8_t> keep(static_cast<size_t>(side) * static_cast<size_t>(side));
  for (int ty = 0; ty < side; ++ty) {
    for (int tx = 0; tx < side; ++tx) {
      keep[static_cast<size_t>(ty) * side + tx] = free_tiles.contains(tx0 + tx, ty0 + ty) ? 0 : 1;
    }
  }
  // Where along a hit beam its occupied mass reaches ε (see the header), s from the hit.
  const double epsilon =
      kScanSurfaceMass / (4.0 * static_cast<double>(std::max<size_t>(1, scan.size())));
  double s_reach = s_max_;
  for (size_t i = 0; i < inverse_table_.size(); ++i) {
    if (inverse_table_[i].occupied >= epsilon) {
      s_reach = s_min_ + (static_cast<double>(i) - 1.0) * table_step_;
      break;
    }
  }
  uint64_t rays_bad = 0, rays_no_return = 0;
  forEachRay(sensor_in_map, scan, &rays_bad, &rays_no_return, [&](const Ray& ray) {
    if (!ray.hit) return;
    // The tiles of the box around the beam from s_reach before its hit to its end, two cells wider
    // than the cells the traversal visits there.
    const double c = std::cos(ray.angle), s = std::sin(ray.angle);
    const double t0 = std::max(0.0, ray.range + s_reach - 2.0 * resolution_);
    const double t1 = ray.length + 2.0 * resolution_;
    const double ax = (origin.x() + t0 * c) / resolution_, ay = (origin.y() + t0 * s) / resolution_;
    const double bx = (origin.x() + t1 * c) / resolution_, by = (origin.y() + t1 * s) / resolution_;
    const int x_lo = (static_cast<int>(std::floor(std::min(ax, bx))) - 2) >> kBits;
    const int x_hi = (static_cast<int>(std::floor(std::max(ax, bx))) + 2) >> kBits;
    const int y_lo = (static_cast<int>(std::floor(std::min(ay, by))) - 2) >> kBits;
    const int y_hi = (static_cast<int>(std::floor(std::max(ay, by))) + 2) >> kBits;
    for (int ty = std::max(y_lo, ty0); ty <= std::min(y_hi, ty0 + side - 1); ++ty) {
      for (int tx = std::max(x_lo, tx0); tx <= std::min(x_hi, tx0 + side - 1); ++tx) {
        keep[static_cast<size_t>(ty - ty0) * side + (tx - tx0)] = 1;
      }
    }
  });
  forEachRay(sensor_in_map, scan, &rays_bad, &rays_no_return, [&](const Ray& ray) {
    const double z = ray.range;
    int last_x = std::numeric_limits<int>::min(), last_y = 0;
    bool kept = true;
    traverse(origin, ray.angle, ray.length, [&](int cx, int cy, float d) {
      if ((cx >> kBits) != last_x || (cy >> kBits) != last_y) {
        last_x = cx >> kBits;
        last_y = cy >> kBits;
        const int tx = last_x - tx0, ty = last_y - ty0;
        // Off the window: kept (the accumulator refuses it, as it would).
        kept = static_cast<unsigned>(tx) >= static_cast<unsigned>(side) ||
               static_cast<unsigned>(ty) >= static_cast<unsigned>(side) ||
               keep[static_cast<size_t>(ty) * side + tx] != 0;
      }
      if (kept) addEvidence(scratch, cx, cy, d, z, ray.hit);
    });
  });
}

}  // namespace evidential_slam
