#include "evidential_slam/core/scan_matcher.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {
namespace {
constexpr double kKernelStepsPerCell2 = 64.0;
// Cauchy weight scale (m): endpoints far from their matched cell count less.
constexpr double kRobustScale = 0.1;
constexpr double kConvergedTranslation = 1e-4;  // m
constexpr double kConvergedRotation = 1e-4;     // rad

// Reads the 3 x 3 cells around (cx, cy) of a grid.
class Neighbourhood {
 public:
  Neighbourhood(const EvidentialGridMap& map, int cx, int cy) : map_(map), cx_(cx), cy_(cy) {
    constexpr int kBits = EvidentialGridMap::kTileBits;
    if (((cx - 1) >> kBits) == ((cx + 1) >> kBits) && ((cy - 1) >> kBits) == ((cy + 1) >> kBits)) {
      in_one_tile_ = true;
      tile_ = map.tile(cx >> kBits, cy >> kBits);
    }
  }
  const Cell& at(int dx, int dy) const {
    if (!in_one_tile_) return map_.cell(cx_ + dx, cy_ + dy);
    if (tile_ == nullptr) return kVacuous;
    return tile_->cells[EvidentialGridMap::cellInTile(cx_ + dx, cy_ + dy)];
  }

 private:
  static const Cell kVacuous;
  const EvidentialGridMap& map_;
  int cx_, cy_;
  bool in_one_tile_ = false;
  const EvidentialGridMap::Tile* tile_ = nullptr;
};
const Cell Neighbourhood::kVacuous{};

// The 3x3 cells score() looks at, the centre (the endpoint's own cell) first.
constexpr CellIndex kScoreNeighbours[9] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                           {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
}  // namespace

ScanMatcher::ScanMatcher(const ScanMatcherConfig& config, const SensorModelConfig& sensor,
                         double resolution)
    : config_(config), sensor_(sensor), resolution_(resolution) {
  const int r = static_cast<int>(std::ceil(config_.search_radius / resolution_));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (dx * dx + dy * dy <= r * r) spiral_.push_back(CellIndex{dx, dy});
    }
  }
  std::stable_sort(spiral_.begin(), spiral_.end(), [](const CellIndex& a, const CellIndex& b) {
    return a.x * a.x + a.y * a.y < b.x * b.x + b.y * b.y;
  });
  const double sigma_cells = config_.score_sigma / resolution_;
  kernel_scale_ = kKernelStepsPerCell2;
  kernel_.resize(static_cast<size_t>(std::ceil(8.0 * kernel_scale_)) + 2);  // up to (2 cells)² · 2
  for (size_t i = 0; i < kernel_.size(); ++i) {
    const double d2 = static_cast<double>(i) / kernel_scale_;
    kernel_[i] = static_cast<float>(std::exp(-0.5 * d2 / (sigma_cells * sigma_cells)));
  }
}

std::vector<MatchPoint> ScanMatcher::endpoints(const LaserScan& scan) const {
  std::vector<MatchPoint> pts;
  const double limit = std::min<double>(
      sensor_.usable_range, scan.max_range > 0.0f ? scan.max_range : sensor_.usable_range);
  int k = 0;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const float z = scan.ranges[i];
    if (!scan.valid.empty() && scan.valid[i] == 0) continue;
    if (!std::isfinite(z) || z < sensor_.min_range || z >= limit) continue;
    if (k++ % config_.beam_stride != 0) continue;
    const Eigen::Vector2d dir(std::cos(scan.bearings[i]), std::sin(scan.bearings[i]));
    // Probe in front of the inverse model's Θ gap (k_i·σ + Δ/2), where repeated passes make cells
    // free.
    const double back = std::min(sensor_.free_gap * sensor_.hit_sigma + 1.5 * resolution_, 0.5 * z);
    pts.push_back(MatchPoint{scan.sensor_pose.transformPoint(z * dir),
                             scan.sensor_pose.transformPoint((z - back) * dir)});
  }
  return pts;
}

