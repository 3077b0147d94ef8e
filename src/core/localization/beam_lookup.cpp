#include "evidential_slam/core/localization/beam_lookup.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "evidential_slam/core/localization/distance_transform.h"
#include "evidential_slam/core/measures.h"

namespace evidential_slam {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSqrt2 = 1.41421356237309504880;
// The march jumps only where the nearest opaque cell is at least this far (cells): the jump,
// d - sqrt(2), then passes at least one cell.
constexpr int kJumpCells = 3;
// A beam that got through with less than this is stopped: what it could still collect is below
// the float noise of a plausibility of at least r.
constexpr double kStopped = 1e-6;

// A cell-by-cell walk along a ray (Amanatides-Woo), in cell units, that can be (re)started at any
// point of the ray: the same cells in the same order as BeamModel's traversal.
struct Cursor {
  Cursor(double ox_, double oy_, double angle) : ox(ox_), oy(oy_) {
    dx = std::cos(angle);
    dy = std::sin(angle);
    step_x = dx > 0 ? 1 : -1;
    step_y = dy > 0 ? 1 : -1;
    const double adx = std::abs(dx), ady = std::abs(dy);
    t_delta_x = adx > 1e-12 ? 1.0 / adx : kInf;
    t_delta_y = ady > 1e-12 ? 1.0 / ady : kInf;
  }
  // The cell holding the ray's point at parameter t (cells from the origin).
  void enterAt(double t) {
    cx = static_cast<int>(std::floor(ox + t * dx));
    cy = static_cast<int>(std::floor(oy + t * dy));
    t_max_x = t_delta_x < kInf ? (step_x > 0 ? cx + 1 - ox : ox - cx) * t_delta_x : kInf;
    t_max_y = t_delta_y < kInf ? (step_y > 0 ? cy + 1 - oy : oy - cy) * t_delta_y : kInf;
    t_enter = t;
  }
  double exitParameter() const { return std::min(t_max_x, t_max_y); }
  void next() {
    t_enter = exitParameter();
    if (t_max_x < t_max_y) {
      cx += step_x;
      t_max_x += t_delta_x;
    } else {
      cy += step_y;
      t_max_y += t_delta_y;
    }
  }
  // Distance of the cell's centre along the ray (cells).
  double centreDistance() const { return (cx + 0.5 - ox) * dx + (cy + 0.5 - oy) * dy; }

  double ox, oy, dx, dy;
  int step_x, step_y;
  double t_delta_x, t_delta_y;
  int cx = 0, cy = 0;
  double t_max_x = kInf, t_max_y = kInf;
  double t_enter = 0.0;
};

// The parameters (cells) where the ray enters and leaves the box's cells; enter > leave when it
// misses them.
void clip(const Cursor& c, const CellBox& box, double* enter, double* leave) {
  double t0 = -kInf, t1 = kInf;
  const auto slab = [&](double o, double d, double lo, double hi) {
    if (std::abs(d) < 1e-12) {
      if (o < lo || o >= hi) t0 = kInf;
      return;
    }
    double a = (lo - o) / d, b = (hi - o) / d;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  };
  slab(c.ox, c.dx, box.min_x, box.max_x + 1.0);
  slab(c.oy, c.dy, box.min_y, box.max_y + 1.0);
  *enter = t0;
  *leave = t1;
}

}  // namespace

const BeamLookup::CellMasses BeamLookup::kVacuous{};

