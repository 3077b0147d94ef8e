// Evidential maps painted from a world of wall segments, for the fusion tests: what a SLAM run's
// map of that world looks like (walls occupied, the building's inside free, noisy masses, some
// spurious hits), seen from a chosen map frame and only within a circle of the world.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace synthetic {

struct Segment {
  Eigen::Vector2d a, b;
};

struct Box {
  Eigen::Vector2d min, max;
  bool contains(const Eigen::Vector2d& p) const {
    return p.x() > min.x() && p.y() > min.y() && p.x() < max.x() && p.y() < max.y();
  }
};

struct World {
  std::vector<Segment> walls;
  Eigen::Vector2d min, max;  // the building: cells inside it that are not walls are free
  std::vector<Box> solids;   // blocks no sensor sees into: their inside stays unobserved

  double distance(const Eigen::Vector2d& p) const {
    double best = 1e9;
    for (const Segment& s : walls) {
      const Eigen::Vector2d d = s.b - s.a;
      const double t = std::clamp((p - s.a).dot(d) / d.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (s.a + t * d - p).norm());
    }
    return best;
  }
};

inline void addBox(World* w, double x0, double y0, double x1, double y1) {
  w->walls.push_back({{x0, y0}, {x1, y0}});
  w->walls.push_back({{x1, y0}, {x1, y1}});
  w->walls.push_back({{x1, y1}, {x0, y1}});
  w->walls.push_back({{x0, y1}, {x0, y0}});
}

// A 20 m x 14 m floor: a corridor with doors, rooms of different widths, a pillar and a slanted
// wall, so that no rotation or shift of it matches itself.
inline World office() {
  World w;
  w.min = {0.0, 0.0};
  w.max = {20.0, 14.0};
  addBox(&w, 0, 0, 20, 14);
  auto wall = [&](double x0, double y0, double x1, double y1) {
    w.walls.push_back({{x0, y0}, {x1, y1}});
  };
  wall(0, 6, 3, 6), wall(4, 6, 9, 6), wall(10, 6, 15.5, 6), wall(16.5, 6, 20, 6);
  wall(0, 8, 5, 8), wall(6, 8, 12, 8), wall(13, 8, 20, 8);
  wall(7, 0, 7, 6), wall(13, 0, 13, 6), wall(9, 8, 9, 14), wall(16, 8, 16, 11.5);
  wall(17, 2, 19, 4);
  addBox(&w, 3.8, 10.8, 4.2, 11.2);
  return w;
}

// A 36 m x 20 m floor of solid blocks of different widths between 1.8 m corridors (a building
// like the Radish log aces): free space only in corridors narrower than three 0.8 m cells.
inline World corridors() {
  World w;
  w.min = {0.0, 0.0};
  w.max = {36.0, 20.0};
  addBox(&w, 0, 0, 36, 20);
  auto block = [&](double x0, double y0, double x1, double y1) {
    addBox(&w, x0, y0, x1, y1);
    w.solids.push_back({{x0 + 0.06, y0 + 0.06}, {x1 - 0.06, y1 - 0.06}});
  };
  block(1.8, 1.8, 7.0, 8.2), block(8.8, 1.8, 17.5, 8.2), block(19.3, 1.8, 23.0, 8.2);
  block(24.8, 1.8, 34.2, 8.2);
  block(1.8, 10.0, 11.0, 18.2), block(12.8, 10.0, 15.5, 18.2), block(17.3, 10.0, 27.0, 18.2);
  block(28.8, 10.0, 34.2, 18.2);
  return w;
}

