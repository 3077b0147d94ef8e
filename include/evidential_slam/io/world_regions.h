// Regions of a simulated world that a laser reads ambiguously (gridmap_simulator.h): glass, which
// a beam crosses or returns from at random, and clutter (plants, chair legs, shelves), which
// returns beams at a range scattered far more than a wall's. Each is a capsule (every point within
// `radius` of segment a-b), present for the whole run, and an obstacle to the robot's disc.
#pragma once

#include <istream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace evidential_slam {
namespace io {

enum class RegionKind { kGlass, kClutter };

struct WorldRegion {
  RegionKind kind = RegionKind::kGlass;
  Eigen::Vector2d a{0, 0}, b{0, 0};  // m, map frame
  double radius = 0.0;               // m, > 0
  // glass: probability that a beam crossing the region passes through it (else it returns where
  // it enters); clutter: m, 1-sigma of the Gaussian added to the range where a beam enters.
  double value = 0.0;

  bool contains(const Eigen::Vector2d& p) const;
  double distanceTo(const Eigen::Vector2d& p) const;  // 0 inside
};

const char* regionKindName(RegionKind kind);

// Parses the fields after the keyword of an objects-file line: `glass AX AY BX BY R P`
// (0 <= P <= 1) or `clutter AX AY BX BY R SIGMA` (SIGMA > 0). False, with what a line of that
// kind must hold in `expected`, on anything else.
bool parseWorldRegion(const std::string& kind, std::istream& fields, WorldRegion* region,
                      std::string* expected);

// Where a ray from `origin` along unit `direction` ends once the regions are taken into account,
// given where it would end without them (`end`, m; infinity for no return). The regions it enters
// before `end` (a region holding the origin is ignored) act in the order it enters them: glass
// lets it pass with its probability, clutter returns it at the entry + N(0, sigma^2) (at least 0).
// Returns the index of the region it ended in (its range in `range`), or -1 (range = end).
// Draws from `rng` only for the regions the ray enters.
int castThroughRegions(const std::vector<WorldRegion>& regions, const Eigen::Vector2d& origin,
                       const Eigen::Vector2d& direction, double end, std::mt19937_64* rng,
                       double* range);

}  // namespace io
}  // namespace evidential_slam
