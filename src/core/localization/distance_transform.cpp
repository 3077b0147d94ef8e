#include "evidential_slam/core/localization/distance_transform.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace evidential_slam {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// d[i] = min_j (f[j] + (i - j)^2) over the n samples of f (f[j] = inf where there is no seed):
// the lower envelope of the parabolas rooted at the finite samples. v holds the parabolas'
// roots, z the boundaries between them.
void transform1d(const double* f, int n, double* d, std::vector<int>* v_buf,
                 std::vector<double>* z_buf) {
  std::vector<int>& v = *v_buf;
  std::vector<double>& z = *z_buf;
  v.resize(static_cast<size_t>(n));
  z.resize(static_cast<size_t>(n) + 1);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    while (k >= 0) {
      const int p = v[static_cast<size_t>(k)];
      const double s = ((f[q] + static_cast<double>(q) * q) - (f[p] + static_cast<double>(p) * p)) /
                       (2.0 * (q - p));
      if (s > z[static_cast<size_t>(k)]) {
        ++k;
        v[static_cast<size_t>(k)] = q;
        z[static_cast<size_t>(k)] = s;
        z[static_cast<size_t>(k) + 1] = kInf;
        break;
      }
      --k;
    }
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
    }
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) d[q] = kInf;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[static_cast<size_t>(j) + 1] < q) ++j;
    const double dq = q - v[static_cast<size_t>(j)];
    d[q] = dq * dq + f[v[static_cast<size_t>(j)]];
  }
}

}  // namespace

std::vector<float> squaredDistanceTransform(const std::vector<uint8_t>& seeds, int width,
                                            int height) {
  if (width < 0 || height < 0 ||
      seeds.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    throw std::invalid_argument("squaredDistanceTransform: the seeds are not width x height");
  }
  const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
  std::vector<double> grid(w * h);
  for (size_t i = 0; i < grid.size(); ++i) grid[i] = seeds[i] != 0 ? 0.0 : kInf;
  std::vector<int> v;
  std::vector<double> z;
  std::vector<double> f(std::max(w, h)), d(std::max(w, h));
  // Rows first, then columns of the row result.
  for (size_t y = 0; y < h; ++y) {
    transform1d(&grid[y * w], width, d.data(), &v, &z);
    for (size_t x = 0; x < w; ++x) grid[y * w + x] = d[x];
  }
  for (size_t x = 0; x < w; ++x) {
    for (size_t y = 0; y < h; ++y) f[y] = grid[y * w + x];
    transform1d(f.data(), height, d.data(), &v, &z);
    for (size_t y = 0; y < h; ++y) grid[y * w + x] = d[y];
  }
  std::vector<float> out(w * h);
  for (size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(grid[i]);
  return out;
}

void saturatedDistanceTransform(std::vector<uint8_t>* grid, int width, int height,
                                std::vector<float>* scratch) {
  if (width < 0 || height < 0 ||
      grid->size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    throw std::invalid_argument("saturatedDistanceTransform: the grid is not width x height");
  }
  // Squared distances are capped at kCap > 255^2: a cap on the row pass leaves every column
  // result below it exact (each term f + dy^2 of the minimum is at least min(its true value, the
  // cap)), and every one at or above it still saturates. Every value then is an integer below
  // 2^24, exact in a float.
  constexpr float kCap = 65536.0f;
  const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
  scratch->resize(w * h);
  // Rows: the squared distance to the nearest seed of the row, from a sweep each way.
  for (size_t y = 0; y < h; ++y) {
    const uint8_t* seeds = grid->data() + y * w;
    float* row = scratch->data() + y * w;
    long last = -1;
    for (size_t x = 0; x < w; ++x) {
      if (seeds[x] != 0) last = static_cast<long>(x);
      const double dx = last < 0 ? kInf : static_cast<double>(static_cast<long>(x) - last);
      row[x] = static_cast<float>(std::min<double>(kCap, dx * dx));
    }
    last = -1;
    for (size_t x = w; x-- > 0;) {
      if (seeds[x] != 0) last = static_cast<long>(x);
      if (last < 0) continue;
      const double dx = static_cast<double>(last - static_cast<long>(x));
      row[x] = std::min(row[x], static_cast<float>(std::min<double>(kCap, dx * dx)));
    }
  }
  // Columns: the lower envelope of the rows' parabolas, then the saturated whole distance.
  std::vector<int> v;
  std::vector<double> z;
  std::vector<double> f(h), d(h);
  for (size_t x = 0; x < w; ++x) {
    for (size_t y = 0; y < h; ++y) f[y] = (*scratch)[y * w + x];
    transform1d(f.data(), height, d.data(), &v, &z);
    for (size_t y = 0; y < h; ++y) {
      (*grid)[y * w + x] = static_cast<uint8_t>(std::min(255.0, std::floor(std::sqrt(d[y]))));
    }
  }
}

}  // namespace evidential_slam