BeamLookup::BeamLookup(const EvidentialGridMap& map, bool conflict_as_unknown)
    : box_(map.observedBox()),
      resolution_(map.resolution()),
      conflict_as_unknown_(conflict_as_unknown) {
  if (box_.empty()) throw std::invalid_argument("BeamLookup: the map has no observed cell");
  const int w = box_.width(), h = box_.height();
  // Filled cell by cell (not value-initialised first: one pass over the largest array).
  cells_.reserve(static_cast<size_t>(w) * static_cast<size_t>(h));
  std::vector<uint8_t> opaque(cells_.capacity(), 0), uncertain(cells_.capacity(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Cell& c = map.cell(box_.min_x + x, box_.min_y + y);
      CellMasses& m = cells_.emplace_back();
      double mo = c.occupied(), mu = c.unknown();
      if (conflict_as_unknown_ && c.conflicted()) {  // as ForwardPass::visit
        const double keep = c.oneMinusConflict();
        mu += (1.0 - keep) * (mo + c.free());
        mo *= keep;
      }
      m.occupied = static_cast<float>(mo);
      m.unknown = static_cast<float>(mu);
      m.observed = c.observed() ? 1 : 0;
      // NS = m(Θ), which is m̃(Θ) unless the cell conflicts (nonSpecificity, without its exp).
      m.free = m.observed != 0 && pignistic(c) < 0.25 &&
                       (c.conflicted() ? nonSpecificity(c) : c.unknown()) < 0.5
                   ? 1
                   : 0;
      opaque[static_cast<size_t>(y) * w + x] = m.occupied >= kOpaque ? 1 : 0;
      uncertain[static_cast<size_t>(y) * w + x] =
          m.observed == 0 || m.occupied >= kCertain || m.unknown >= kCertain ? 1 : 0;
    }
  }
  // Distances in whole cells, saturated at 255 (a jump of 12 m at 5 cm cells), over the seeds.
  std::vector<float> scratch;
  saturatedDistanceTransform(&opaque, w, h, &scratch);
  saturatedDistanceTransform(&uncertain, w, h, &scratch);
  opaque_distance_ = std::move(opaque);
  uncertain_distance_ = std::move(uncertain);
  // Off the box every cell is vacuous (uncertain): no jump may leave it unseen.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int border = std::min({x + 1, y + 1, w - x, h - y});
      uint8_t& d = uncertain_distance_[static_cast<size_t>(y) * w + x];
      d = static_cast<uint8_t>(std::min<int>(d, border));
    }
  }
}

size_t BeamLookup::memoryBytes() const {
  return cells_.capacity() * sizeof(CellMasses) + opaque_distance_.capacity() +
         uncertain_distance_.capacity();
}

const BeamLookup::CellMasses& BeamLookup::at(int cx, int cy) const {
  const int x = cx - box_.min_x, y = cy - box_.min_y;
  if (x < 0 || y < 0 || x >= box_.width() || y >= box_.height()) return kVacuous;
  return cells_[static_cast<size_t>(y) * box_.width() + x];
}

double BeamLookup::firstOpaque(const Eigen::Vector2d& origin, double angle,
                               double max_range) const {
  Cursor c(origin.x() / resolution_, origin.y() / resolution_, angle);
  const double t_max = max_range / resolution_;
  double enter, leave;
  clip(c, box_, &enter, &leave);
  if (!(enter < leave) || leave <= 0.0 || enter >= t_max) return max_range;
  double t = std::max(0.0, enter);
  const int w = box_.width();
  c.enterAt(t);
  while (c.t_enter < std::min(leave, t_max)) {
    const int x = c.cx - box_.min_x, y = c.cy - box_.min_y;
    if (x < 0 || y < 0 || x >= w || y >= box_.height()) {  // a border touched on the way in
      c.next();
      continue;
    }
    const size_t i = static_cast<size_t>(y) * w + x;
    if (cells_[i].occupied >= kOpaque) return c.t_enter * resolution_;
    const int d = opaque_distance_[i];
    if (d >= kJumpCells) {
      const double jump = c.t_enter + (d - kSqrt2) - 1e-6;
      if (jump > c.exitParameter()) {
        c.enterAt(jump);
        continue;
      }
    }
    c.next();
  }
  return max_range;
}

