// Shared helpers of the core tests: a synthetic room scan, a noise-free motion model, a walk over
// a map's tiles.
#pragma once

#include <algorithm>
#include <cmath>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"

namespace evidential_slam {
namespace testing_room {

// Distance from `pose` along the direction (c, s) = (cos, sin) to the nearest wall of a 4 m x 4 m
// room centred on the origin (walls x, y = ±2).
inline double roomWallRange(const Pose2& pose, double c, double s) {
  double t = 1e9;
  if (c > 1e-9) t = std::min(t, (2.0 - pose.x) / c);
  if (c < -1e-9) t = std::min(t, (-2.0 - pose.x) / c);
  if (s > 1e-9) t = std::min(t, (2.0 - pose.y) / s);
  if (s < -1e-9) t = std::min(t, (-2.0 - pose.y) / s);
  return t;
}

// Scan of a 4 m x 4 m room centred on the origin (walls x, y = ±2): 360 beams over a full turn
// from `pose` (sensor at the robot origin), each the range to the nearest wall. With `with_box`,
// a wall segment x = 1 for y in [0.5, 2] breaks the room's symmetry.
inline LaserScan roomScan(const Pose2& pose, double stamp = 0.0, bool with_box = false) {
  constexpr double kPi = 3.14159265358979323846;
  LaserScan scan;
  scan.stamp = stamp;
  scan.max_range = 30.0f;
  for (int i = 0; i < 360; ++i) {
    const double bearing = -kPi + i * (2 * kPi / 360);
    const double a = pose.theta + bearing;
    const double c = std::cos(a), s = std::sin(a);
    double t = roomWallRange(pose, c, s);
    if (with_box && c > 1e-9 && pose.x < 1.0) {
      const double tb = (1.0 - pose.x) / c;
      const double yb = pose.y + tb * s;
      if (yb >= 0.5 && yb <= 2.0) t = std::min(t, tb);
    }
    scan.ranges.push_back(static_cast<float>(t));
    scan.bearings.push_back(static_cast<float>(bearing));
    scan.valid.push_back(1);
  }
  return scan;
}

// Scan of a corridor along x (walls y = ±1, no end within the laser's 20 m): 360 beams over a
// full turn from `pose`; beams along it are no-return (invalid).
inline LaserScan corridorScan(const Pose2& pose) {
  constexpr double kPi = 3.14159265358979323846;
  LaserScan scan;
  scan.max_range = 20.0f;
  for (int i = 0; i < 360; ++i) {
    const double bearing = -kPi + i * (2 * kPi / 360), s = std::sin(pose.theta + bearing);
    const double t = s > 1e-9 ? (1.0 - pose.y) / s : s < -1e-9 ? (-1.0 - pose.y) / s : 1e9;
    scan.bearings.push_back(static_cast<float>(bearing));
    scan.ranges.push_back(static_cast<float>(std::min(t, 25.0)));
    scan.valid.push_back(t < 20.0 ? 1 : 0);
  }
  return scan;
}

// A motion model that adds no noise at all (no α terms, no floor): samples equal the odometry.
inline MotionModelConfig noiselessMotion() {
  MotionModelConfig c;
  c.alpha_rot_rot = c.alpha_rot_trans = c.alpha_trans_trans = c.alpha_trans_rot = 0.0;
  c.min_sigma_xy = c.min_sigma_theta = 0.0;
  return c;
}

// `c` with the real-robot settings the defaults carry (docs/decisions.md) switched off: no
// wide-basin match, conflict counted against a pose, no along-track prior, 12 ICP iterations, no
// long-step settings, the simulated odometry's rotation noise. What most core tests exercise: each
// of those settings has tests of its own.
inline SlamConfig withoutRealRobotSettings(SlamConfig c) {
  c.matcher.heading_window = 0.0;
  c.sensor.forward_conflict_as_unknown = false;
  c.along_track_prior = false;
  c.matcher.icp_iterations = 12;
  c.long_step.beam_spacing = 0.0;
  c.long_step.forward_sigma = 0.0;
  c.motion.alpha_rot_rot = 0.02;
  return c;
}

// `c` with the real-robot settings back at their defaults.
inline SlamConfig withRealRobotSettings(SlamConfig c) {
  const SlamConfig d;
  c.matcher.heading_window = d.matcher.heading_window;
  c.sensor.forward_conflict_as_unknown = d.sensor.forward_conflict_as_unknown;
  c.along_track_prior = d.along_track_prior;
  c.matcher.icp_iterations = d.matcher.icp_iterations;
  c.long_step.beam_spacing = d.long_step.beam_spacing;
  c.long_step.forward_sigma = d.long_step.forward_sigma;
  c.motion.alpha_rot_rot = d.motion.alpha_rot_rot;
  return c;
}

// Calls fn(tx, ty, tile) for every allocated tile of `map`, row by row.
template <typename Fn>
void forEachAllocatedTile(const EvidentialGridMap& map, Fn&& fn) {
  const CellBox box = map.allocatedBox();
  for (int ty = box.min_y >> EvidentialGridMap::kTileBits;
       ty <= box.max_y >> EvidentialGridMap::kTileBits; ++ty) {
    for (int tx = box.min_x >> EvidentialGridMap::kTileBits;
         tx <= box.max_x >> EvidentialGridMap::kTileBits; ++tx) {
      if (const EvidentialGridMap::Tile* tile = map.tile(tx, ty)) fn(tx, ty, *tile);
    }
  }
}

}  // namespace testing_room
}  // namespace evidential_slam
