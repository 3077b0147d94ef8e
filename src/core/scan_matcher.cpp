#include "evidential_slam/core/scan_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "evidential_slam/core/profile.h"

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
    if (tile_ == nullptr) return EvidentialGridMap::vacuousCell();
    return tile_->cells[EvidentialGridMap::cellInTile(cx_ + dx, cy_ + dy)];
  }

 private:
  const EvidentialGridMap& map_;
  int cx_, cy_;
  bool in_one_tile_ = false;
  const EvidentialGridMap::Tile* tile_ = nullptr;
};

// ICP's correspondence search on one map: for an endpoint in cell `hit` probed free in cell
// `free`, the nearest offset o within `radius` cells (ties: smaller dy, then smaller dx) with
// m̃(o)(hit + o) and m̃(e)(free + o) both ≥ `threshold`. Occupied cells are found from the tiles'
// occupied rows (EvidentialGridMap::Tile::occupiedRows), a word per row of the window, so an
// endpoint with no target near it costs a few words, not a cell read per offset.
class CorrespondenceSearch {
 public:
  // `with_normals`: normal() will be called, so nearest() also fetches the tiles it reads.
  CorrespondenceSearch(const EvidentialGridMap& map, float threshold, int radius,
                       const std::vector<int>& row_half_width, bool with_normals)
      : map_(map),
        threshold_(threshold),
        radius_(radius),
        reach_(radius + (with_normals ? kNormalReach : 0)),
        row_half_width_(row_half_width) {}

  bool nearest(const CellIndex& hit, const CellIndex& free, CellIndex* offset) {
    const int r = radius_, reach = reach_;
    fetchTiles(hit.x - reach, hit.y - reach, hit.x + reach, hit.y + reach);
    // Rows by growing |dy|, until dy² alone exceeds the best d².
    int best_d2 = std::numeric_limits<int>::max(), best_dy = 0, best_dx = 0;
    for (int k = 0; k <= r && k * k <= best_d2; ++k) {
      const int w = row_half_width_[static_cast<size_t>(k)];
      for (const int dy : {-k, k}) {
        forEachOccupied(hit.y + dy, hit.x - w, hit.x + w, [&](int x) {
          const int dx = x - hit.x, d2 = dx * dx + dy * dy;
          if (d2 > best_d2 ||
              (d2 == best_d2 && (dy > best_dy || (dy == best_dy && dx > best_dx)))) {
            return;
          }
          if (map_.cell(free.x + dx, free.y + dy).free() < threshold_) return;
          best_d2 = d2;
          best_dy = dy;
          best_dx = dx;
        });
        if (k == 0) break;
      }
    }
    if (best_d2 == std::numeric_limits<int>::max()) return false;
    *offset = CellIndex{best_dx, best_dy};
    return true;
  }

