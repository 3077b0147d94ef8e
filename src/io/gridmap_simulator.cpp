// The grid-map robot simulator and its rawlog recorder. See gridmap_simulator.h for the contract.
#include "evidential_slam/io/gridmap_simulator.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <system_error>

#include <mrpt/core/Clock.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/dynamic_objects.h"
#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace {

// Waypoint following: turn rate = gain × heading error (clamped to angular_speed); the robot turns
// in place while the next waypoint is more than kDriveMaxHeadingError off its heading.
constexpr double kTurnGain = 2.0;              // 1/s
constexpr double kDriveMaxHeadingError = 0.3;  // rad (~17 degrees)
// Collisions: a robot stopped by a wall stays in contact until it is further than this from
// every wall (one that backs off further and runs into it again collides again); a waypoint
// route held by a wall this long ends (it would never arrive).
constexpr double kContactMargin = 0.01;  // m
constexpr double kStuckTimeout = 5.0;    // s
constexpr int kContactBisections = 20;   // halvings of a blocked step to find the contact

bool finite(double v) { return std::isfinite(v); }

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Exact pose change of a unicycle driving (v, w) for dt, in its own frame at the start.
Pose2 unicycleIncrement(double v, double w, double dt) {
  const double a = w * dt;
  if (std::abs(a) < 1e-9) return Pose2(v * dt, 0.0, a);
  const double r = v / w;
  return Pose2(r * std::sin(a), r * (1.0 - std::cos(a)), a);
}

// MRPT's map loaders print their exceptions to std::cerr and return false. This keeps that text
// off the terminal and for our own one-line error.
class CerrCapture {
 public:
  CerrCapture() : old_(std::cerr.rdbuf(buffer_.rdbuf())) {}
  ~CerrCapture() { std::cerr.rdbuf(old_); }
  std::string message() const {
    const std::string text = buffer_.str();
    return text.find("Message:") == std::string::npos ? "" : oneLineMessage(text);
  }

 private:
  std::ostringstream buffer_;
  std::streambuf* old_;
};

mrpt::poses::CPose2D toMrpt(const Pose2& p) { return mrpt::poses::CPose2D(p.x, p.y, p.theta); }

// One engine per noise source, all from the one seed.
std::mt19937_64 seededEngine(int seed, uint32_t stream) {
  std::seed_seq sequence{static_cast<uint32_t>(seed), stream};
  return std::mt19937_64(sequence);
}

}  // namespace

bool GridmapSimulatorConfig::isValid(std::string* why) const {
  auto fail = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  GridmapSimulatorConfig copy = *this;  // the field list wants pointers it could write through
  for (const auto& field : gridmapSimulatorFields(&copy)) {
    if (const auto* d = std::get_if<double*>(&field.value); d && !finite(**d)) {
      return fail(std::string(field.name) + " must be a finite number");
    }
  }
  if (map.empty()) return fail("map (the image or map_server .yaml to simulate in) is not set");
  if (!(resolution > 0.0)) return fail("resolution must be > 0 (m per pixel)");
  if (!(occupied_threshold > 0.5 && occupied_threshold <= 1.0)) {
    return fail("occupied_threshold must be in (0.5, 1]");
  }
  if (!(linear_speed > 0.0)) return fail("linear_speed must be > 0");
  if (!(angular_speed > 0.0)) return fail("angular_speed must be > 0");
  if (!(waypoint_tolerance > 0.0)) return fail("waypoint_tolerance must be > 0");
  if (!(robot_radius >= 0.0)) return fail("robot_radius must be >= 0 (m)");
  if (duration < 0.0) return fail("duration must be >= 0 (0 = until the last waypoint)");
  if (!(start_time > 0.0)) return fail("start_time must be > 0 (time 0 means 'unset' in ROS)");
  if (!(scan_period > 0.0)) return fail("scan_period must be > 0");
  if (!(physics_period > 0.0 && physics_period <= scan_period)) {
    return fail("physics_period must be > 0 and <= scan_period");
  }
  if (laser_rays < 2) return fail("laser_rays must be >= 2");
  if (!(laser_aperture > 0.0 && laser_aperture <= 2.0 * M_PI)) {
    return fail("laser_aperture must be in (0, 2 pi] rad");
  }
  if (!(laser_max_range > 0.0)) return fail("laser_max_range must be > 0");
  if (range_noise < 0.0 || bearing_noise < 0.0) {
    return fail("range_noise and bearing_noise must be >= 0");
  }
  if (odometry_noise_xy < 0.0 || odometry_noise_theta < 0.0 || odometry_noise_theta_per_m < 0.0) {
    return fail("odometry noise parameters must be >= 0");
  }
  if (seed < 0) return fail("seed must be >= 0");
  if (hasKidnap() && !(kidnap_time > start_time)) {
    return fail("kidnap_time must come after start_time (the first scan)");
  }
  if (hasMovingObject()) {
    if (!(moving_object_end >= moving_object_start)) {
      return fail("moving_object_end must be >= moving_object_start");
    }
    if (!(moving_object_bearing_max >= moving_object_bearing_min)) {
      return fail("moving_object_bearing_max must be >= moving_object_bearing_min");
    }
    if (!(moving_object_distance > 0.0 && moving_object_distance < laser_max_range)) {
      return fail("moving_object_distance must be in (0, laser_max_range)");
    }
  }
  return true;
}

