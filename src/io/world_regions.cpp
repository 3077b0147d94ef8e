#include "evidential_slam/io/world_regions.h"

#include <algorithm>
#include <cmath>
#include <istream>
#include <utility>

#include "evidential_slam/io/dynamic_objects.h"

namespace evidential_slam {
namespace io {

double WorldRegion::distanceTo(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d e = b - a;
  const double len2 = e.squaredNorm();
  const double s = len2 > 0.0 ? std::clamp((p - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return std::max(0.0, (p - (a + s * e)).norm() - radius);
}

bool WorldRegion::contains(const Eigen::Vector2d& p) const { return distanceTo(p) <= 0.0; }

const char* regionKindName(RegionKind kind) {
  return kind == RegionKind::kGlass ? "glass" : "clutter";
}

bool parseWorldRegion(const std::string& kind, std::istream& fields, WorldRegion* region,
                      std::string* expected) {
  const bool glass = kind == "glass";
  *expected = glass ? "`glass AX AY BX BY R P` (R > 0, 0 <= P <= 1)"
                    : "`clutter AX AY BX BY R SIGMA` (R > 0, SIGMA > 0)";
  double v[6];
  for (double& x : v) {
    if (!(fields >> x) || !std::isfinite(x)) return false;
  }
  std::string extra;
  if (fields >> extra) return false;
  region->kind = glass ? RegionKind::kGlass : RegionKind::kClutter;
  region->a = Eigen::Vector2d(v[0], v[1]);
  region->b = Eigen::Vector2d(v[2], v[3]);
  region->radius = v[4];
  region->value = v[5];
  if (!(region->radius > 0.0)) return false;
  return glass ? region->value >= 0.0 && region->value <= 1.0 : region->value > 0.0;
}

int castThroughRegions(const std::vector<WorldRegion>& regions, const Eigen::Vector2d& origin,
                       const Eigen::Vector2d& direction, double end, std::mt19937_64* rng,
                       double* range) {
  *range = end;
  std::vector<std::pair<double, int>> entries;
  for (size_t k = 0; k < regions.size(); ++k) {
    const WorldRegion& r = regions[k];
    if (r.contains(origin)) continue;
    const double d = capsuleRayHit(origin, direction, r.a, r.b, r.radius);
    if (d >= 0.0 && d < end) entries.emplace_back(d, static_cast<int>(k));
  }
  std::sort(entries.begin(), entries.end());
  for (const auto& [d, k] : entries) {
    const WorldRegion& r = regions[static_cast<size_t>(k)];
    if (r.kind == RegionKind::kGlass) {
      if (std::uniform_real_distribution<double>(0.0, 1.0)(*rng) < r.value) continue;
      *range = d;
    } else {
      *range = std::max(0.0, d + r.value * std::normal_distribution<double>(0.0, 1.0)(*rng));
    }
    return k;
  }
  return -1;
}

}  // namespace io
}  // namespace evidential_slam
