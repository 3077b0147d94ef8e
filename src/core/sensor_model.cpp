#include "evidential_slam/core/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace evidential_slam {
namespace {

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// Beams are traced this many table steps per σ (tables are nearest-neighbour).
constexpr double kTableStepsPerSigma = 64.0;
// The forward pass stops once past the hit and the window is below this.
constexpr float kNegligibleWindow = 1e-6f;

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
    side_ = 2 * half_ + 1;
    slots_.assign(static_cast<size_t>(side_) * side_, Slot{});
    stamp_ = 0;
  }
  origin_x_ = center.x - half_;
  origin_y_ = center.y - half_;
  touched_.clear();
  if (++stamp_ == 0) {  // wrapped: forget every old stamp
    for (Slot& slot : slots_) slot.stamp = 0;
    stamp_ = 1;
  }
}

double ScanAccumulator::applyTo(EvidentialGridMap* map, double* conflict_mass_added) const {
  double added = 0.0, mass = 0.0;
  for (const Touched& t : touched_) {
    Cell& c = map->mutableCell(t.x, t.y);
    const float before = c.lambda;
    updateCell(c, t.mass);
    added += c.lambda - before;
    // m(∅) = 1 - exp(-λ), so its increase is exp(-λ_before) - exp(-λ_after).
    if (conflict_mass_added != nullptr && c.lambda != before) {
      mass += std::exp(-static_cast<double>(before)) - std::exp(-static_cast<double>(c.lambda));
    }
  }
  if (conflict_mass_added != nullptr) *conflict_mass_added = mass;
  return added;
}

double ScanAccumulator::openSpaceConflict(const EvidentialGridMap& map, int radius) const {
  auto believedFree = [](const Cell& c) { return c.free > c.occupied; };
  double mass = 0.0;
  for (const Touched& t : touched_) {
    if (t.mass.occupied < 0.5f) continue;  // m̃(e) s(o) >= 1/2 needs s(o) >= 1/2
    const Cell& c = map.cell(t.x, t.y);
    if (static_cast<double>(c.free) * t.mass.occupied < 0.5) continue;
    bool open = true;
    for (int dy = -radius; dy <= radius && open; ++dy) {
      for (int dx = -radius; dx <= radius && open; ++dx) open = believedFree(map.cell(t.x + dx, t.y + dy));
    }
    if (!open) continue;
    // The m(∅) applyTo will add to this cell: e^{-λ} K.
    const double k = static_cast<double>(c.occupied) * t.mass.free +
                     static_cast<double>(c.free) * t.mass.occupied;
    mass += std::exp(-static_cast<double>(c.lambda)) * k;
  }
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
}

float BeamModel::hitWindow(double delta) const {
  if (delta <= -g_half_ || delta >= g_half_) return 0.0f;
  return g_table_[static_cast<size_t>((delta + g_half_) * inv_table_step_ + 0.5)];
}

ScanMass BeamModel::inverseMass(double s) const {
  if (s <= s_min_) return clearMass();
  if (s >= s_max_) return ScanMass{};
  return inverse_table_[static_cast<size_t>((s - s_min_) * inv_table_step_ + 0.5)];
}

ScanMass BeamModel::clearMass() const {
  ScanMass m;
  m.free = static_cast<float>(1.0 - config_.random_weight);
  return m;
}

double BeamModel::beamPlausibility(const EvidentialGridMap& map, const RayCell* cells, size_t n,
                                   double z) const {
  // One outward pass of the recursion P_i = m̃o g_i + m̃e P_{i+1} + m̃Θ (g_i + P_{i+1} - g_i P_{i+1}):
  // T is the probability that the beam got past every cell so far, S the plausibility collected.
  double t = 1.0, s = 0.0;
  bool stopped = false;
  for (size_t i = 0; i < n; ++i) {
    const double d = cells[i].distance;
    const float g = hitWindow(z - d);
    const Cell& c = map.cell(cells[i].x, cells[i].y);
    const double mo = c.occupied, mu = 1.0 - c.occupied - c.free;
    s += t * g * (mo + mu);
    if (d > z && g < kNegligibleWindow) {
      stopped = true;
      break;
    }
    t *= 1.0 - mo - mu * g;
  }
  if (!stopped) s += t * hitWindow(z - config_.usable_range);
  const double r = config_.random_weight;
  return (1.0 - r) * s + r;
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

void BeamModel::traceRay(const Eigen::Vector2d& origin, double angle, double length,
                         std::vector<RayCell>* out) const {
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
  out->reserve(out->size() + static_cast<size_t>(2.0 * t_end) + 4);
  for (;;) {
    out->push_back(RayCell{cx, cy, static_cast<float>(dist)});
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

void BeamModel::traceScan(const Pose2& sensor_in_map, const LaserScan& scan,
                          TracedScan* out) const {
  out->clear();
  const Eigen::Vector2d origin = sensor_in_map.translation();
  const double usable = config_.usable_range;
  const double sensor_max = scan.max_range > 0.0f ? scan.max_range : usable;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const float z = scan.ranges[i];
    const double angle = sensor_in_map.theta + scan.bearings[i];
    const bool no_return = !scan.valid.empty() && scan.valid[i] == 0;
    double length;
    bool hit;
    if (no_return) {
      ++out->rays_no_return;
      if (!config_.clear_no_return) continue;
      length = usable;
      hit = false;
    } else if (!std::isfinite(z) || z < 0.0f) {
      ++out->rays_bad;
      continue;
    } else if (z < config_.min_range) {
      continue;
    } else if (z >= usable || z >= sensor_max) {
      length = std::min(static_cast<double>(z), usable);
      hit = false;
    } else {
      length = z + beyond_hit_;
      hit = true;
    }
    TracedBeam b;
    b.begin = static_cast<uint32_t>(out->cells.size());
    traceRay(origin, angle, length, &out->cells);
    b.end = static_cast<uint32_t>(out->cells.size());
    b.range = hit ? z : static_cast<float>(length);
    b.hit = hit;
    out->beams.push_back(b);
  }
}

double BeamModel::integrateScan(const TracedScan& traced, EvidentialGridMap* map,
                                ScanAccumulator* scratch, ScanConflict* conflict) const {
  if (conflict != nullptr) *conflict = ScanConflict{};
  if (traced.cells.empty()) return 0.0;
  // The window is centred on the first traced cell (the sensor's) and covers the longest beam.
  const RayCell& first = traced.cells.front();
  const int half =
      static_cast<int>(std::ceil((config_.usable_range + beyond_hit_) / resolution_)) + 2;
  scratch->reset(CellIndex{first.x, first.y}, half);
  const ScanMass clear = clearMass();
  for (const TracedBeam& b : traced.beams) {
    for (uint32_t i = b.begin; i < b.end; ++i) {
      const RayCell& c = traced.cells[i];
      if (!b.hit) {
        scratch->add(c.x, c.y, clear);
        continue;
      }
      const ScanMass m = inverseMass(c.distance - b.range);
      if (m.occupied == 0.0f && m.free == 0.0f) continue;  // vacuous: nothing to add
      scratch->add(c.x, c.y, m);
    }
  }
  constexpr double kLn2 = 0.69314718055994530942;
  if (conflict == nullptr) return scratch->applyTo(map) / kLn2;
  conflict->open_space_added = scratch->openSpaceConflict(*map, open_space_radius_);
  return scratch->applyTo(map, &conflict->mass_added) / kLn2;
}

}  // namespace evidential_slam