std::vector<GridmapSimulatorField> gridmapSimulatorFields(GridmapSimulatorConfig* c) {
  return {
      {"map", &c->map, "map image (PNG, PGM...; black = wall) or map_server .yaml"},
      {"resolution", &c->resolution, "m per pixel of the image (a .yaml brings its own)"},
      {"map_centered", &c->map_centered, "put the image centre at the map origin"},
      {"origin_x", &c->origin_x, "m, map x of the image's lower-left corner (map_centered off)"},
      {"origin_y", &c->origin_y, "m, map y of the image's lower-left corner (map_centered off)"},
      {"occupied_threshold", &c->occupied_threshold,
       "cells at least this occupied (0 white .. 1 black) stop a ray"},
      {"waypoints", &c->waypoints, "waypoint file (`x y` per line); empty = cmd_vel"},
      {"start_x", &c->start_x, "m, start pose without waypoints"},
      {"start_y", &c->start_y, "m, start pose without waypoints"},
      {"start_theta", &c->start_theta, "rad, start pose without waypoints"},
      {"linear_speed", &c->linear_speed, "m/s, forward speed limit"},
      {"angular_speed", &c->angular_speed, "rad/s, turn rate limit"},
      {"waypoint_tolerance", &c->waypoint_tolerance, "m, a waypoint closer than this is reached"},
      {"robot_radius", &c->robot_radius,
       "m, the robot's disc: motion into a wall stops at contact and counts as a collision"},
      {"duration", &c->duration, "s of simulation at most; 0 = until the last waypoint"},
      {"start_time", &c->start_time, "s, simulation clock at the first scan (> 0)"},
      {"scan_period", &c->scan_period, "s between scans and odometry increments"},
      {"physics_period", &c->physics_period, "s, kinematics integration step"},
      {"laser_label", &c->laser_label, "sensor label of the scans in the rawlog"},
      {"laser_rays", &c->laser_rays, "rays per scan"},
      {"laser_aperture", &c->laser_aperture, "rad, field of view, centred ahead"},
      {"laser_max_range", &c->laser_max_range, "m, farther = no return"},
      {"laser_x", &c->laser_x, "m, laser position on the robot"},
      {"laser_y", &c->laser_y, "m, laser position on the robot"},
      {"laser_yaw", &c->laser_yaw, "rad, laser heading on the robot"},
      {"range_noise", &c->range_noise, "m, 1-sigma Gaussian range noise"},
      {"bearing_noise", &c->bearing_noise, "rad, 1-sigma error of each ray's true direction"},
      {"odometry_noise_xy", &c->odometry_noise_xy,
       "m per m driven: 1-sigma x and y error of each odometry increment"},
      {"odometry_noise_theta", &c->odometry_noise_theta,
       "rad per rad turned: 1-sigma heading error of each increment"},
      {"odometry_noise_theta_per_m", &c->odometry_noise_theta_per_m,
       "rad per m driven: more heading error"},
      {"seed", &c->seed, "random seed of all noise"},
      {"kidnap_time", &c->kidnap_time, "s, when the true pose jumps; < 0 = no kidnap"},
      {"kidnap_dx", &c->kidnap_dx, "m, kidnap jump along map x"},
      {"kidnap_dy", &c->kidnap_dy, "m, kidnap jump along map y"},
      {"kidnap_dtheta", &c->kidnap_dtheta, "rad, kidnap rotation"},
      {"moving_object_start", &c->moving_object_start,
       "s, moving object appears; < 0 = no moving object"},
      {"moving_object_end", &c->moving_object_end, "s, moving object leaves"},
      {"moving_object_bearing_min", &c->moving_object_bearing_min,
       "rad, laser frame, first bearing it covers"},
      {"moving_object_bearing_max", &c->moving_object_bearing_max,
       "rad, laser frame, last bearing it covers"},
      {"moving_object_distance", &c->moving_object_distance, "m, its distance from the laser"},
      {"objects", &c->objects,
       "objects file: `disc T0 T1 X0 Y0 X1 Y1 R` / `bar T0 T1 AX AY BX BY R` / `glass AX AY BX "
       "BY R P` / `clutter AX AY BX BY R SIGMA` per line (map frame, s, m); \"\" = none"},
  };
}