LookupBeam BeamLookup::beam(const BeamModel& model, const Eigen::Vector2d& origin, double angle,
                            double z, const Options& options) const {
  const SensorModelConfig& config = model.config();
  const double r = config.random_weight;
  LookupBeam out;
  Cursor c(origin.x() / resolution_, origin.y() / resolution_, angle);
  // Cells whose centre lies this far before the range are outside the hit window
  // (g < Φ(-5) < 3e-7): only their m̃(o) matters.
  const double t_window = (z - (config.forward_window + 5.0) * config.forward_sigma) / resolution_;
  const double t_end = (z + model.traceBeyondHit()) / resolution_;
  double enter, leave;
  clip(c, box_, &enter, &leave);
  const int w = box_.width(), h = box_.height();
  double passed = 1.0, collected = 0.0;
  bool crossed_opaque = false;

  // The march, up to the hit window: only opaque cells cost the beam anything.
  bool started = false;
  if (enter < leave && leave > 0.0 && enter < t_window) {
    c.enterAt(std::max(0.0, enter));
    started = true;
    while (c.centreDistance() < t_window && c.t_enter < leave) {
      const int x = c.cx - box_.min_x, y = c.cy - box_.min_y;
      if (x >= 0 && y >= 0 && x < w && y < h) {
        const size_t i = static_cast<size_t>(y) * w + x;
        const int d = opaque_distance_[i];
        if (d >= kJumpCells) {
          // No opaque cell within d - sqrt(2) of any point of this cell; window cells (centre at
          // t_window or beyond) start no earlier than t_window - sqrt(2)/2.
          const double jump = std::min({c.t_enter + (d - kSqrt2) - 1e-6, t_window - 0.75, leave});
          if (jump > c.exitParameter()) {
            c.enterAt(jump);
            continue;
          }
        }
        const float mo = cells_[i].occupied;
        if (mo > 0.0f) {
          passed *= 1.0 - mo;
          crossed_opaque = crossed_opaque || mo >= kOpaque;
          if (passed < kStopped) {
            out.plausibility = r;
            return out;
          }
        }
      }
      c.next();
    }
  }
  if (!started) {
    c.enterAt(std::max(0.0, t_window - 0.75));
  } else if (c.t_enter >= leave && c.t_enter < t_window - 0.75) {
    // The ray left the box before its window: the cells up to it are vacuous (nothing opaque).
    if (!options.unobserved_collects) {
      out.plausibility = r;  // and the window's cells, never observed, collect nothing
      return out;
    }
    c.enterAt(t_window - 0.75);
  }

  // The hit window, cell by cell as BeamModel traces it (ForwardPass::visit), but for runs of
  // certain cells (observed, m̃(o) and m̃(Θ) below kCertain), which it jumps over: they would
  // neither collect nor stop the beam.
  bool stopped = false;
  for (;;) {
    const int x = c.cx - box_.min_x, y = c.cy - box_.min_y;
    if (x >= 0 && y >= 0 && x < w && y < h) {
      const int d = uncertain_distance_[static_cast<size_t>(y) * w + x];
      if (d >= kJumpCells) {
        const double jump = c.t_enter + (d - kSqrt2) - 1e-6;
        if (jump > t_end) break;
        if (jump > c.exitParameter()) {
          c.enterAt(jump);
          continue;
        }
      }
    }
    const CellMasses& m = at(c.cx, c.cy);
    const double d = c.centreDistance() * resolution_;
    const float g = model.hitWindow(z - d);
    if (g == 0.0f) {
      if (d > z) {
        stopped = true;
        break;
      }
      passed *= 1.0 - m.occupied;
      crossed_opaque = crossed_opaque || m.occupied >= kOpaque;
    } else {
      const double mo = m.occupied, mu = m.unknown;
      crossed_opaque = crossed_opaque || m.occupied >= kOpaque;
      if (m.observed != 0 || options.unobserved_collects) collected += passed * g * (mo + mu);
      if (d > z && g < 1e-6f) {
        stopped = true;
        break;
      }
      passed *= 1.0 - mo - mu * g;
    }
    if (passed < kStopped) {  // what is left could not lift the plausibility above float noise
      stopped = true;
      break;
    }
    if (c.exitParameter() > t_end) break;
    c.next();
  }
  double s = stopped ? collected : collected + passed * model.hitWindow(z - config.usable_range);
  // Short: nothing opaque before the range or around it, and the endpoint's cell held free.
  if (!crossed_opaque) {
    const CellMasses& end = at(static_cast<int>(std::floor(c.ox + c.dx * z / resolution_)),
                               static_cast<int>(std::floor(c.oy + c.dy * z / resolution_)));
    out.short_reading = end.free != 0;
  }
  if (out.short_reading) s = (1.0 - options.short_rate) * s + options.short_rate;
  out.plausibility = (1.0 - r) * s + r;
  return out;
}

double BeamLookup::logPlausibility(const BeamModel& model, const Pose2& sensor_in_map,
                                   const LaserScan& beams, const Options& options,
                                   size_t* shorts) const {
  const Eigen::Vector2d origin = sensor_in_map.translation();
  // The product of the plausibilities (each >= r), its log taken when it gets small: one log per
  // few dozen beams instead of one per beam.
  double sum = 0.0, product = 1.0;
  size_t n_short = 0;
  for (size_t i = 0; i < beams.ranges.size(); ++i) {
    const LookupBeam b =
        beam(model, origin, sensor_in_map.theta + beams.bearings[i], beams.ranges[i], options);
    product *= b.plausibility;
    if (product < 1e-200) {
      sum += std::log(product);
      product = 1.0;
    }
    n_short += b.short_reading ? 1 : 0;
  }
  if (shorts != nullptr) *shorts = n_short;
  return sum + std::log(product);
}

}  // namespace evidential_slam