  // After nearest() found `cell`: the unit normal of the surface the target cells within
  // kNormalReach of it lie on (the axis of their least spread); false where they do not line up
  // (fewer than 3, or a corner or blob: spread across over 0.3 of the spread along).
  bool normal(const CellIndex& cell, Eigen::Vector2d* n) const {
    int count = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int dy = -kNormalReach; dy <= kNormalReach; ++dy) {
      forEachOccupied(cell.y + dy, cell.x - kNormalReach, cell.x + kNormalReach, [&](int x) {
        const int dx = x - cell.x;
        ++count;
        sx += dx;
        sy += dy;
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
      });
    }
    if (count < 3) return false;
    const double inv = 1.0 / count, mx = sx * inv, my = sy * inv;
    const double cxx = sxx * inv - mx * mx, cyy = syy * inv - my * my, cxy = sxy * inv - mx * my;
    const double half_diff = 0.5 * (cxx - cyy), root = std::sqrt(half_diff * half_diff + cxy * cxy);
    const double mean = 0.5 * (cxx + cyy), along = mean + root, across = mean - root;
    if (across > 0.3 * along) return false;
    // The eigenvector of the smaller eigenvalue, from whichever row of (C - across·I) is longer.
    const Eigen::Vector2d from_x(cxy, across - cxx), from_y(across - cyy, cxy);
    *n = (from_x.squaredNorm() >= from_y.squaredNorm() ? from_x : from_y).normalized();
    return true;
  }

 private:
  static constexpr int kNormalReach = 2;  // cells
  using Rows = EvidentialGridMap::Tile::Rows;
  static constexpr int kBits = EvidentialGridMap::kTileBits;
  static constexpr int kSize = EvidentialGridMap::kTileSize;

  // The occupied rows of the tiles covering the cell box (vacuous tiles: no bits).
  // Consecutive endpoints mostly need the same tiles: kept when the box of tiles is unchanged.
  void fetchTiles(int min_x, int min_y, int max_x, int max_y) {
    const int tx0 = min_x >> kBits, ty0 = min_y >> kBits;
    const int nx = (max_x >> kBits) - tx0 + 1, ny = (max_y >> kBits) - ty0 + 1;
    if (tx0 == tx0_ && ty0 == ty0_ && nx == nx_ && ny == ny_) return;
    tx0_ = tx0;
    ty0_ = ty0;
    nx_ = nx;
    ny_ = ny;
    const size_t n = static_cast<size_t>(nx_) * static_cast<size_t>(ny);
    rows_.assign(n, &kNoRows);
    if (scratch_.size() < n) scratch_.resize(n);
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx_; ++i) {
        const EvidentialGridMap::Tile* t = map_.tile(tx0_ + i, ty0_ + j);
        if (t == nullptr) continue;
        const size_t k = static_cast<size_t>(j) * nx_ + i;
        rows_[k] = &t->occupiedRows(threshold_, &scratch_[k]);
      }
    }
  }
  // Calls visit(x) for each x in [x0, x1] whose cell (x, y) is occupied, x ascending.
  template <typename Visit>
  void forEachOccupied(int y, int x0, int x1, Visit visit) const {
    const size_t row_base = static_cast<size_t>((y >> kBits) - ty0_) * nx_;
    const size_t in_tile = static_cast<size_t>(y & (kSize - 1));
    for (int tx = x0 >> kBits; tx <= x1 >> kBits; ++tx) {
      uint32_t bits = (*rows_[row_base + static_cast<size_t>(tx - tx0_)])[in_tile];
      if (bits == 0) continue;
      const int base = tx * kSize;  // tx < 0 west of the origin: a left shift would be UB
      const int lo = std::max(x0, base) - base, hi = std::min(x1, base + kSize - 1) - base;
      bits &= (0xFFFFFFFFu >> (kSize - 1 - hi)) & (0xFFFFFFFFu << lo);
      while (bits != 0) {
        visit(base + __builtin_ctz(bits));
        bits &= bits - 1;
      }
    }
  }

  static const Rows kNoRows;
  const EvidentialGridMap& map_;
  const float threshold_;
  const int radius_;
  const int reach_;  // cells around a hit whose tiles nearest() fetches
  const std::vector<int>& row_half_width_;
  int tx0_ = 0, ty0_ = 0, nx_ = 0, ny_ = 0;  // the box of tiles fetched (none yet)
  std::vector<const Rows*> rows_;
  std::vector<Rows> scratch_;
};
const CorrespondenceSearch::Rows CorrespondenceSearch::kNoRows{};

// The 3x3 cells score() looks at, the centre (the endpoint's own cell) first.
constexpr CellIndex kScoreNeighbours[9] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                           {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
}  // namespace

ScanMatcher::ScanMatcher(const ScanMatcherConfig& config, const SensorModelConfig& sensor,
                         double resolution)
    : config_(config), sensor_(sensor), resolution_(resolution) {
  search_cells_ = static_cast<int>(std::ceil(config_.search_radius / resolution_));
  for (int dy = 0; dy <= search_cells_; ++dy) {
    int w = 0;
    while ((w + 1) * (w + 1) + dy * dy <= search_cells_ * search_cells_) ++w;
    row_half_width_.push_back(w);
  }
  const double sigma_cells = config_.score_sigma / resolution_;
  kernel_scale_ = kKernelStepsPerCell2;
  kernel_.resize(static_cast<size_t>(std::ceil(8.0 * kernel_scale_)) + 2);  // up to (2 cells)² · 2
  for (size_t i = 0; i < kernel_.size(); ++i) {
    const double d2 = static_cast<double>(i) / kernel_scale_;
    kernel_[i] = static_cast<float>(std::exp(-0.5 * d2 / (sigma_cells * sigma_cells)));
  }
}

int ScanMatcher::matchStride(const LaserScan& scan) const {
  const size_t n = scan.bearings.size();
  if (n < 2) return 1;
  const double step = std::abs(scan.bearings.back() - scan.bearings.front()) / (n - 1);
  if (!(step > 0.0)) return 1;
  const double stride = std::min(config_.beam_spacing / step, static_cast<double>(n));
  return std::max(1, static_cast<int>(std::lround(stride)));
}