bool readWaypoints(const std::string& path, std::vector<Eigen::Vector2d>* waypoints,
                   std::string* error) {
  waypoints->clear();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (error) *error = "waypoint file '" + path + "' does not exist or is not a file";
    return false;
  }
  std::ifstream in(path);
  if (!in) {
    if (error) *error = "cannot read waypoint file '" + path + "'";
    return false;
  }
  return readWaypoints(in, path, waypoints, error);
}

bool readWaypoints(std::istream& in, const std::string& name,
                   std::vector<Eigen::Vector2d>* waypoints, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    waypoints->clear();
    return false;
  };
  waypoints->clear();
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::string first;
    if (!(fields >> first)) continue;  // blank or comment
    std::istringstream again(line);
    double x = 0.0, y = 0.0;
    std::string extra;
    if (!(again >> x >> y) || (again >> extra) || !finite(x) || !finite(y)) {
      return fail("waypoint file '" + name + "' line " + std::to_string(number) +
                  ": expected two numbers `x y`, got " + quotedForMessage(line));
    }
    waypoints->emplace_back(x, y);
  }
  if (in.bad()) return fail("error reading waypoint file '" + name + "'");
  if (waypoints->size() < 2) {
    return fail("waypoint file '" + name + "' holds " + std::to_string(waypoints->size()) +
                " waypoint(s); at least 2 are needed");
  }
  return true;
}

// ------------------------------------------------------------------------------------------------
// GridmapSimulator
// ------------------------------------------------------------------------------------------------

struct GridmapSimulator::Impl {
  explicit Impl(const GridmapSimulatorConfig& c)
      : config(c),
        laser_pose(c.laser_x, c.laser_y, c.laser_yaw),
        // Separate streams: the laser's draws never shift the odometry's, so a fault that changes
        // what the laser sees leaves the odometry noise as it was.
        laser_rng(seededEngine(c.seed, 1)),
        odometry_rng(seededEngine(c.seed, 2)),
        region_rng(seededEngine(c.seed, 3)) {}

  GridmapSimulatorConfig config;
  Pose2 laser_pose;
  mrpt::maps::COccupancyGridMap2D grid;
  std::vector<Eigen::Vector2d> waypoints;
  std::vector<DynamicObject> objects;
  std::vector<WorldRegion> regions;
  size_t next_waypoint = 1;
  bool loaded = false;

  std::mt19937_64 laser_rng;
  std::mt19937_64 odometry_rng;
  std::mt19937_64 region_rng;  // the regions' draws: the laser noise stays as without them
  std::normal_distribution<double> gaussian{0.0, 1.0};

  Pose2 truth;
  Pose2 odometry;
  Pose2 motion_since_scan;  // true motion (robot frame) since the last scan, kidnap excluded
  double command_v = 0.0, command_w = 0.0;
  uint64_t scans = 0;
  double clock = 0.0;
  bool route_done = false;
  bool finished = false;
  bool kidnap_done = false;

  exploration::OccupancyImage obstacles;
  uint64_t collisions = 0;
  bool in_contact = false;
  double blocked_for = 0.0;  // s the robot has been held by a wall without a break
  bool stuck = false;
  Eigen::Vector2d last_collision = Eigen::Vector2d::Zero();
  double last_collision_time = 0.0;

  // The obstacle cells, from the loaded grid (its cells are the image's pixels).
  void buildObstacles() {
    exploration::GridGeometry& g = obstacles.geometry;
    g.resolution = grid.getResolution();
    g.origin_x = grid.getXMin();
    g.origin_y = grid.getYMin();
    g.width = static_cast<int>(grid.getSizeX());
    g.height = static_cast<int>(grid.getSizeY());
    obstacles.occupied.assign(static_cast<size_t>(g.size()), 0);
    // getCell gives the probability of free space (1 = white); a ray stops at a cell at or below
    // 1 - occupied_threshold (castScan), and so does the robot.
    const float threshold_free = static_cast<float>(1.0 - config.occupied_threshold);
    for (int r = 0; r < g.height; ++r) {
      for (int c = 0; c < g.width; ++c) {
        obstacles.occupied[g.index(c, r)] = grid.getCell(c, r) <= threshold_free ? 1 : 0;
      }
    }
    // Glass and clutter stop the robot like walls: every cell whose centre lies within half a
    // cell of a region (so a thin pane still has cells).
    for (const WorldRegion& region : regions) {
      for (int i = 0; i < g.size(); ++i) {
        const Eigen::Vector2d centre(g.origin_x + (g.col(i) + 0.5) * g.resolution,
                                     g.origin_y + (g.row(i) + 0.5) * g.resolution);
        if (region.distanceTo(centre) <= 0.5 * g.resolution) obstacles.occupied[i] = 1;
      }
    }
  }