double ScanMatcher::score(const EvidentialGridMap& map, const Pose2& pose,
                          const std::vector<MatchPoint>& pts) const {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const double inv_res = 1.0 / resolution_;
  double total = 0.0;
  for (const MatchPoint& p : pts) {
    const double fx = (pose.x + c * p.hit.x() - s * p.hit.y()) * inv_res;
    const double fy = (pose.y + s * p.hit.x() + c * p.hit.y()) * inv_res;
    const int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy));
    const int jx =
        static_cast<int>(std::floor((pose.x + c * p.free.x() - s * p.free.y()) * inv_res));
    const int jy =
        static_cast<int>(std::floor((pose.y + s * p.free.x() + c * p.free.y()) * inv_res));
    // The best of the 3x3 cells, the one holding the endpoint first. A cell's term is
    // (m̃(o)·m̃(e))·kernel with both masses ≤ 1, so a cell whose kernel, or m̃(o)·kernel, is not
    // above the best so far cannot win and its remaining lookups are skipped (the result is the
    // same maximum, bit for bit: float rounding is monotone).
    // Both 3x3 blocks are read through their tiles when each lies in one tile (most do).
    const Neighbourhood hit_cells(map, ix, iy), free_cells(map, jx, jy);
    float best = 0.0f;
    for (const CellIndex& o : kScoreNeighbours) {
      const double ddx = ix + o.x + 0.5 - fx, ddy = iy + o.y + 0.5 - fy;
      const size_t k = static_cast<size_t>((ddx * ddx + ddy * ddy) * kernel_scale_);
      const float kernel = kernel_[std::min(k, kernel_.size() - 1)];
      if (kernel <= best) continue;
      float occ = hit_cells.at(o.x, o.y).occupied();
      if (occ <= best || occ * kernel <= best) continue;
      occ *= free_cells.at(o.x, o.y).free();
      best = std::max(best, occ * kernel);
    }
    total += best;
  }
  return total;
}

bool ScanMatcher::icpStep(const EvidentialGridMap& map, const std::vector<MatchPoint>& pts,
                          Pose2* pose) const {
  const double c = std::cos(pose->theta), s = std::sin(pose->theta);
  const float threshold = static_cast<float>(config_.occupied_threshold);
  // Weighted sums for the closed-form 2-D rigid alignment of matched pairs (q -> y).
  double sw = 0, sqx = 0, sqy = 0, syx = 0, syy = 0;
  std::vector<Eigen::Vector4d> pairs;  // q.x, q.y, y.x, y.y
  pairs.reserve(pts.size());
  std::vector<double> weights;
  weights.reserve(pts.size());
  for (const MatchPoint& p : pts) {
    const double qx = pose->x + c * p.hit.x() - s * p.hit.y();
    const double qy = pose->y + s * p.hit.x() + c * p.hit.y();
    const CellIndex q = map.worldToCell(qx, qy);
    const CellIndex f = map.worldToCell(pose->x + c * p.free.x() - s * p.free.y(),
                                        pose->y + s * p.free.x() + c * p.free.y());
    for (const CellIndex& o : spiral_) {
      if (map.cell(q.x + o.x, q.y + o.y).occupied() < threshold) continue;
      if (map.cell(f.x + o.x, f.y + o.y).free() < threshold) continue;
      const double yx = (q.x + o.x + 0.5) * resolution_, yy = (q.y + o.y + 0.5) * resolution_;
      const double d2 = (yx - qx) * (yx - qx) + (yy - qy) * (yy - qy);
      const double w = 1.0 / (1.0 + d2 / (kRobustScale * kRobustScale));
      pairs.emplace_back(qx, qy, yx, yy);
      weights.push_back(w);
      sw += w;
      sqx += w * qx;
      sqy += w * qy;
      syx += w * yx;
      syy += w * yy;
      break;
    }
  }
  if (pairs.size() <
      std::max<size_t>(3, static_cast<size_t>(config_.min_match_fraction * pts.size()))) {
    return false;
  }
  const double mqx = sqx / sw, mqy = sqy / sw, myx = syx / sw, myy = syy / sw;
  double sin_sum = 0, cos_sum = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const double ax = pairs[i][0] - mqx, ay = pairs[i][1] - mqy;
    const double bx = pairs[i][2] - myx, by = pairs[i][3] - myy;
    sin_sum += weights[i] * (ax * by - ay * bx);
    cos_sum += weights[i] * (ax * bx + ay * by);
  }
  const double dtheta = std::atan2(sin_sum, cos_sum);
  const double dc = std::cos(dtheta), ds = std::sin(dtheta);
  // World-frame correction: y ≈ R(dθ)(q - mq) + my.
  const double tx = myx - (dc * mqx - ds * mqy), ty = myy - (ds * mqx + dc * mqy);
  *pose = Pose2(dc * pose->x - ds * pose->y + tx, ds * pose->x + dc * pose->y + ty,
                pose->theta + dtheta);
  return true;
}

