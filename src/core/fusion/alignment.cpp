#include "evidential_slam/core/fusion/alignment.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

#include <unsupported/Eigen/FFT>

#include "evidential_slam/core/fusion/alignment_check.h"
#include "evidential_slam/core/scan_matcher.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// ICP endpoints at most (every k-th occupied face cell of the moving map beyond).
constexpr size_t kMaxEndpoints = 20000;
// Refinement window at each finer level: ±2 of its cells (one cell of the level above, plus the
// pooled grids' tolerance of one cell) and the yaw ± its step.
constexpr int kRefineCells = 2;
// Candidates carried past the first refinement level: the best and the alternatives the ambiguity
// check and the verifier compare it with (a twin and the truth, shifts by a room period).
constexpr size_t kFineCandidates = 8;  // 3 crowded the truth out (docs/fusion.md §9)

using Complex = std::complex<double>;

// A map pooled into cells of 2^level map cells, from sums over the observed cells pooled:
// occupied = min(1, Σ m̃(o) / 2^level), the occupied evidence of a wall crossing the pooled cell
// (one spurious hit among its 4^level cells barely counts); free = mean m̃(e) · (1 - occupied), and
// `free_eroded` the smallest free over the observed pooled cells in the 3 x 3 around (free only
// away from every wall, so that a pose within a pooled cell of the truth does not put walls on free
// space). Row-major over the pooled observed box.
struct Pooled {
  int level = 0;
  double cell = 0.0;  // m
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<float> occ_sum, fre_sum;  // Σ m̃(o), Σ m̃(e)
  std::vector<uint32_t> count;          // observed cells pooled
  std::vector<float> occ, fre, fre_eroded;
  std::vector<uint8_t> obs;
  size_t observed = 0;
  double occupied_sum = 0.0;

  size_t index(int i, int j) const { return static_cast<size_t>(j) * w + i; }
  // Index of the pooled cell holding map-frame point (x, y), or -1 outside the box.
  long find(double x, double y) const {
    const int i = static_cast<int>(std::floor(x / cell)) - x0;
    const int j = static_cast<int>(std::floor(y / cell)) - y0;
    if (i < 0 || j < 0 || i >= w || j >= h) return -1;
    return static_cast<long>(index(i, j));
  }
  void add(size_t k, float occupied, float free, uint32_t cells) {
    occ_sum[k] += occupied;
    fre_sum[k] += free;
    count[k] += cells;
  }
};

void allocate(Pooled* p) {
  const size_t n = static_cast<size_t>(p->w) * p->h;
  p->occ_sum.assign(n, 0.0f);
  p->fre_sum.assign(n, 0.0f);
  p->count.assign(n, 0);
}

// free_eroded from free, observed and occupied_sum from the pooled values.
void erode(Pooled* p) {
  p->observed = 0;
  p->occupied_sum = 0.0;
  p->fre_eroded = p->fre;
  for (int j = 0; j < p->h; ++j) {
    for (int i = 0; i < p->w; ++i) {
      const size_t k = p->index(i, j);
      if (p->obs[k] == 0) continue;
      ++p->observed;
      p->occupied_sum += p->occ[k];
      float e = p->fre[k];
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if (a < 0 || b < 0 || a >= p->w || b >= p->h) continue;
          const size_t m = p->index(a, b);
          if (p->obs[m] != 0) e = std::min(e, p->fre[m]);
        }
      }
      p->fre_eroded[k] = e;
    }
  }
}

// The pooled values from the sums.
void finish(Pooled* p) {
  const size_t n = p->count.size();
  const float wall = static_cast<float>(1 << p->level);
  p->occ.assign(n, 0.0f);
  p->fre.assign(n, 0.0f);
  p->obs.assign(n, 0);
  for (size_t k = 0; k < n; ++k) {
    if (p->count[k] == 0) continue;
    p->obs[k] = 1;
    p->occ[k] = std::min(1.0f, p->occ_sum[k] / wall);
    p->fre[k] = p->fre_sum[k] / static_cast<float>(p->count[k]) * (1.0f - p->occ[k]);
  }
  erode(p);
}

// Level 0, the map's own cells, without the sums (nothing is pooled from it): m̃(o), m̃(e) (1 - m̃(o))
// as finish() gives them, and only what tallyPooled reads is kept.
Pooled cellRaster(const EvidentialGridMap& map, bool eroded = true) {
  Pooled p;
  p.cell = map.resolution();
  const CellBox box = map.observedBox();
  if (box.empty()) return p;
  p.x0 = box.min_x;
  p.y0 = box.min_y;
  p.w = box.width();
  p.h = box.height();
  const size_t n = static_cast<size_t>(p.w) * p.h;
  p.occ.assign(n, 0.0f);
  p.fre.assign(n, 0.0f);
  p.obs.assign(n, 0);
  for (int j = 0; j < p.h; ++j) {
    for (int i = 0; i < p.w; ++i) {
      const Cell& c = map.cell(p.x0 + i, p.y0 + j);
      if (!c.observed()) continue;
      const size_t k = p.index(i, j);
      p.obs[k] = 1;
      p.occ[k] = c.occupied();
      p.fre[k] = c.free() * (1.0f - c.occupied());
    }
  }
  if (eroded) {
    erode(&p);
    std::vector<float>().swap(p.fre);
  } else {
    p.fre_eroded.swap(p.fre);
  }
  return p;
}