  // True when a disc of `radius` at `p` overlaps an obstacle cell (touching is not overlapping);
  // a point (radius 0) collides inside one. Outside the map there is nothing to hit.
  bool discHitsObstacle(const Eigen::Vector2d& p, double radius) const {
    const exploration::GridGeometry& g = obstacles.geometry;
    int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
    g.cellOf(p.x() - radius, p.y() - radius, &c0, &r0);
    g.cellOf(p.x() + radius, p.y() + radius, &c1, &r1);
    for (int r = std::max(r0, 0); r <= std::min(r1, g.height - 1); ++r) {
      for (int c = std::max(c0, 0); c <= std::min(c1, g.width - 1); ++c) {
        if (!obstacles.occupied[g.index(c, r)]) continue;
        const double x0 = g.origin_x + c * g.resolution, y0 = g.origin_y + r * g.resolution;
        const double dx = std::max({x0 - p.x(), 0.0, p.x() - (x0 + g.resolution)});
        const double dy = std::max({y0 - p.y(), 0.0, p.y() - (y0 + g.resolution)});
        if (radius == 0.0 ? dx == 0.0 && dy == 0.0 : dx * dx + dy * dy < radius * radius) {
          return true;
        }
      }
    }
    return false;
  }
  bool collides(const Pose2& pose) const {
    return discHitsObstacle(pose.translation(), config.robot_radius);
  }

