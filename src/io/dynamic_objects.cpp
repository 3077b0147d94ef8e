#include "evidential_slam/io/dynamic_objects.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace {

// Smallest t >= 0 with |origin + t d - c| = r (d unit), or -1.
double rayCircle(const Eigen::Vector2d& origin, const Eigen::Vector2d& d, const Eigen::Vector2d& c,
                 double r) {
  const Eigen::Vector2d m = origin - c;
  const double b = m.dot(d), q = m.squaredNorm() - r * r;
  if (q <= 0.0) return 0.0;  // inside
  const double disc = b * b - q;
  if (disc < 0.0) return -1.0;
  const double t = -b - std::sqrt(disc);
  return t >= 0.0 ? t : -1.0;
}

// Smallest t >= 0 where the ray crosses segment p-q, or -1.
double raySegment(const Eigen::Vector2d& origin, const Eigen::Vector2d& d, const Eigen::Vector2d& p,
                  const Eigen::Vector2d& q) {
  const Eigen::Vector2d e = q - p, w = p - origin;
  const double den = d.x() * e.y() - d.y() * e.x();
  if (std::abs(den) < 1e-12) return -1.0;
  const double t = (w.x() * e.y() - w.y() * e.x()) / den;
  const double u = (w.x() * d.y() - w.y() * d.x()) / den;
  return t >= 0.0 && u >= 0.0 && u <= 1.0 ? t : -1.0;
}

}  // namespace

void DynamicObject::segmentAt(double t, Eigen::Vector2d* a, Eigen::Vector2d* b) const {
  const double s = t1 > t0 ? std::clamp((t - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
  *a = a0 + s * (a1 - a0);
  *b = b0 + s * (b1 - b0);
}

double capsuleRayHit(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                     const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius) {
  double best = -1.0;
  auto take = [&best](double v) {
    if (v >= 0.0 && (best < 0.0 || v < best)) best = v;
  };
  take(rayCircle(origin, direction, a, radius));
  take(rayCircle(origin, direction, b, radius));
  const Eigen::Vector2d e = b - a;
  if (e.norm() > 1e-12) {
    const Eigen::Vector2d n = Eigen::Vector2d(-e.y(), e.x()).normalized() * radius;
    take(raySegment(origin, direction, a + n, b + n));
    take(raySegment(origin, direction, a - n, b - n));
  }
  return best;
}

double DynamicObject::rayHit(double t, const Eigen::Vector2d& origin,
                             const Eigen::Vector2d& direction) const {
  Eigen::Vector2d a, b;
  segmentAt(t, &a, &b);
  return capsuleRayHit(origin, direction, a, b, radius);
}

bool readDynamicObjects(std::istream& in, const std::string& name,
                        std::vector<DynamicObject>* objects, std::string* error,
                        std::vector<WorldRegion>* regions) {
  objects->clear();
  if (regions != nullptr) regions->clear();
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::string kind;
    if (!(fields >> kind)) continue;
    if (kind == "glass" || kind == "clutter") {
      WorldRegion region;
      std::string expected;
      if (regions == nullptr || !parseWorldRegion(kind, fields, &region, &expected)) {
        if (error) {
          *error = "objects file '" + name + "' line " + std::to_string(number) + ": " +
                   (regions == nullptr ? "regions (" + kind + ") are not read here"
                                       : "expected " + expected) +
                   ", got " + quotedForMessage(line);
        }
        objects->clear();
        if (regions != nullptr) regions->clear();
        return false;
      }
      regions->push_back(region);
      continue;
    }
    double v[7];
    std::string extra;
    bool ok = (kind == "disc" || kind == "bar");
    for (double& x : v) ok = ok && static_cast<bool>(fields >> x) && std::isfinite(x);
    ok = ok && !(fields >> extra);
    DynamicObject o;
    if (ok) {
      o.t0 = v[0];
      o.t1 = v[1];
      o.radius = v[6];
      if (kind == "disc") {
        o.a0 = o.b0 = Eigen::Vector2d(v[2], v[3]);
        o.a1 = o.b1 = Eigen::Vector2d(v[4], v[5]);
      } else {
        o.a0 = o.a1 = Eigen::Vector2d(v[2], v[3]);
        o.b0 = o.b1 = Eigen::Vector2d(v[4], v[5]);
      }
      ok = o.t1 >= o.t0 && o.radius > 0.0;
    }
    if (!ok) {
      if (error) {
        *error = "objects file '" + name + "' line " + std::to_string(number) +
                 ": expected `disc T0 T1 X0 Y0 X1 Y1 R`, `bar T0 T1 AX AY BX BY R` (T1 >= T0, "
                 "R > 0), `glass ...` or `clutter ...`, got " +
                 quotedForMessage(line);
      }
      objects->clear();
      if (regions != nullptr) regions->clear();
      return false;
    }
    objects->push_back(o);
  }
  return true;
}

bool readDynamicObjects(const std::string& path, std::vector<DynamicObject>* objects,
                        std::string* error, std::vector<WorldRegion>* regions) {
  std::ifstream in(path);
  if (!in) {
    if (error) *error = "cannot read objects file '" + path + "'";
    return false;
  }
  return readDynamicObjects(in, path, objects, error, regions);
}

int nearestObjectHit(const std::vector<DynamicObject>& objects, double t,
                     const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                     double* distance) {
  int best = -1;
  *distance = -1.0;
  for (size_t i = 0; i < objects.size(); ++i) {
    if (!objects[i].presentAt(t)) continue;
    const double d = objects[i].rayHit(t, origin, direction);
    if (d >= 0.0 && (best < 0 || d < *distance)) {
      best = static_cast<int>(i);
      *distance = d;
    }
  }
  return best;
}

}  // namespace io
}  // namespace evidential_slam