Pooled poolMap(const EvidentialGridMap& map, int level) {
  Pooled p;
  p.level = level;
  p.cell = map.resolution() * (1 << level);
  const CellBox box = map.observedBox();
  if (box.empty()) return p;
  p.x0 = box.min_x >> level;
  p.y0 = box.min_y >> level;
  p.w = (box.max_x >> level) - p.x0 + 1;
  p.h = (box.max_y >> level) - p.y0 + 1;
  allocate(&p);
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& c = map.cell(x, y);
      if (!c.observed()) continue;
      p.add(p.index((x >> level) - p.x0, (y >> level) - p.y0), c.occupied(), c.free(), 1);
    }
  }
  finish(&p);
  return p;
}

// The next coarser level: 2 x 2 cells of `fine` per cell.
Pooled poolUp(const Pooled& fine) {
  Pooled p;
  p.level = fine.level + 1;
  p.cell = 2.0 * fine.cell;
  if (fine.w == 0) return p;
  p.x0 = fine.x0 >> 1;
  p.y0 = fine.y0 >> 1;
  p.w = ((fine.x0 + fine.w - 1) >> 1) - p.x0 + 1;
  p.h = ((fine.y0 + fine.h - 1) >> 1) - p.y0 + 1;
  allocate(&p);
  for (int j = 0; j < fine.h; ++j) {
    for (int i = 0; i < fine.w; ++i) {
      const size_t f = fine.index(i, j);
      if (fine.count[f] == 0) continue;
      p.add(p.index(((fine.x0 + i) >> 1) - p.x0, ((fine.y0 + j) >> 1) - p.y0), fine.occ_sum[f],
            fine.fre_sum[f], fine.count[f]);
    }
  }
  finish(&p);
  return p;
}

// An observed pooled cell of the moving map: its centre in that map's frame and its sums (the
// exhaustive search pools them again into the rotated grid).
struct Point {
  double x, y;
  float occ_sum, fre_sum;
  uint32_t count;
};

std::vector<Point> pointsOf(const Pooled& p) {
  std::vector<Point> pts;
  pts.reserve(p.observed);
  for (int j = 0; j < p.h; ++j) {
    for (int i = 0; i < p.w; ++i) {
      const size_t k = p.index(i, j);
      if (p.obs[k] == 0) continue;
      pts.push_back(Point{(p.x0 + i + 0.5) * p.cell, (p.y0 + j + 0.5) * p.cell, p.occ_sum[k],
                          p.fre_sum[k], p.count[k]});
    }
  }
  return pts;
}

// Conflict, occupied evidence and cells of the overlap at one pose.
struct Tally {
  double conflict = 0.0;
  double structure = 0.0;
  size_t overlap = 0;
  // The structure conflict Σ K / Σ m̃(o).
  double rate() const { return structure > 0.0 ? conflict / structure : kInf; }
  // What ranks poses: the structure conflict as if `prior` more occupied evidence had been in the
  // overlap at conflict 1/2, so that an overlap that barely meets the requirement (a corner of
  // one map on a corner of the other, little evidence, little conflict) cannot win on a handful of
  // cells. `prior` is the required occupied evidence.
  double score(double prior) const {
    return structure + prior > 0.0 ? (conflict + 0.5 * prior) / (structure + prior) : kInf;
  }
};

// Every observed cell of `moving`, at its centre, reads the `ref` cell under it (on level 0, the
// maps' own cells: fuseMaps's sampling, from the other side).
Tally tallyPooled(const Pooled& ref, const Pooled& moving, const Pose2& pose) {
  Tally t;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  for (int j = 0; j < moving.h; ++j) {
    const double y = (moving.y0 + j + 0.5) * moving.cell;
    for (int i = 0; i < moving.w; ++i) {
      const size_t m = moving.index(i, j);
      if (moving.obs[m] == 0) continue;
      const double x = (moving.x0 + i + 0.5) * moving.cell;
      const long k = ref.find(pose.x + c * x - s * y, pose.y + s * x + c * y);
      if (k < 0 || ref.obs[static_cast<size_t>(k)] == 0) continue;
      const size_t r = static_cast<size_t>(k);
      t.conflict += moving.occ[m] * ref.fre_eroded[r] + moving.fre_eroded[m] * ref.occ[r];
      t.structure += moving.occ[m] + ref.occ[r];
      ++t.overlap;
    }
  }
  return t;
}

// The mean over the overlap of the conflict K fusing the maps' own cells creates (no tolerance).
double meanConflict(const EvidentialGridMap& ref, const EvidentialGridMap& moving,
                    const Pose2& pose) {
  double sum = 0.0;
  size_t overlap = 0;
  const double res = moving.resolution();
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const CellBox box = moving.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& b = moving.cell(x, y);
      if (!b.observed()) continue;
      const double px = (x + 0.5) * res, py = (y + 0.5) * res;
      const Cell& a = ref.cell(ref.worldToCell(pose.x + c * px - s * py, pose.y + s * px + c * py));
      if (!a.observed()) continue;
      sum += static_cast<double>(b.occupied()) * a.free() +
             static_cast<double>(b.free()) * a.occupied();
      ++overlap;
    }
  }
  return overlap > 0 ? sum / overlap : 0.0;
}