  bool loadMap(std::string* error) {
    const std::string& path = config.map;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      *error = "map '" + path + "' does not exist or is not a file";
      return false;
    }
    const std::string ext = lowerExtension(path);
    bool ok = false;
    std::string detail;
    CerrCapture capture;
    try {
      if (ext == ".yaml" || ext == ".yml") {
        ok = grid.loadFromROSMapServerYAML(path);
      } else {
        mrpt::img::CImage image;
        if (image.loadFromFile(path, 0 /* grey */) && image.getWidth() > 1 &&
            image.getHeight() > 1) {
          // loadFromBitmap takes the origin as a pixel position (x right, y up). It only sizes
          // the grid when the image's size differs from the grid's, so start from one cell.
          grid.setSize(0.0, config.resolution, 0.0, config.resolution, config.resolution);
          mrpt::math::TPoint2D origin_pixel(image.getWidth() / 2.0, image.getHeight() / 2.0);
          if (!config.map_centered) {
            origin_pixel = {-config.origin_x / config.resolution,
                            -config.origin_y / config.resolution};
          }
          ok = grid.loadFromBitmap(image, static_cast<float>(config.resolution), origin_pixel);
        }
      }
    } catch (const std::exception& e) {
      ok = false;
      detail = oneLineMessage(e.what());
    }
    if (detail.empty()) detail = capture.message();
    if (!ok) {
      *error = "cannot load map '" + path + "' (" +
               (ext == ".yaml" || ext == ".yml" ? "not a readable map_server YAML with its image"
                                                : "not an image MRPT can read") +
               (detail.empty() ? std::string() : ": " + detail) + ")";
      return false;
    }
    return true;
  }

  bool load(std::string* error) {
    std::string why;
    if (!config.isValid(&why)) {
      *error = "invalid simulator configuration: " + why;
      return false;
    }
    if (!loadMap(error)) return false;
    if (!config.objects.empty() && !readDynamicObjects(config.objects, &objects, error, &regions)) {
      return false;
    }
    buildObstacles();
    if (!config.waypoints.empty()) {
      if (!readWaypoints(config.waypoints, &waypoints, error)) return false;
      // The run ends at the last waypoint: one far off the map would never be reached. Beyond a
      // wall, within the map's own size of its edges, the robot is held by the wall and stops.
      const double margin_x = grid.getXMax() - grid.getXMin();
      const double margin_y = grid.getYMax() - grid.getYMin();
      for (size_t i = 0; i < waypoints.size(); ++i) {
        const Eigen::Vector2d& w = waypoints[i];
        if (w.x() < grid.getXMin() - margin_x || w.x() > grid.getXMax() + margin_x ||
            w.y() < grid.getYMin() - margin_y || w.y() > grid.getYMax() + margin_y) {
          std::ostringstream why;
          why << "waypoint " << i + 1 << " of '" << config.waypoints << "' at (" << w.x() << ", "
              << w.y() << ") lies more than the map's size outside the map (x " << grid.getXMin()
              << " .. " << grid.getXMax() << ", y " << grid.getYMin() << " .. " << grid.getYMax()
              << " m)";
          *error = why.str();
          return false;
        }
      }
      const Eigen::Vector2d d = waypoints[1] - waypoints[0];
      truth = Pose2(waypoints[0].x(), waypoints[0].y(), std::atan2(d.y(), d.x()));
    } else {
      truth = Pose2(config.start_x, config.start_y, config.start_theta);
    }
    loaded = true;
    return true;
  }

  // Velocity toward the next waypoint; (0, 0) once the last one is reached.
  void waypointCommand(double dt, double* v, double* w) {
    *v = *w = 0.0;
    while (next_waypoint < waypoints.size()) {
      const Eigen::Vector2d to = waypoints[next_waypoint] - truth.translation();
      const double distance = to.norm();
      if (distance < config.waypoint_tolerance) {
        ++next_waypoint;
        continue;
      }
      const double error = normalizeAngle(std::atan2(to.y(), to.x()) - truth.theta);
      *w = std::clamp(kTurnGain * error, -config.angular_speed, config.angular_speed);
      if (std::abs(error) <= kDriveMaxHeadingError) {
        *v = std::min(config.linear_speed, distance / dt);
      }
      return;
    }
    route_done = true;
  }

  // The motion (robot frame) of driving (v, w) for dt from `truth`, stopped at contact when the
  // disc would run into an obstacle: the largest share of the step that stays clear, then the
  // rest of the step's turn in place (a disc turning about its centre hits nothing). A disc that
  // already overlaps an obstacle (after a kidnap into one) moves freely until it is clear.
  Pose2 motionWithCollisions(double v, double w, double dt, double now) {
    const Pose2 free_motion = unicycleIncrement(v, w, dt);
    const Pose2 free_end = truth.compose(free_motion);
    if (!collides(free_end) || collides(truth)) {
      blocked_for = 0.0;
      if (in_contact) {
        in_contact = discHitsObstacle(free_end.translation(), config.robot_radius + kContactMargin);
      }
      return free_motion;
    }
    double clear = 0.0, blocked = 1.0;
    for (int k = 0; k < kContactBisections; ++k) {
      const double mid = 0.5 * (clear + blocked);
      if (collides(truth.compose(unicycleIncrement(v, w, mid * dt)))) {
        blocked = mid;
      } else {
        clear = mid;
      }
    }
    if (!in_contact) {
      ++collisions;
      last_collision = truth.translation();
      last_collision_time = now;
    }
    in_contact = true;
    blocked_for += dt;
    return unicycleIncrement(v, w, clear * dt).compose(Pose2(0.0, 0.0, (1.0 - clear) * w * dt));
  }

  void drive(double duration) {
    const int substeps =
        std::max(1, static_cast<int>(std::ceil(duration / config.physics_period - 1e-9)));
    const double dt = duration / substeps;
    for (int i = 0; i < substeps; ++i) {
      double v = command_v, w = command_w;
      if (!waypoints.empty()) waypointCommand(dt, &v, &w);
      const Pose2 increment = motionWithCollisions(v, w, dt, clock + (i + 1) * dt);
      truth = truth.compose(increment);
      motion_since_scan = motion_since_scan.compose(increment);
      if (!waypoints.empty() && blocked_for >= kStuckTimeout - 1e-9) {
        stuck = true;
        route_done = true;
      }
    }
  }

  Pose2 noisyIncrement(const Pose2& truth_increment) {
    const double driven = std::hypot(truth_increment.x, truth_increment.y);
    const double sigma_xy = config.odometry_noise_xy * driven;
    const double sigma_theta = config.odometry_noise_theta * std::abs(truth_increment.theta) +
                               config.odometry_noise_theta_per_m * driven;
    // Three draws every time, whatever the sigmas: the stream stays aligned across configs.
    const double ex = gaussian(odometry_rng), ey = gaussian(odometry_rng);
    const double eth = gaussian(odometry_rng);
    return Pose2(truth_increment.x + sigma_xy * ex, truth_increment.y + sigma_xy * ey,
                 truth_increment.theta + sigma_theta * eth);
  }

  bool inMovingObjectWindow(double stamp, double bearing) const {
    return config.hasMovingObject() && stamp >= config.moving_object_start - 1e-9 &&
           stamp <= config.moving_object_end + 1e-9 &&
           bearing >= config.moving_object_bearing_min &&
           bearing <= config.moving_object_bearing_max;
  }

  LaserScan castScan(double stamp, bool* moving_object_seen, std::vector<int>* object_hit) {
    LaserScan scan;
    scan.stamp = stamp;
    scan.sensor_pose = laser_pose;
    scan.max_range = static_cast<float>(config.laser_max_range);
    scan.range_sigma = static_cast<float>(config.range_noise);
    const size_t n = static_cast<size_t>(config.laser_rays);
    scan.ranges.resize(n);
    scan.bearings.resize(n);
    scan.valid.resize(n);
    const Pose2 sensor = truth.compose(laser_pose);
    // MRPT 2.5's simulateScanRay counts max_range in cells while it steps
    // RAYTRACE_STEP_SIZE_IN_CELL_UNITS (0.8) cells per sample, so it stops at 0.8 × the range it
    // is given. Ask for more and cut at the real maximum here.
    const double step = mrpt::maps::COccupancyGridMap2D::RAYTRACE_STEP_SIZE_IN_CELL_UNITS;
    const double trace_range = config.laser_max_range / std::min(step, 1.0) + config.resolution;
    const float threshold_free = static_cast<float>(1.0 - config.occupied_threshold);
    *moving_object_seen = false;
    object_hit->assign(n, -1);
    for (size_t i = 0; i < n; ++i) {
      // Right to left, as MRPT's CObservation2DRangeScan (rightToLeft = true) numbers them.
      const double bearing =
          -0.5 * config.laser_aperture + config.laser_aperture * static_cast<double>(i) / (n - 1);
      // Two draws per ray, always (see noisyIncrement).
      const double direction_error = config.bearing_noise * gaussian(laser_rng);
      const double range_error = config.range_noise * gaussian(laser_rng);
      float range = 0.0f;
      bool valid = false;
      grid.simulateScanRay(sensor.x, sensor.y, sensor.theta + bearing + direction_error, range,
                           valid, trace_range, threshold_free, 0.0, 0.0);
      if (!objects.empty()) {
        const double a = sensor.theta + bearing + direction_error;
        double d = -1.0;
        const int k = nearestObjectHit(objects, stamp, Eigen::Vector2d(sensor.x, sensor.y),
                                       Eigen::Vector2d(std::cos(a), std::sin(a)), &d);
        if (k >= 0 && (!valid || d < range)) {
          range = static_cast<float>(d);
          valid = true;
          (*object_hit)[i] = k;
        }
      }
      if (!regions.empty()) {
        const double a = sensor.theta + bearing + direction_error;
        double d = 0.0;
        const double end = valid ? range : std::numeric_limits<double>::infinity();
        if (castThroughRegions(regions, Eigen::Vector2d(sensor.x, sensor.y),
                               Eigen::Vector2d(std::cos(a), std::sin(a)), end, &region_rng,
                               &d) >= 0) {
          range = static_cast<float>(d);
          valid = true;
          (*object_hit)[i] = -1;
        }
      }
      if (valid && range >= config.laser_max_range) {
        valid = false;
        (*object_hit)[i] = -1;
      }
      if (inMovingObjectWindow(stamp, bearing)) {
        range = static_cast<float>(config.moving_object_distance);
        valid = true;
        *moving_object_seen = true;
      }
      if (valid) {
        range = std::max(0.0f, range + static_cast<float>(range_error));
      } else {
        range = scan.max_range;
      }
      scan.bearings[i] = static_cast<float>(bearing);
      scan.ranges[i] = range;
      scan.valid[i] = valid ? 1 : 0;
    }
    return scan;
  }

  bool step(SimulatedScan* out) {
    if (!loaded || finished) return false;
    if (scans == 0) {
      clock = config.start_time;
    } else {
      if (route_done || (config.duration > 0.0 && config.start_time + scans * config.scan_period >
                                                      config.start_time + config.duration + 1e-9)) {
        finished = true;
        return false;
      }
      drive(config.scan_period);
      clock = config.start_time + scans * config.scan_period;  // no drift from summing
    }
    *out = SimulatedScan();
    out->stamp = clock;
    if (config.hasKidnap() && !kidnap_done && clock >= config.kidnap_time - 1e-9) {
      truth = Pose2(truth.x + config.kidnap_dx, truth.y + config.kidnap_dy,
                    truth.theta + config.kidnap_dtheta);
      kidnap_done = true;
      out->kidnapped = true;
    }
    out->odometry_increment = noisyIncrement(motion_since_scan);
    motion_since_scan = Pose2();
    odometry = odometry.compose(out->odometry_increment);
    out->odometry = odometry;
    out->true_pose = truth;
    out->collisions = collisions;
    out->in_contact = in_contact;
    out->scan = castScan(clock, &out->moving_object, &out->object_hit);
    ++scans;
    return true;
  }
};