std::vector<MatchPoint> ScanMatcher::endpoints(const LaserScan& scan) const {
  std::vector<MatchPoint> pts;
  const double limit = std::min<double>(
      sensor_.usable_range, scan.max_range > 0.0f ? scan.max_range : sensor_.usable_range);
  const int stride = matchStride(scan);
  int k = 0;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const float z = scan.ranges[i];
    if (!scan.valid.empty() && scan.valid[i] == 0) continue;
    if (!std::isfinite(z) || z < sensor_.min_range || z >= limit) continue;
    if (k++ % stride != 0) continue;
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
    // Squared distances from the endpoint to the centres of the columns and rows ix - 1 .. ix + 1
    // and iy - 1 .. iy + 1.
    double dx2[3], dy2[3];
    for (int a = -1; a <= 1; ++a) {
      const double ddx = ix + a + 0.5 - fx, ddy = iy + a + 0.5 - fy;
      dx2[a + 1] = ddx * ddx;
      dy2[a + 1] = ddy * ddy;
    }
    float best = 0.0f;
    for (const CellIndex& o : kScoreNeighbours) {
      const size_t k = static_cast<size_t>((dx2[o.x + 1] + dy2[o.y + 1]) * kernel_scale_);
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

bool ScanMatcher::correspondence(const EvidentialGridMap& map, const CellIndex& hit,
                                 const CellIndex& free, CellIndex* offset) const {
  CorrespondenceSearch search(map, static_cast<float>(config_.occupied_threshold), search_cells_,
                              row_half_width_, /*with_normals=*/false);
  return search.nearest(hit, free, offset);
}

bool ScanMatcher::icpStep(const EvidentialGridMap& map, const std::vector<MatchPoint>& pts,
                          std::vector<Correspondence>* correspondences, Pose2* pose,
                          Eigen::Matrix2d* translation_information) const {
  const double c = std::cos(pose->theta), s = std::sin(pose->theta);
  const bool to_line = config_.point_to_line;
  // The information wants the targets' normals whichever residual ICP uses.
  const bool with_normals = to_line || translation_information != nullptr;
  CorrespondenceSearch targets(map, static_cast<float>(config_.occupied_threshold), search_cells_,
                               row_half_width_, with_normals);
  // Point to point: weighted sums for the closed-form 2-D rigid alignment of matched pairs
  // (q -> y). Point to line: the Gauss-Newton normal equations H δ = -g of the linearised
  // residuals n·(q - y) in δ = (tx, ty, dθ), rotating about the robot (point to point where the
  // target cells do not line up).
  double sw = 0, sqx = 0, sqy = 0, syx = 0, syy = 0;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  size_t matched = 0;
  std::vector<Eigen::Vector4d> pairs;  // point to point: q.x, q.y, y.x, y.y
  std::vector<double> weights;
  if (!to_line) {
    pairs.reserve(pts.size());
    weights.reserve(pts.size());
  }
  auto addResidual = [&](const Eigen::Vector3d& jacobian, double residual, double w) {
    h.noalias() += w * jacobian * jacobian.transpose();
    g.noalias() += (w * residual) * jacobian;
  };
  for (size_t i = 0; i < pts.size(); ++i) {
    const MatchPoint& p = pts[i];
    const double qx = pose->x + c * p.hit.x() - s * p.hit.y();
    const double qy = pose->y + s * p.hit.x() + c * p.hit.y();
    const CellIndex q = map.worldToCell(qx, qy);
    const CellIndex f = map.worldToCell(pose->x + c * p.free.x() - s * p.free.y(),
                                        pose->y + s * p.free.x() + c * p.free.y());
    Correspondence& known = (*correspondences)[i];
    if (!(known.hit == q) || !(known.free == f)) {
      known.hit = q;
      known.free = f;
      known.found = targets.nearest(q, f, &known.offset);
      known.has_normal =
          known.found && with_normals &&
          targets.normal(CellIndex{q.x + known.offset.x, q.y + known.offset.y}, &known.normal);
    }
    if (!known.found) continue;
    const CellIndex& o = known.offset;
    const double yx = (q.x + o.x + 0.5) * resolution_, yy = (q.y + o.y + 0.5) * resolution_;
    const double d2 = (yx - qx) * (yx - qx) + (yy - qy) * (yy - qy);
    const double w = 1.0 / (1.0 + d2 / (kRobustScale * kRobustScale));
    ++matched;
    if (translation_information != nullptr) {
      if (known.has_normal) {
        translation_information->noalias() += w * known.normal * known.normal.transpose();
      } else {
        translation_information->diagonal().array() += w;
      }
    }
    if (to_line) {
      // ∂q/∂dθ about the robot: the lever arm turned by 90°.
      const double ax = -(qy - pose->y), ay = qx - pose->x;
      if (known.has_normal) {
        const Eigen::Vector2d& n = known.normal;
        addResidual({n.x(), n.y(), n.x() * ax + n.y() * ay}, n.x() * (qx - yx) + n.y() * (qy - yy),
                    w);
      } else {
        addResidual({1.0, 0.0, ax}, qx - yx, w);
        addResidual({0.0, 1.0, ay}, qy - yy, w);
      }
      continue;
    }
    pairs.emplace_back(qx, qy, yx, yy);
    weights.push_back(w);
    sw += w;
    sqx += w * qx;
    sqy += w * qy;
    syx += w * yx;
    syy += w * yy;
  }
  if (matched < std::max<size_t>(3, static_cast<size_t>(config_.min_match_fraction * pts.size()))) {
    return false;
  }
  if (to_line) {
    // A direction no residual constrains (along a corridor) stays where the proposal put it.
    h.diagonal().array() += 1e-9 * (h.trace() + 1.0);
    const Eigen::Vector3d delta = -h.ldlt().solve(g);
    if (!delta.allFinite()) return false;
    *pose = Pose2(pose->x + delta.x(), pose->y + delta.y(), pose->theta + delta.z());
    return true;
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

double ScanMatcher::translationConstraint(const EvidentialGridMap& map, const Pose2& pose,
                                          const std::vector<MatchPoint>& pts) const {
  const ProfileTimer timer(ProfileSection::kConstraint);
  std::vector<Correspondence> correspondences(pts.size());
  Pose2 stepped = pose;
  Eigen::Matrix2d info = Eigen::Matrix2d::Zero();
  if (!icpStep(map, pts, &correspondences, &stepped, &info)) return 0.0;
  // Eigenvalues of the symmetric 2x2: half the trace ± the root.
  const double half_trace = 0.5 * info.trace();
  if (!(half_trace > 0.0)) return 0.0;
  const double half_diff = 0.5 * (info(0, 0) - info(1, 1));
  const double root = std::sqrt(half_diff * half_diff + info(0, 1) * info(0, 1));
  return (half_trace - root) / (half_trace + root);
}

Pose2 ScanMatcher::hillClimb(const EvidentialGridMap& map, const Pose2& start,
                             const std::vector<MatchPoint>& pts) const {
  const ProfileTimer timer(ProfileSection::kHillClimb);
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
  const ProfileTimer timer(ProfileSection::kIcp);
  std::vector<Correspondence> correspondences(pts.size());
  for (int it = 0; it < config_.icp_iterations; ++it) {
    const Pose2 before = *pose;
    if (!icpStep(map, pts, &correspondences, pose)) {
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

ScanMatcher::Match ScanMatcher::matchFrom(const EvidentialGridMap& map, const Pose2& start,
                                          const std::vector<MatchPoint>& pts) const {
  Match m;
  m.pose = start;
  // icp() leaves the pose at `start` when its first step fails.
  if (pts.empty() || !icp(map, pts, &m.pose)) return m;
  m.score = score(map, m.pose, pts);
  return m;
}

Pose2 ScanMatcher::search(const EvidentialGridMap& map, const Pose2& predicted,
                          const std::vector<MatchPoint>& pts, double heading_window,
                          double* best_score_out, const Match* unturned) const {
  *best_score_out = -1.0;
  if (pts.empty()) return predicted;
  const int n = static_cast<int>(std::floor(heading_window / config_.heading_step + 1e-9));
  Pose2 best = predicted;
  double best_score = -1.0;
  for (int i = 0; i <= 2 * n; ++i) {
    const int k = (i + 1) / 2 * (i % 2 == 1 ? 1 : -1);  // 0, +1, -1, +2, -2, ...
    const Match m =
        k == 0 && unturned != nullptr
            ? *unturned
            : matchFrom(map,
                        Pose2(predicted.x, predicted.y, predicted.theta + k * config_.heading_step),
                        pts);
    if (m.score > best_score) {  // a start without matches has score -1
      best_score = m.score;
      best = m.pose;
    }
  }
  *best_score_out = best_score;
  return best;
}

}  // namespace evidential_slam