// Smallest n >= m whose only prime factors are 2, 3 and 5 (sizes the FFT handles fast).
int fftSize(int m) {
  for (int n = std::max(m, 1);; ++n) {
    int k = n;
    for (const int f : {2, 3, 5}) {
      while (k % f == 0) k /= f;
    }
    if (k == 1) return n;
  }
}

// 2-D DFT of an nx x ny row-major array, rows then columns (Eigen's FFT is one-dimensional).
class Fft2 {
 public:
  Fft2(int nx, int ny) : nx_(nx), ny_(ny), row_(nx), col_(ny), out_(std::max(nx, ny)) {}
  void forward(std::vector<Complex>* data) { run(data, false); }
  // Scaled by 1/(nx ny): inverse(forward(x)) = x.
  void inverse(std::vector<Complex>* data) { run(data, true); }

 private:
  void run(std::vector<Complex>* data, bool inv) {
    Complex* d = data->data();
    for (int j = 0; j < ny_; ++j) {
      Complex* row = d + static_cast<size_t>(j) * nx_;
      std::copy(row, row + nx_, row_.begin());
      if (inv) {
        fft_.inv(out_.data(), row_.data(), nx_);
      } else {
        fft_.fwd(out_.data(), row_.data(), nx_);
      }
      std::copy(out_.begin(), out_.begin() + nx_, row);
    }
    for (int i = 0; i < nx_; ++i) {
      for (int j = 0; j < ny_; ++j) {
        col_[static_cast<size_t>(j)] = d[static_cast<size_t>(j) * nx_ + i];
      }
      if (inv) {
        fft_.inv(out_.data(), col_.data(), ny_);
      } else {
        fft_.fwd(out_.data(), col_.data(), ny_);
      }
      for (int j = 0; j < ny_; ++j) {
        d[static_cast<size_t>(j) * nx_ + i] = out_[static_cast<size_t>(j)];
      }
    }
  }

  int nx_, ny_;
  Eigen::FFT<double> fft_;
  std::vector<Complex> row_, col_, out_;
};

// The spectra of two real arrays transformed together as x + i y.
void splitSpectra(const std::vector<Complex>& z, int nx, int ny, std::vector<Complex>* x,
                  std::vector<Complex>* y) {
  x->resize(z.size());
  y->resize(z.size());
  for (int j = 0; j < ny; ++j) {
    const int jm = (ny - j) % ny;
    for (int i = 0; i < nx; ++i) {
      const int im = (nx - i) % nx;
      const Complex a = z[static_cast<size_t>(j) * nx + i];
      const Complex b = std::conj(z[static_cast<size_t>(jm) * nx + im]);
      (*x)[static_cast<size_t>(j) * nx + i] = 0.5 * (a + b);
      (*y)[static_cast<size_t>(j) * nx + i] = Complex(0.0, -0.5) * (a - b);
    }
  }
}

struct Candidate {
  Pose2 pose;
  double score = kInf;     // Tally::score
  double conflict = kInf;  // Tally::rate
  size_t overlap = 0;
};

// Farther than distinct_distance (plus `margin`) or turned more than distinct_angle.
bool distinct(const Pose2& a, const Pose2& b, const AlignmentConfig& config, double margin = 0.0) {
  return std::hypot(a.x - b.x, a.y - b.y) > config.distinct_distance + margin ||
         std::abs(normalizeAngle(a.theta - b.theta)) > config.distinct_angle;
}

