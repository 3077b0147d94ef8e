#include "evidential_slam/core/fusion/alignment_check.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace evidential_slam {
namespace fusion {
namespace {

// A map's observed box as rasters: m̃(o), and the free evidence away from walls, ẽ_R (separable
// running minimum over the (2r + 1)² square; unobserved cells do not count).
struct Raster {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<float> occupied, deep_free, near_structure;
  std::vector<uint8_t> observed;

  long find(const EvidentialGridMap& map, double x, double y) const {
    const CellIndex c = map.worldToCell(x, y);
    const int i = c.x - x0, j = c.y - y0;
    if (i < 0 || j < 0 || i >= w || j >= h) return -1;
    return static_cast<long>(j) * w + i;
  }
};

// Running minimum (or maximum) of `in` along rows (step 1, `count` rows of `length`) or columns,
// window ±r.
template <typename Pick>
void running(const std::vector<float>& in, std::vector<float>* out, int length, int count,
             int stride, int step, int r, float start, Pick pick) {
  for (int line = 0; line < count; ++line) {
    const size_t base = static_cast<size_t>(line) * stride;
    for (int i = 0; i < length; ++i) {
      float m = start;
      const int lo = std::max(0, i - r), hi = std::min(length - 1, i + r);
      for (int k = lo; k <= hi; ++k) m = pick(m, in[base + static_cast<size_t>(k) * step]);
      (*out)[base + static_cast<size_t>(i) * step] = m;
    }
  }
}

// The (2r + 1)² square's minimum (`start` 1) or maximum (`start` 0) of `in` at every cell.
template <typename Pick>
std::vector<float> squareFilter(const std::vector<float>& in, int w, int h, int r, float start,
                                Pick pick) {
  std::vector<float> rows(in.size()), out(in.size());
  running(in, &rows, w, h, w, 1, r, start, pick);
  running(rows, &out, h, w, 1, w, r, start, pick);
  return out;
}

Raster rasterOf(const EvidentialGridMap& map, int r) {
  Raster p;
  const CellBox box = map.observedBox();
  if (box.empty()) return p;
  p.x0 = box.min_x;
  p.y0 = box.min_y;
  p.w = box.width();
  p.h = box.height();
  const size_t n = static_cast<size_t>(p.w) * p.h;
  p.occupied.assign(n, 0.0f);
  p.observed.assign(n, 0);
  std::vector<float> free(n, 1.0f);  // unobserved: no wall known there
  for (int j = 0; j < p.h; ++j) {
    for (int i = 0; i < p.w; ++i) {
      const Cell& c = map.cell(p.x0 + i, p.y0 + j);
      if (!c.observed()) continue;
      const size_t k = static_cast<size_t>(j) * p.w + i;
      p.observed[k] = 1;
      p.occupied[k] = c.occupied();
      free[k] = c.free() * (1.0f - c.occupied());
    }
  }
  // Occupied evidence counts as structure as far as its 8 neighbours hold occupied evidence too
  // (a wall is a line of cells): a lone hit, noise or a passer-by, weighs nothing.
  std::vector<float> structure(n, 0.0f);
  for (int j = 0; j < p.h; ++j) {
    for (int i = 0; i < p.w; ++i) {
      const size_t k = static_cast<size_t>(j) * p.w + i;
      if (p.occupied[k] == 0.0f) continue;
      float around = 0.0f;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if ((di == 0 && dj == 0) || a < 0 || b < 0 || a >= p.w || b >= p.h) continue;
          around += p.occupied[static_cast<size_t>(b) * p.w + a];
        }
      }
      structure[k] = p.occupied[k] * std::min(1.0f, around);
    }
  }
  p.occupied.swap(structure);
  auto min = [](float a, float b) { return std::min(a, b); };
  auto max = [](float a, float b) { return std::max(a, b); };
  p.deep_free = squareFilter(free, p.w, p.h, r, 1.0f, min);
  p.near_structure = squareFilter(p.occupied, p.w, p.h, r, 0.0f, max);
  for (size_t k = 0; k < n; ++k) {
    if (p.observed[k] == 0) p.deep_free[k] = 0.0f;
  }
  return p;
}

}  // namespace

Disagreement disagreement(const EvidentialGridMap& reference, const EvidentialGridMap& moving,
                          const Pose2& pose, double tolerance) {
  Disagreement d;
  const int r = std::max(0, static_cast<int>(std::ceil(tolerance / reference.resolution() - 1e-9)));
  const Raster a = rasterOf(reference, r), b = rasterOf(moving, r);
  if (a.w == 0 || b.w == 0) return d;
  const double res = moving.resolution();
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  for (int j = 0; j < b.h; ++j) {
    const double y = (b.y0 + j + 0.5) * res;
    for (int i = 0; i < b.w; ++i) {
      const size_t m = static_cast<size_t>(j) * b.w + i;
      if (b.observed[m] == 0) continue;
      const double x = (b.x0 + i + 0.5) * res;
      const long k = a.find(reference, pose.x + c * x - s * y, pose.y + s * x + c * y);
      if (k < 0 || a.observed[static_cast<size_t>(k)] == 0) continue;
      const size_t n = static_cast<size_t>(k);
      d.contradicted += static_cast<double>(b.occupied[m]) * a.deep_free[n] +
                        static_cast<double>(a.occupied[n]) * b.deep_free[m];
      d.occupied += static_cast<double>(b.occupied[m]) + a.occupied[n];
      d.matched += static_cast<double>(b.occupied[m]) * a.near_structure[n] +
                   static_cast<double>(a.occupied[n]) * b.near_structure[m];
      ++d.overlap;
    }
  }
  return d;
}

}  // namespace fusion
}  // namespace evidential_slam