GridmapSimulator::GridmapSimulator(const GridmapSimulatorConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

GridmapSimulator::~GridmapSimulator() = default;

bool GridmapSimulator::load(std::string* error) {
  std::string why;
  const bool ok = impl_->load(&why);
  if (!ok && error) *error = why;
  return ok;
}

void GridmapSimulator::setVelocityCommand(double linear, double angular) {
  const auto& c = impl_->config;
  impl_->command_v = finite(linear) ? std::clamp(linear, -c.linear_speed, c.linear_speed) : 0.0;
  impl_->command_w = finite(angular) ? std::clamp(angular, -c.angular_speed, c.angular_speed) : 0.0;
}

bool GridmapSimulator::step(SimulatedScan* out) { return impl_->step(out); }
bool GridmapSimulator::followsWaypoints() const { return !impl_->waypoints.empty(); }
bool GridmapSimulator::finished() const { return impl_->finished; }
uint64_t GridmapSimulator::collisions() const { return impl_->collisions; }
Eigen::Vector2d GridmapSimulator::lastCollisionPosition() const { return impl_->last_collision; }
double GridmapSimulator::lastCollisionTime() const { return impl_->last_collision_time; }
bool GridmapSimulator::stuck() const { return impl_->stuck; }
const exploration::OccupancyImage& GridmapSimulator::obstacles() const { return impl_->obstacles; }
double GridmapSimulator::now() const { return impl_->clock; }
Pose2 GridmapSimulator::truePose() const { return impl_->truth; }
const Pose2& GridmapSimulator::laserPose() const { return impl_->laser_pose; }
double GridmapSimulator::mapResolution() const { return impl_->grid.getResolution(); }
Eigen::Vector4d GridmapSimulator::mapBounds() const {
  const auto& g = impl_->grid;
  return {g.getXMin(), g.getYMin(), g.getXMax(), g.getYMax()};
}
const GridmapSimulatorConfig& GridmapSimulator::config() const { return impl_->config; }
const std::vector<DynamicObject>& GridmapSimulator::objects() const { return impl_->objects; }
const std::vector<WorldRegion>& GridmapSimulator::regions() const { return impl_->regions; }

// ------------------------------------------------------------------------------------------------
// SimulationRecorder
// ------------------------------------------------------------------------------------------------

std::string groundTruthPathFor(const std::string& rawlog_path) { return rawlog_path + ".GT.txt"; }

struct SimulationRecorder::Impl {
  mrpt::io::CFileGZOutputStream rawlog;
  std::ofstream truth;
  std::string rawlog_path, truth_path, label;
  AtomicFiles files;  // both files, under temporary names until close()
  std::string rawlog_temp;
  uint64_t written = 0;
  bool open = false;

  void abandon() {
    rawlog.close();
    truth.close();
    files.abandon();
    open = false;
  }
  // gzip output whose final flush failed is cut short: it must decompress to every byte written.
  bool rawlogReadsBack(uint64_t bytes) const {
    mrpt::io::CFileGZInputStream in;
    if (!in.open(rawlog_temp)) return false;
    std::vector<char> buffer(1 << 16);
    uint64_t total = 0;
    for (;;) {
      const size_t n = in.Read(buffer.data(), buffer.size());
      if (n > buffer.size()) return false;  // a zlib error
      if (n == 0) break;
      total += n;
    }
    return total == bytes;
  }
};

SimulationRecorder::SimulationRecorder() : impl_(std::make_unique<Impl>()) {}
SimulationRecorder::~SimulationRecorder() {
  if (impl_->open) impl_->abandon();
}

bool SimulationRecorder::open(const std::string& rawlog_path, const std::string& laser_label,
                              std::string* error) {
  Impl& d = *impl_;
  d.rawlog_path = rawlog_path;
  d.truth_path = groundTruthPathFor(rawlog_path);
  d.label = laser_label;
  std::string why, truth_temp;
  if (!d.files.reserve(rawlog_path, &d.rawlog_temp, &why) ||
      !d.files.reserve(d.truth_path, &truth_temp, &why)) {
    if (error) *error = why;
    return false;
  }
  bool opened = false;
  try {
    opened = d.rawlog.open(d.rawlog_temp, 1, why);
  } catch (const std::exception& e) {
    why = e.what();
  }
  if (!opened) {
    d.files.abandon();
    if (error) {
      *error = "cannot write rawlog '" + rawlog_path + "'" +
               (why.empty() ? "" : ": " + oneLineMessage(why));
    }
    return false;
  }
  d.truth.open(truth_temp, std::ios::trunc);
  if (!d.truth) {
    d.rawlog.close();
    d.files.abandon();
    if (error) *error = "cannot write ground truth '" + d.truth_path + "'";
    return false;
  }
  d.truth << std::fixed << std::setprecision(6);
  d.open = true;
  return true;
}

bool SimulationRecorder::write(const SimulatedScan& s, std::string* error) {
  Impl& d = *impl_;
  if (!d.open) {
    if (error) *error = "rawlog recorder is not open";
    return false;
  }
  const auto stamp = mrpt::Clock::fromDouble(s.stamp);

  mrpt::obs::CActionRobotMovement2D move;
  move.computeFromOdometry(toMrpt(s.odometry_increment),
                           mrpt::obs::CActionRobotMovement2D::TMotionModelOptions());
  move.timestamp = stamp;
  mrpt::obs::CActionCollection actions;
  actions.insert(move);

  auto obs = mrpt::obs::CObservation2DRangeScan::Create();
  obs->sensorLabel = d.label;
  obs->timestamp = stamp;
  obs->aperture = static_cast<float>(s.scan.bearings.back() - s.scan.bearings.front());
  obs->rightToLeft = true;
  obs->maxRange = s.scan.max_range;
  obs->stdError = s.scan.range_sigma;
  obs->sensorPose = mrpt::poses::CPose3D(toMrpt(s.scan.sensor_pose));
  obs->resizeScan(s.scan.size());
  for (size_t i = 0; i < s.scan.size(); ++i) {
    obs->setScanRange(i, s.scan.ranges[i]);
    obs->setScanRangeValidity(i, s.scan.valid[i] != 0);
  }
  mrpt::obs::CSensoryFrame frame;
  frame.insert(obs);

  errno = 0;  // what the failing write leaves here is the reason
  try {
    auto archive = mrpt::serialization::archiveFrom(d.rawlog);
    archive << actions << frame;
  } catch (const std::exception& e) {
    if (error) {
      *error = "cannot write rawlog '" + d.rawlog_path + "': " + oneLineMessage(e.what()) +
               (errno != 0 ? " (" + std::string(std::strerror(errno)) + ")" : "");
    }
    return false;
  }
  d.truth << s.stamp << ' ' << s.true_pose.x << ' ' << s.true_pose.y << ' ' << s.true_pose.theta
          << '\n';
  if (!d.truth) {
    if (error) *error = "cannot write ground truth '" + d.truth_path + "'";
    return false;
  }
  ++d.written;
  return true;
}

bool SimulationRecorder::close(std::string* error) {
  Impl& d = *impl_;
  if (!d.open) return true;
  const uint64_t bytes = d.rawlog.getPosition();
  d.rawlog.close();
  d.truth.close();
  d.open = false;
  if (!d.truth) {
    d.files.abandon();
    if (error) *error = "cannot finish ground truth '" + d.truth_path + "'";
    return false;
  }
  if (!d.rawlogReadsBack(bytes)) {
    d.files.abandon();
    if (error) *error = "cannot finish rawlog '" + d.rawlog_path + "' (disk full?)";
    return false;
  }
  return d.files.commit(error);
}

uint64_t SimulationRecorder::written() const { return impl_->written; }

bool simulateToRawlog(const GridmapSimulatorConfig& config, const std::string& rawlog_path,
                      SimulationSummary* summary, std::string* error,
                      const std::string& truth_scans_path) {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (config.waypoints.empty() && !(config.duration > 0.0)) {
    return fail("nothing would end the run: give waypoints or a duration");
  }
  GridmapSimulator simulator(config);
  std::string why;
  if (!simulator.load(&why)) return fail(why);
  SimulationRecorder recorder;
  if (!recorder.open(rawlog_path, config.laser_label, &why)) return fail(why);
  std::ofstream truth_scans;
  if (!truth_scans_path.empty()) {
    truth_scans.open(truth_scans_path);
    if (!truth_scans) return fail("cannot write truth scans '" + truth_scans_path + "'");
    truth_scans << std::setprecision(9);
  }
  SimulationSummary s;
  SimulatedScan scan;
  Pose2 previous_truth;
  Pose2 first_truth;
  while (simulator.step(&scan)) {
    if (!recorder.write(scan, &why)) return fail(why);
    if (s.scans == 0) {
      s.first_stamp = scan.stamp;
      first_truth = scan.true_pose;
    } else if (!scan.kidnapped) {
      s.path_length += (scan.true_pose.translation() - previous_truth.translation()).norm();
    }
    s.kidnapped = s.kidnapped || scan.kidnapped;
    s.moving_object_scans += scan.moving_object ? 1 : 0;
    s.object_scans +=
        std::any_of(scan.object_hit.begin(), scan.object_hit.end(), [](int k) { return k >= 0; })
            ? 1
            : 0;
    if (truth_scans.is_open()) {
      const Pose2& p = scan.true_pose;
      const Pose2& l = scan.scan.sensor_pose;
      truth_scans << scan.stamp << ' ' << p.x << ' ' << p.y << ' ' << p.theta << ' ' << l.x << ' '
                  << l.y << ' ' << l.theta << ' ' << scan.scan.size();
      for (size_t i = 0; i < scan.scan.size(); ++i) {
        truth_scans << ' ' << (scan.scan.valid[i] ? scan.scan.ranges[i] : 0.0f);
      }
      for (int k : scan.object_hit) truth_scans << ' ' << k;
      truth_scans << '\n';
    }
    previous_truth = scan.true_pose;
    s.last_stamp = scan.stamp;
    ++s.scans;
    // The odometry frame is the truth's at the first scan.
    s.odometry_error =
        (first_truth.compose(scan.odometry).translation() - scan.true_pose.translation()).norm();
  }
  if (!recorder.close(&why)) return fail(why);
  if (truth_scans.is_open() && !truth_scans.flush()) {
    return fail("cannot write truth scans '" + truth_scans_path + "'");
  }
  s.collisions = simulator.collisions();
  s.stuck = simulator.stuck();
  if (summary) *summary = s;
  return true;
}

}  // namespace io
}  // namespace evidential_slam