// Keeps the best `count` candidates that are distinct from each other, positions `margin` more
// apart than distinct_distance.
std::vector<Candidate> bestDistinct(std::vector<Candidate> all, size_t count,
                                    const AlignmentConfig& config, double margin = 0.0) {
  std::sort(all.begin(), all.end(),
            [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
  std::vector<Candidate> kept;
  for (const Candidate& c : all) {
    if (kept.size() >= count) break;
    bool far = true;
    for (const Candidate& k : kept) far = far && distinct(c.pose, k.pose, config, margin);
    if (far) kept.push_back(c);
  }
  return kept;
}

// What an overlap needs at a pooled level: cells and occupied evidence.
struct Requirement {
  double cells = 0.0;
  double structure = 0.0;
  bool met(const Tally& t) const { return t.overlap >= cells && t.structure >= structure; }
};

Requirement requirement(const Pooled& a, const Pooled& b, double share) {
  return {share * static_cast<double>(std::min(a.observed, b.observed)),
          share * std::min(a.occupied_sum, b.occupied_sum)};
}

// The exhaustive search on one pooled level: every `yaw_step`, every translation by whole pooled
// cells, through FFT cross-correlations of the rotated moving grid with the reference grid.
std::vector<Candidate> exhaustiveSearch(const Pooled& ref, const Pooled& moving_fine,
                                        const Pooled& moving, double yaw_step, int nx, int ny,
                                        const Requirement& need, size_t keep_per_yaw,
                                        size_t* yaws) {
  const double s = ref.cell;
  const size_t n = static_cast<size_t>(nx) * ny;
  Fft2 fft(nx, ny);
  // The reference's spectra, once: m̃(o), eroded m̃(e), observed.
  std::vector<Complex> z(n, 0.0), ref_occ, ref_fre, ref_obs(n, 0.0);
  for (int j = 0; j < ref.h; ++j) {
    for (int i = 0; i < ref.w; ++i) {
      const size_t k = ref.index(i, j), d = static_cast<size_t>(j) * nx + i;
      z[d] = Complex(ref.occ[k], ref.fre_eroded[k]);
      ref_obs[d] = ref.obs[k];
    }
  }
  fft.forward(&z);
  splitSpectra(z, nx, ny, &ref_occ, &ref_fre);
  fft.forward(&ref_obs);

  const std::vector<Point> pts = pointsOf(moving_fine);
  const double half_diag = 0.5 * std::hypot(moving.w * s, moving.h * s);
  const double cx = (moving.x0 + 0.5 * moving.w) * s, cy = (moving.y0 + 0.5 * moving.h) * s;
  const int steps = std::max(1, static_cast<int>(std::ceil(2.0 * kPi / yaw_step - 1e-9)));
  *yaws = static_cast<size_t>(steps);
  std::vector<Candidate> found;
  Pooled rotated;
  rotated.level = moving.level;
  rotated.cell = s;
  std::vector<Complex> mov_occ, mov_fre, mov_obs(n), corr_cs(n), corr_o(n);
  std::vector<double> score;
  std::vector<uint8_t> ok;
  for (int step = 0; step < steps; ++step) {
    const double theta = normalizeAngle(step * 2.0 * kPi / steps);
    const double c = std::cos(theta), sn = std::sin(theta);
    // The rotated moving grid: its box from the rotated centre and half diagonal.
    const double rx = c * cx - sn * cy, ry = sn * cx + c * cy;
    rotated.x0 = static_cast<int>(std::floor((rx - half_diag) / s)) - 1;
    rotated.y0 = static_cast<int>(std::floor((ry - half_diag) / s)) - 1;
    rotated.w = static_cast<int>(std::ceil((rx + half_diag) / s)) + 1 - rotated.x0 + 1;
    rotated.h = static_cast<int>(std::ceil((ry + half_diag) / s)) + 1 - rotated.y0 + 1;
    allocate(&rotated);
    for (const Point& p : pts) {
      const long k = rotated.find(c * p.x - sn * p.y, sn * p.x + c * p.y);
      if (k < 0) continue;
      rotated.add(static_cast<size_t>(k), p.occ_sum, p.fre_sum, p.count);
    }
    finish(&rotated);
    std::fill(z.begin(), z.end(), Complex(0.0, 0.0));
    std::fill(mov_obs.begin(), mov_obs.end(), Complex(0.0, 0.0));
    for (int j = 0; j < rotated.h; ++j) {
      for (int i = 0; i < rotated.w; ++i) {
        const size_t k = rotated.index(i, j), d = static_cast<size_t>(j) * nx + i;
        if (rotated.obs[k] == 0) continue;
        z[d] = Complex(rotated.occ[k], rotated.fre_eroded[k]);
        mov_obs[d] = 1.0;
      }
    }
    fft.forward(&z);
    splitSpectra(z, nx, ny, &mov_occ, &mov_fre);
    fft.forward(&mov_obs);
    // corr(t) = Σ_x f(x) g(x + t) ↔ conj(F) G. Conflict and structure as one complex inverse.
    for (size_t k = 0; k < n; ++k) {
      const Complex conflict =
          std::conj(mov_occ[k]) * ref_fre[k] + std::conj(mov_fre[k]) * ref_occ[k];
      const Complex structure =
          std::conj(mov_occ[k]) * ref_obs[k] + std::conj(mov_obs[k]) * ref_occ[k];
      corr_cs[k] = conflict + Complex(0.0, 1.0) * structure;
      corr_o[k] = std::conj(mov_obs[k]) * ref_obs[k];
    }
    fft.inverse(&corr_cs);
    fft.inverse(&corr_o);
    // Translations t (cells) with any overlap: moving cell i lands on reference cell i + t.
    const int tx0 = -(rotated.w - 1), ty0 = -(rotated.h - 1);
    const int tw = ref.w + rotated.w - 1, th = ref.h + rotated.h - 1;
    score.assign(static_cast<size_t>(tw) * th, kInf);
    ok.assign(score.size(), 0);
    for (int j = 0; j < th; ++j) {
      for (int i = 0; i < tw; ++i) {
        const int tx = tx0 + i, ty = ty0 + j;
        const size_t d =
            static_cast<size_t>((ty + ny) % ny) * nx + static_cast<size_t>((tx + nx) % nx);
        Tally t;
        t.conflict = std::max(0.0, corr_cs[d].real());
        t.structure = std::max(0.0, corr_cs[d].imag());
        t.overlap = static_cast<size_t>(std::max(0.0, std::round(corr_o[d].real())));
        if (!need.met(t)) continue;
        score[static_cast<size_t>(j) * tw + i] = t.score(need.structure);
        ok[static_cast<size_t>(j) * tw + i] = 1;
      }
    }
    // Local minima over the 3 x 3 translations, the best keep_per_yaw of them.
    std::vector<Candidate> minima;
    for (int j = 0; j < th; ++j) {
      for (int i = 0; i < tw; ++i) {
        const size_t k = static_cast<size_t>(j) * tw + i;
        if (ok[k] == 0) continue;
        bool minimum = true;
        for (int dj = -1; dj <= 1 && minimum; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            const int a = i + di, b = j + dj;
            if ((di == 0 && dj == 0) || a < 0 || b < 0 || a >= tw || b >= th) continue;
            if (score[static_cast<size_t>(b) * tw + a] < score[k]) {
              minimum = false;
              break;
            }
          }
        }
        if (!minimum) continue;
        Candidate cand;
        cand.pose =
            Pose2((ref.x0 + tx0 + i - rotated.x0) * s, (ref.y0 + ty0 + j - rotated.y0) * s, theta);
        cand.score = score[k];
        minima.push_back(cand);
      }
    }
    const size_t m = std::min(keep_per_yaw, minima.size());
    std::partial_sort(minima.begin(), minima.begin() + m, minima.end(),
                      [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
    found.insert(found.end(), minima.begin(), minima.begin() + m);
  }
  return found;
}

// Coarse to fine: at each finer level, the best of ±kRefineCells cells and the yaw ± yaw_step.
Candidate refineOnLevel(const Pooled& ref, const Pooled& moving, const Candidate& start,
                        double yaw_step, const Requirement& need) {
  Candidate best;
  best.pose = start.pose;
  for (int dt = -1; dt <= 1; ++dt) {
    for (int dy = -kRefineCells; dy <= kRefineCells; ++dy) {
      for (int dx = -kRefineCells; dx <= kRefineCells; ++dx) {
        const Pose2 pose(start.pose.x + dx * ref.cell, start.pose.y + dy * ref.cell,
                         start.pose.theta + dt * yaw_step);
        const Tally t = tallyPooled(ref, moving, pose);
        if (!need.met(t) || t.score(need.structure) >= best.score) continue;
        best.pose = pose;
        best.score = t.score(need.structure);
        best.conflict = t.rate();
        best.overlap = t.overlap;
      }
    }
  }
  return best;
}

// Sub-cell refinement: the pose near `start` where fusing the maps' own cells creates the least
// conflict per occupied evidence, with no tolerance (the score's erosion makes it flat within a
// cell, and the pooled refinement stops at refine_resolution). A hill climb over x, y and the yaw
// about the moving map's centre `pivot` (its frame), steps halved from one cell down to an eighth
// (yaw: the arc of that step at `radius`), at most four moves per step size (the start is within
// a pooled cell of the minimum). Overlap changes little within these steps, so the rate is not
// lowered by losing overlap.
Pose2 refineSubCell(const Pooled& ref_raw, const Pooled& mov_raw, const Pose2& start,
                    const Eigen::Vector2d& pivot, double radius) {
  auto rate = [&](const Pose2& p) { return tallyPooled(ref_raw, mov_raw, p).rate(); };
  auto turned = [&](const Pose2& p, double d) {
    const Eigen::Vector2d c = p.transformPoint(pivot);
    const double cs = std::cos(d), sn = std::sin(d);
    const double x = p.x - c.x(), y = p.y - c.y();
    return Pose2(c.x() + cs * x - sn * y, c.y() + sn * x + cs * y, normalizeAngle(p.theta + d));
  };
  Pose2 best = start;
  double best_rate = rate(best);
  if (!std::isfinite(best_rate)) return start;
  double step = ref_raw.cell;
  for (int halvings = 0; halvings < 4; ++halvings, step *= 0.5) {
    const double yaw = step / std::max(radius, step);
    for (int moves = 0; moves < 4; ++moves) {
      const Pose2 next[6] = {Pose2(best.x + step, best.y, best.theta),
                             Pose2(best.x - step, best.y, best.theta),
                             Pose2(best.x, best.y + step, best.theta),
                             Pose2(best.x, best.y - step, best.theta),
                             turned(best, yaw),
                             turned(best, -yaw)};
      int chosen = -1;
      for (int i = 0; i < 6; ++i) {
        const double r = rate(next[i]);
        if (r < best_rate) {
          best_rate = r;
          chosen = i;
        }
      }
      if (chosen < 0) break;
      best = next[chosen];
    }
  }
  return best;
}

// The moving map's occupied cells that face free space, as scan-matcher endpoints in its frame:
// `hit` the occupied cell's centre, `free` the centre of the nearest cell within two cells at
// least as free as the matcher's threshold (the matcher then matches the wall's same face).
std::vector<MatchPoint> faceEndpoints(const EvidentialGridMap& map, float threshold) {
  std::vector<MatchPoint> pts;
  const double res = map.resolution();
  const CellBox box = map.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      if (map.cell(x, y).occupied() < threshold) continue;
      int best_d2 = std::numeric_limits<int>::max(), fx = 0, fy = 0;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const int d2 = dx * dx + dy * dy;
          if (d2 == 0 || d2 >= best_d2 || map.cell(x + dx, y + dy).free() < threshold) continue;
          best_d2 = d2;
          fx = dx;
          fy = dy;
        }
      }
      if (best_d2 == std::numeric_limits<int>::max()) continue;
      pts.push_back(MatchPoint{Eigen::Vector2d((x + 0.5) * res, (y + 0.5) * res),
                               Eigen::Vector2d((x + fx + 0.5) * res, (y + fy + 0.5) * res)});
    }
  }
  if (pts.size() > kMaxEndpoints) {
    const size_t stride = (pts.size() + kMaxEndpoints - 1) / kMaxEndpoints;
    std::vector<MatchPoint> kept;
    for (size_t i = 0; i < pts.size(); i += stride) kept.push_back(pts[i]);
    pts.swap(kept);
  }
  return pts;
}