Pose2 ScanMatcher::hillClimb(const EvidentialGridMap& map, const Pose2& start,
                             const std::vector<MatchPoint>& pts) const {
  Pose2 current = start;
  double current_score = score(map, current, pts);
  double lin = config_.linear_step, ang = config_.angular_step;
  for (int level = 0; level <= config_.refinements; ++level) {
    int undo = -1;  // the move that would undo the last one taken: back where the score was lower
    for (int it = 0; it < config_.max_iterations; ++it) {
      const Pose2 moves[6] = {
          {current.x + lin, current.y, current.theta}, {current.x - lin, current.y, current.theta},
          {current.x, current.y + lin, current.theta}, {current.x, current.y - lin, current.theta},
          {current.x, current.y, current.theta + ang}, {current.x, current.y, current.theta - ang}};
      Pose2 best = current;
      double best_score = current_score;
      int taken = -1;
      for (int m = 0; m < 6; ++m) {
        if (m == undo) continue;
        const double sc = score(map, moves[m], pts);
        if (sc > best_score) {
          best_score = sc;
          best = moves[m];
          taken = m;
        }
      }
      if (best_score <= current_score) break;
      current = best;
      current_score = best_score;
      undo = taken ^ 1;  // moves come in pairs: +/- x, +/- y, +/- theta
    }
    lin *= 0.5;
    ang *= 0.5;
  }
  return current;
}

bool ScanMatcher::icp(const EvidentialGridMap& map, const std::vector<MatchPoint>& pts,
                      Pose2* pose) const {
  for (int it = 0; it < config_.icp_iterations; ++it) {
    const Pose2 before = *pose;
    if (!icpStep(map, pts, pose)) {
      *pose = before;
      return it > 0;  // at the first step: the map does not explain this scan (yet)
    }
    const Pose2 change = before.between(*pose);
    if (std::hypot(change.x, change.y) < kConvergedTranslation &&
        std::abs(change.theta) < kConvergedRotation) {
      break;
    }
  }
  return true;
}

Pose2 ScanMatcher::refine(const EvidentialGridMap& map, const Pose2& initial,
                          const std::vector<MatchPoint>& pts) const {
  if (pts.empty()) return initial;
  Pose2 pose = initial;
  if (!icp(map, pts, &pose)) return initial;
  return config_.max_iterations > 0 ? hillClimb(map, pose, pts) : pose;
}

Pose2 ScanMatcher::search(const EvidentialGridMap& map, const Pose2& predicted,
                          const std::vector<MatchPoint>& pts, double heading_window,
                          double* best_score_out) const {
  *best_score_out = -1.0;
  if (pts.empty()) return predicted;
  const int n = static_cast<int>(std::floor(heading_window / config_.heading_step + 1e-9));
  Pose2 best = predicted;
  double best_score = -1.0;
  for (int i = 0; i <= 2 * n; ++i) {
    const int k = (i + 1) / 2 * (i % 2 == 1 ? 1 : -1);  // 0, +1, -1, +2, -2, ...
    Pose2 pose(predicted.x, predicted.y, predicted.theta + k * config_.heading_step);
    if (!icp(map, pts, &pose)) continue;
    const double s = score(map, pose, pts);
    if (s > best_score) {
      best_score = s;
      best = pose;
    }
  }
  *best_score_out = best_score;
  return best;
}

}  // namespace evidential_slam
