// Objects that move or appear in a simulated world (gridmap_simulator.h): people crossing, boxes
// parked then removed, a door that opens. Each is a capsule (every point within `radius` of a
// segment) present during [t0, t1], its segment moving linearly from (a0, b0) at t0 to (a1, b1)
// at t1. A laser ray ends on the nearest of the walls and the objects present at the scan's stamp.
#pragma once

#include <istream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/io/world_regions.h"

namespace evidential_slam {
namespace io {

struct DynamicObject {
  double t0 = 0.0, t1 = 0.0;           // s, present in [t0, t1]
  Eigen::Vector2d a0{0, 0}, b0{0, 0};  // segment at t0 (m, map frame)
  Eigen::Vector2d a1{0, 0}, b1{0, 0};  // segment at t1
  double radius = 0.0;                 // m, > 0

  bool presentAt(double t) const { return t >= t0 - 1e-9 && t <= t1 + 1e-9; }
  // The segment at t (clamped to [t0, t1]).
  void segmentAt(double t, Eigen::Vector2d* a, Eigen::Vector2d* b) const;
  // Distance along the ray from `origin` in unit `direction` to the capsule at t, or a negative
  // value when the ray misses it (a ray starting inside it hits at 0).
  double rayHit(double t, const Eigen::Vector2d& origin, const Eigen::Vector2d& direction) const;
};

// Distance along the ray from `origin` in unit `direction` to the capsule of `radius` round
// segment a-b, or a negative value when the ray misses it (a ray starting inside it hits at 0).
double capsuleRayHit(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                     const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius);

// Reads an objects file, one object a line (blank lines and text after '#' ignored):
//   disc T0 T1 X0 Y0 X1 Y1 R      a disc of radius R going from (X0, Y0) at T0 to (X1, Y1) at T1
//   bar  T0 T1 AX AY BX BY R      a fixed capsule around segment A-B (a parked box, a door panel)
//   glass AX AY BX BY R P         world_regions.h: beams pass with probability P
//   clutter AX AY BX BY R SIGMA   world_regions.h: beams return with SIGMA m of range scatter
// Region lines go to `regions` (nullptr: they are an error). False with a one-line `error` naming
// the file and line on anything else, T1 < T0, R <= 0, P outside [0, 1] or SIGMA <= 0.
bool readDynamicObjects(std::istream& in, const std::string& name,
                        std::vector<DynamicObject>* objects, std::string* error,
                        std::vector<WorldRegion>* regions = nullptr);
bool readDynamicObjects(const std::string& path, std::vector<DynamicObject>* objects,
                        std::string* error, std::vector<WorldRegion>* regions = nullptr);

// The nearest object present at t along the ray: its index and distance (-1 and a negative
// distance when none).
int nearestObjectHit(const std::vector<DynamicObject>& objects, double t,
                     const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                     double* distance);

}  // namespace io
}  // namespace evidential_slam