// The endpoints that land on observed reference cells at `pose`.
std::vector<MatchPoint> inOverlap(const std::vector<MatchPoint>& pts, const EvidentialGridMap& ref,
                                  const Pose2& pose) {
  std::vector<MatchPoint> kept;
  for (const MatchPoint& p : pts) {
    const Eigen::Vector2d q = pose.transformPoint(p.hit);
    if (ref.cell(ref.worldToCell(q.x(), q.y())).observed()) kept.push_back(p);
  }
  return kept;
}

std::string describe(const Pose2& p) {
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << "(" << p.x << ", " << p.y << ", " << p.theta * 180.0 / kPi << "°)";
  return s.str();
}

std::string number(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

}  // namespace

bool AlignmentConfig::isValid(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!(search_resolution > 0.0)) return fail("search_resolution must be > 0");
  if (max_search_cells < 16) return fail("max_search_cells must be at least 16");
  if (!(yaw_step >= 0.0 && yaw_step <= kPi)) return fail("yaw_step must be in [0, pi]");
  if (candidates < 1) return fail("candidates must be at least 1");
  if (!(refine_resolution > 0.0)) return fail("refine_resolution must be > 0");
  if (!(min_overlap > 0.0 && min_overlap <= 1.0)) return fail("min_overlap must be in (0, 1]");
  if (!(max_conflict > 0.0 && max_conflict <= 1.0)) return fail("max_conflict must be in (0, 1]");
  if (!(ambiguity_ratio > 0.0 && ambiguity_ratio <= 1.0)) {
    return fail("ambiguity_ratio must be in (0, 1]");
  }
  if (!(distinct_distance > 0.0)) return fail("distinct_distance must be > 0");
  if (!(distinct_angle > 0.0)) return fail("distinct_angle must be > 0");
  if (!(verify_tolerance >= 0.0)) return fail("verify_tolerance must be >= 0");
  if (!(verify_ratio > 0.0 && verify_ratio <= 1.0)) return fail("verify_ratio must be in (0, 1]");
  if (!(verify_min_length >= 0.0)) return fail("verify_min_length must be >= 0");
  if (!(verify_score_margin >= 0.0)) return fail("verify_score_margin must be >= 0");
  if (has_prior && !(std::isfinite(prior.x) && std::isfinite(prior.y) &&
                     std::isfinite(prior.theta) && prior_sigma > 0.0 && prior_sigma_yaw > 0.0)) {
    return fail("the initial guess must be finite with sigmas > 0");
  }
  std::string reason;
  if (icp && !matcher.isValid(&reason)) return fail("matcher: " + reason);
  return true;
}