// A 20 m x 12 m floor that a half turn about its centre maps onto itself: a corridor between
// two rows of four rooms, doors placed symmetrically. With `furnished`, a pillar and a cabinet
// (a 1.5 m wall) in two rooms break the symmetry, as the few asymmetric things of a real
// building do.
inline World symmetricOffice(bool furnished) {
  World w;
  w.min = {0.0, 0.0};
  w.max = {20.0, 12.0};
  addBox(&w, 0, 0, 20, 12);
  auto wall = [&](double x0, double y0, double x1, double y1) {
    w.walls.push_back({{x0, y0}, {x1, y1}});
    w.walls.push_back({{20.0 - x0, 12.0 - y0}, {20.0 - x1, 12.0 - y1}});  // its half-turn twin
  };
  wall(0, 5, 2, 5), wall(3, 5, 7, 5), wall(8, 5, 12, 5), wall(13, 5, 17, 5), wall(18, 5, 20, 5);
  wall(5, 0, 5, 5), wall(10, 0, 10, 5), wall(15, 0, 15, 5);
  if (furnished) {
    addBox(&w, 3.0, 9.3, 3.4, 9.7);
    w.walls.push_back({{11.5, 1.5}, {13.0, 1.5}});
  }
  return w;
}

// Short walls at random places and angles in a 16 m square: nothing in common with office().
inline World clutter(uint64_t seed) {
  World w;
  w.min = {0.0, 0.0};
  w.max = {16.0, 16.0};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector2d a(16.0 * u(rng), 16.0 * u(rng));
    const double angle = 2.0 * 3.14159265358979323846 * u(rng), length = 0.5 + 2.0 * u(rng);
    w.walls.push_back({a, a + length * Eigen::Vector2d(std::cos(angle), std::sin(angle))});
  }
  return w;
}

// The map of `world` whose frame is `map_in_world`, observed within `radius` of `centre` (world
// coordinates). Walls (within 0.06 m of a segment): m̃(o) in [0.6, 0.95]; free cells m̃(e) in
// [0.6, 0.95]; 0.5 % of free cells a spurious hit (m̃(o) 0.5).
// `bend` (rad) distorts the map as a SLAM run's drift does: a cell at distance r from the observed
// centre is placed turned by bend · r / radius about it (0.017 rad at 10 m: 0.17 m at the edge).
inline EvidentialGridMap paint(const World& world, const Pose2& map_in_world,
                               const Eigen::Vector2d& centre, double radius, double resolution,
                               uint64_t seed, double bend = 0.0) {
  EvidentialGridMap map(resolution);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // The observed circle in the map's frame, and its box of cells.
  const Eigen::Vector2d c = map_in_world.inverse().transformPoint(centre);
  const int x0 = static_cast<int>(std::floor((c.x() - radius) / resolution));
  const int x1 = static_cast<int>(std::ceil((c.x() + radius) / resolution));
  const int y0 = static_cast<int>(std::floor((c.y() - radius) / resolution));
  const int y1 = static_cast<int>(std::ceil((c.y() + radius) / resolution));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      Eigen::Vector2d local((x + 0.5) * resolution, (y + 0.5) * resolution);
      if (bend != 0.0) {
        const Eigen::Vector2d d = local - c;
        const double a = bend * d.norm() / radius;
        local = c + Eigen::Vector2d(std::cos(a) * d.x() - std::sin(a) * d.y(),
                                    std::sin(a) * d.x() + std::cos(a) * d.y());
      }
      const Eigen::Vector2d p = map_in_world.transformPoint(local);
      if ((p - centre).norm() > radius) continue;
      if (p.x() < world.min.x() || p.y() < world.min.y() || p.x() > world.max.x() ||
          p.y() > world.max.y()) {
        continue;
      }
      if (std::any_of(world.solids.begin(), world.solids.end(),
                      [&](const Box& b) { return b.contains(p); })) {
        continue;
      }
      Cell& cell = map.mutableCell(x, y);
      if (world.distance(p) < 0.06) {
        cell.setMasses(static_cast<float>(0.6 + 0.35 * u(rng)), 0.0f);
      } else if (u(rng) < 0.005) {
        cell.setMasses(0.5f, 0.0f);
      } else {
        cell.setMasses(0.0f, static_cast<float>(0.6 + 0.35 * u(rng)));
      }
    }
  }
  return map;
}

}  // namespace synthetic
}  // namespace evidential_slam