bool alignMaps(const EvidentialGridMap& reference, const EvidentialGridMap& moving,
               const AlignmentConfig& config, AlignmentResult* result, std::string* why) {
  auto fail = [&](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  std::string reason;
  if (!config.isValid(&reason)) return fail("invalid alignment config: " + reason);
  const double res = reference.resolution();
  if (std::abs(moving.resolution() - res) > 1e-9 * res) {
    return fail("the maps' cells differ (" + number(res) + " m and " + number(moving.resolution()) +
                " m): alignment needs one resolution");
  }
  if (reference.observedBox().empty() || moving.observedBox().empty()) {
    return fail("a map to align has no observed cell");
  }
  AlignmentResult out;
  auto nearPrior = [&](const Pose2& p) {
    return !config.has_prior ||
           (std::hypot(p.x - config.prior.x, p.y - config.prior.y) <= 3.0 * config.prior_sigma &&
            std::abs(normalizeAngle(p.theta - config.prior.theta)) <= 3.0 * config.prior_sigma_yaw);
  };

  // Levels: the refinement's finest, pooled from the cells, then up to the search level, which
  // grows until the FFT grid fits max_search_cells.
  auto levelFor = [&](double size) {
    int l = 0;
    while (res * (1 << l) < size * (1.0 - 1e-9) && l < 20) ++l;
    return l;
  };
  const int fine_level = levelFor(config.refine_resolution);
  int search_level = std::max(fine_level, levelFor(config.search_resolution));
  std::vector<Pooled> ref_levels, mov_levels;
  ref_levels.reserve(32);  // level() hands out references: no reallocation
  mov_levels.reserve(32);
  ref_levels.push_back(poolMap(reference, fine_level));
  mov_levels.push_back(poolMap(moving, fine_level));
  auto level = [&](std::vector<Pooled>* levels, int l) -> const Pooled& {
    while (levels->back().level < l) levels->push_back(poolUp(levels->back()));
    return (*levels)[static_cast<size_t>(l - fine_level)];
  };
  int nx = 0, ny = 0;
  for (;; ++search_level) {
    const Pooled& a = level(&ref_levels, search_level);
    const Pooled& b = level(&mov_levels, search_level);
    const int diag = static_cast<int>(std::ceil(std::hypot(b.w, b.h))) + 6;  // rotated grid
    nx = fftSize(a.w + diag);
    ny = fftSize(a.h + diag);
    if (std::max(nx, ny) <= config.max_search_cells) break;
  }
  const Pooled& ref_search = level(&ref_levels, search_level);
  const Pooled& mov_search = level(&mov_levels, search_level);
  // The moving grid is rotated from two levels finer (16 points per pooled cell).
  const Pooled& mov_source = level(&mov_levels, std::max(fine_level, search_level - 2));
  out.search_resolution = ref_search.cell;

  // A yaw error δ moves a cell at r from the moving map's centre by r δ once the translation
  // has made up for the centre: the step is two pooled cells of arc at the box's corner.
  const double radius = 0.5 * std::hypot(mov_search.w, mov_search.h) * mov_search.cell;
  const double yaw_step =
      config.yaw_step > 0.0 ? config.yaw_step : std::min(0.5, 2.0 * ref_search.cell / radius);

  const Requirement need = requirement(ref_search, mov_search, config.min_overlap);
  std::vector<Candidate> found =
      exhaustiveSearch(ref_search, mov_source, mov_search, yaw_step, nx, ny, need,
                       static_cast<size_t>(4 * config.candidates), &out.yaws_searched);
  if (config.has_prior) {
    found.erase(std::remove_if(found.begin(), found.end(),
                               [&](const Candidate& c) { return !nearPrior(c.pose); }),
                found.end());
  }
  std::vector<Candidate> candidates =
      bestDistinct(found, static_cast<size_t>(config.candidates), config);
  if (candidates.empty()) {
    *result = out;
    return fail("too little overlap: no pose puts " + number(100.0 * config.min_overlap) +
                " % of the smaller map's observed cells and occupied evidence on the other map");
  }

  // Coarse to fine on the pooled levels.
  double step = yaw_step;
  for (int l = search_level - 1; l >= fine_level; --l) {
    step *= 0.5;
    const Pooled& a = level(&ref_levels, l);
    const Pooled& b = level(&mov_levels, l);
    const Requirement req = requirement(a, b, config.min_overlap);
    for (Candidate& c : candidates) c = refineOnLevel(a, b, c, step, req);
    // Past the first refinement the ranking is settled enough to carry only the best few on; poses
    // within the reach of the finer levels' windows (two cells of this level each, both ways) may
    // still meet in one basin and count as one.
    candidates = bestDistinct(candidates, kFineCandidates, config, 4.0 * a.cell);
  }

  // On the maps' own cells, after ICP when it lowers the conflict.
  ScanMatcher matcher(config.matcher, SensorModelConfig{}, res);
  const std::vector<MatchPoint> faces =
      config.icp ? faceEndpoints(moving, static_cast<float>(config.matcher.occupied_threshold))
                 : std::vector<MatchPoint>{};
  // On the maps' own cells: level 0, free eroded as on the pooled levels.
  const Pooled ref_cells = cellRaster(reference), mov_cells = cellRaster(moving);
  const Requirement need_cells = requirement(ref_cells, mov_cells, config.min_overlap);
  auto evaluate = [&](const Pose2& pose, Candidate* c) {
    const Tally t = tallyPooled(ref_cells, mov_cells, pose);
    c->pose = pose;
    c->overlap = t.overlap;
    c->conflict = t.rate();
    c->score = need_cells.met(t) ? t.score(need_cells.structure) : kInf;
  };
  // Every candidate is refined below the cell (refineSubCell) before the candidates are compared:
  // each is judged at its best fit.
  const Pooled ref_raw = config.subcell ? cellRaster(reference, false) : Pooled{};
  const Pooled mov_raw = config.subcell ? cellRaster(moving, false) : Pooled{};
  const CellBox mov_box = moving.observedBox();
  const Eigen::Vector2d pivot(0.5 * (mov_box.min_x + mov_box.max_x + 1) * res,
                              0.5 * (mov_box.min_y + mov_box.max_y + 1) * res);
  const double mov_radius = 0.5 * std::hypot(mov_box.width(), mov_box.height()) * res;
  std::vector<Candidate> final_candidates;
  for (const Candidate& c : candidates) {
    if (!std::isfinite(c.score)) continue;
    Candidate f;
    evaluate(c.pose, &f);
    if (config.icp) {
      const std::vector<MatchPoint> pts = inOverlap(faces, reference, c.pose);
      if (!pts.empty()) {
        Candidate r;
        evaluate(matcher.refine(reference, c.pose, pts), &r);
        if (r.score < f.score) f = r;
      }
    }
    if (config.subcell && std::isfinite(f.score)) {
      Candidate r;
      evaluate(refineSubCell(ref_raw, mov_raw, f.pose, pivot, mov_radius), &r);
      if (std::isfinite(r.score)) f = r;
    }
    if (std::isfinite(f.score)) final_candidates.push_back(f);
  }
  if (config.has_prior) {
    final_candidates.erase(std::remove_if(final_candidates.begin(), final_candidates.end(),
                                          [&](const Candidate& c) { return !nearPrior(c.pose); }),
                           final_candidates.end());
  }
  std::sort(final_candidates.begin(), final_candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
  if (final_candidates.empty()) {
    *result = out;
    return fail(config.has_prior ? "too little overlap after refinement near the initial guess"
                                 : "too little overlap after refinement");
  }
  // The best and the candidates distinct from it and from each other, each verified.
  std::vector<Candidate> distinct_set;
  for (const Candidate& c : final_candidates) {
    if (std::all_of(distinct_set.begin(), distinct_set.end(),
                    [&](const Candidate& d) { return distinct(c.pose, d.pose, config); })) {
      distinct_set.push_back(c);
    }
  }
  for (const Candidate& c : distinct_set) {
    const Disagreement d = disagreement(reference, moving, c.pose, config.verify_tolerance);
    AlignmentResult::Candidate r;
    r.pose = c.pose;
    r.score = c.score;
    r.conflict = c.conflict;
    r.disagreement = d.share();
    r.contradicted_m = d.contradicted * res;
    r.matched_m = d.matched * res;
    r.overlap = c.overlap;
    out.candidates.push_back(r);
  }
  const Candidate& best = distinct_set.front();
  auto accept = [&](size_t i) {
    const Candidate& c = distinct_set[i];
    out.pose = Pose2(c.pose.x, c.pose.y, c.pose.theta);
    out.conflict = c.conflict;
    out.score = c.score;
    out.mean_conflict = meanConflict(reference, moving, out.pose);
    out.overlap_cells = c.overlap;
    // The best other candidate by score.
    out.alternative_score = -1.0;
    for (size_t k = 0; k < distinct_set.size(); ++k) {
      if (k == i) continue;
      out.alternative_score = distinct_set[k].score;
      out.alternative_pose = distinct_set[k].pose;
      break;
    }
  };
  accept(0);
  *result = out;
  if (best.conflict > config.max_conflict) {
    return fail("no pose explains the overlap: the best, " + describe(best.pose) +
                ", has structure conflict " + number(best.conflict) + " (at most " +
                number(config.max_conflict) + " accepted)");
  }
  // The score is ambiguous when candidates other than the best score within 1 / ambiguity_ratio
  // of it (the band); the verifier then chooses among the band's candidates: the lowest
  // disagreement, clearly below every other one's.
  const std::vector<AlignmentResult::Candidate>& v = out.candidates;
  size_t band = 1;
  while (band < v.size() && best.score > config.ambiguity_ratio * v[band].score) ++band;
  if (band == 1) return true;
  // It may prefer another candidate to the best-scored only within verify_score_margin of its
  // score: when the search missed the true pose, the least contradicted of its wrong candidates
  // is often one that overlaps little and fits poorly.
  size_t chosen = 0;
  for (size_t i = 1; i < band; ++i) {
    if (v[i].disagreement < v[chosen].disagreement &&
        v[i].score <= (1.0 + config.verify_score_margin) * best.score) {
      chosen = i;
    }
  }
  bool clear = true;
  for (size_t i = 0; i < band; ++i) {
    if (i == chosen) continue;
    clear = clear && v[chosen].disagreement <= config.verify_ratio * v[i].disagreement &&
            v[i].contradicted_m - v[chosen].contradicted_m >= config.verify_min_length;
  }
  if (clear && distinct_set[chosen].conflict <= config.max_conflict) {
    accept(chosen);
    out.decided_by_verifier = true;
    *result = out;
    return true;
  }
  std::string listing;
  for (const AlignmentResult::Candidate& c : v) {
    listing += (listing.empty() ? "" : "; ") + describe(c.pose) + " score " + number(c.score) +
               ", disagreement " + number(c.disagreement) + " (" + number(c.contradicted_m) +
               " m of wall contradicted)";
  }
  return fail("ambiguous alignment: neither the score (the best must score at most " +
              number(config.ambiguity_ratio) + " times the next) nor the disagreement beyond " +
              number(config.verify_tolerance) + " m (at most " + number(config.verify_ratio) +
              " times the next's, and " + number(config.verify_min_length) +
              " m of wall less) tells the candidates apart: " + listing);
}

}  // namespace fusion
}  // namespace evidential_slam
