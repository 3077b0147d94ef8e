// A planar robot simulated on an occupancy-grid image, in the spirit of MRPT's GridmapNavSimul: a
// differential-drive robot follows a waypoint file (or velocity commands), a laser is ray-cast on
// the map (MRPT's COccupancyGridMap2D::simulateScanRay) with range and bearing noise, the odometry
// is the true motion plus noise, and two faults can be injected (a kidnap, a moving object). One
// seed fixes the whole run. Results are core types; SimulationRecorder writes them as an MRPT
// rawlog plus a GridmapNavSimul-style ground truth, so one run feeds both the offline runner and
// (through src/ros/gridmap_simulator_main.cpp) ROS. MRPT stays in the .cpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <istream>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/exploration/coverage.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/io/dynamic_objects.h"

namespace evidential_slam {
namespace io {

// Every field is also a ROS private parameter of gridmap_simulator (same name) and a command-line
// option of evidential_slam_simulate (--name, '_' written '-'); gridmapSimulatorFields() lists them
// with their help text. Times are on the simulation clock (s), which starts at start_time.
struct GridmapSimulatorConfig {
  // --- map ---
  std::string map;                  // image (PNG, PGM...: black = wall) or map_server .yaml
  double resolution = 0.05;         // m per pixel (image only; a .yaml brings its own)
  bool map_centered = true;         // image centre at the map origin (else origin_x/origin_y)
  double origin_x = 0.0;            // m, map position of the image's lower-left corner
  double origin_y = 0.0;            // (map_server convention; used when !map_centered)
  double occupied_threshold = 0.6;  // a cell at least this occupied (1 = black) stops a ray

  // --- route and robot ---
  std::string waypoints;  // `x y` per line; empty = velocity commands (cmd_vel)
  double start_x = 0.0;   // start pose without waypoints (m, m, rad); with waypoints
  double start_y = 0.0;   // the robot starts on the first one, facing the second
  double start_theta = 0.0;
  double linear_speed = 0.5;        // m/s, forward speed limit
  double angular_speed = 0.8;       // rad/s, turn rate limit
  double waypoint_tolerance = 0.1;  // m, a waypoint closer than this is reached
  // m; the robot is a disc this wide: a motion that would take it into an occupied cell stops at
  // contact (its turn goes on) and counts as a collision. 0: a point.
  double robot_radius = 0.2;
  double duration = 0.0;            // s of simulation at most; 0 = until the last waypoint
  double start_time = 1.0;          // s, clock at the first scan (> 0: 0 means "unset" in ROS)
  double scan_period = 0.1;         // s between scans (and odometry increments)
  double physics_period = 0.01;     // s, kinematics integration step

  // --- laser ---
  std::string laser_label = "LASER_SIM";  // sensor label in the rawlog
  int laser_rays = 361;
  double laser_aperture = M_PI;   // rad, centred on the laser's x axis, rays right to left
  double laser_max_range = 30.0;  // m; nothing within it = "no return"
  double laser_x = 0.2;           // laser pose on the robot (m, m, rad)
  double laser_y = 0.0;
  double laser_yaw = 0.0;
  double range_noise = 0.01;   // m, 1-sigma Gaussian added to each return (rawlog stdError)
  double bearing_noise = 0.0;  // rad, 1-sigma of the direction a ray is really cast in

  // --- odometry: each increment between scans (robot frame) gets zero-mean Gaussian errors ---
  double odometry_noise_xy = 0.02;           // m per m driven: sigma of the x and y error
  double odometry_noise_theta = 0.02;        // rad per rad turned: sigma of the heading error...
  double odometry_noise_theta_per_m = 0.01;  // ...plus rad per m driven
  int seed = 1;                              // one seed for the laser and odometry noise

  // --- faults ---
  double kidnap_time = -1.0;  // s; < 0 = none. The true pose jumps before the first scan at or
  double kidnap_dx = 0.0;     // after it by (dx, dy) m and dtheta rad in the map frame; the
  double kidnap_dy = 0.0;     // odometry does not see it
  double kidnap_dtheta = 0.0;
  double moving_object_start = -1.0;       // s; < 0 = none. Scans stamped in [start, end] read
  double moving_object_end = -1.0;         // moving_object_distance (+ range noise) on every
  double moving_object_bearing_min = 0.0;  // ray whose bearing (rad, laser frame) lies in
  double moving_object_bearing_max = 0.0;  // [bearing_min, bearing_max]
  double moving_object_distance = 1.0;     // m
  // Objects file (dynamic_objects.h): people, boxes, doors in the world frame, and regions of
  // glass and clutter (world_regions.h); "" = none.
  std::string objects;

  bool hasKidnap() const { return kidnap_time >= 0.0; }
  bool hasMovingObject() const { return moving_object_start >= 0.0; }
  // False (and a one-line `why`) for values the simulator cannot run with. Files are checked by
  // GridmapSimulator::load().
  bool isValid(std::string* why) const;
};

// The field list behind the ROS parameters and the command-line options.
struct GridmapSimulatorField {
  const char* name;  // ROS parameter name
  std::variant<std::string*, double*, int*, bool*> value;
  const char* help;  // unit and meaning, one line
};
std::vector<GridmapSimulatorField> gridmapSimulatorFields(GridmapSimulatorConfig* config);

// Reads a waypoint file: one `x y` pair (m, map frame) per line; blank lines and text after '#'
// are ignored. False (and a one-line `error` naming the file and line) on a missing file, a line
// that is not two finite numbers, or fewer than two waypoints.
bool readWaypoints(const std::string& path, std::vector<Eigen::Vector2d>* waypoints,
                   std::string* error);
// The same from a stream; `name` stands for the file in messages.
bool readWaypoints(std::istream& in, const std::string& name,
                   std::vector<Eigen::Vector2d>* waypoints, std::string* error);

// One simulated scan and what is true at its stamp.
struct SimulatedScan {
  double stamp = 0.0;
  Pose2 true_pose;           // robot, in the map frame of the image
  Pose2 odometry;            // odom frame: the identity at the first scan
  Pose2 odometry_increment;  // since the previous scan, in the previous odometry pose's frame
  LaserScan scan;            // bearings right to left, valid = 0 for "no return"
  bool kidnapped = false;    // the kidnap happened just before this scan
  bool moving_object = false;
  // Per ray, the index of the object (config.objects) it ended on, -1 for a wall, a glass or
  // clutter region, or no return.
  std::vector<int> object_hit;
  uint64_t collisions = 0;  // collisions so far: each time the robot's disc ran into a wall
  bool in_contact = false;  // a wall stopped the robot and it has not moved 1 cm away since
};

class GridmapSimulator {
 public:
  explicit GridmapSimulator(const GridmapSimulatorConfig& config);
  ~GridmapSimulator();
  GridmapSimulator(const GridmapSimulator&) = delete;
  GridmapSimulator& operator=(const GridmapSimulator&) = delete;

  // Checks the config and loads the map and the waypoints. False with a one-line `error`.
  bool load(std::string* error);

  // The velocity command (m/s, rad/s; clamped to the speed limits) followed without waypoints.
  void setVelocityCommand(double linear, double angular);

  // The first call returns the scan at start_time (before any motion); each later call drives
  // one scan_period and returns the scan at its end. False once the run is over: the last
  // waypoint is reached or `duration` has passed (never without waypoints and duration).
  bool step(SimulatedScan* out);

  bool followsWaypoints() const;
  bool finished() const;
  // Collisions so far: each time a motion was stopped at a wall, unless the robot had been
  // stopped before and not moved 1 cm away from every wall since (pushing on counts once).
  uint64_t collisions() const;
  // Where the last collision happened (true robot position, map frame) and when.
  Eigen::Vector2d lastCollisionPosition() const;
  double lastCollisionTime() const;
  // A waypoint route ends early when a wall has held the robot for 5 s (it would never arrive).
  bool stuck() const;
  double now() const;              // simulation clock (s)
  Pose2 truePose() const;          // map frame
  const Pose2& laserPose() const;  // on the robot
  double mapResolution() const;    // m per cell, as loaded
  // Corners of the loaded map (m, map frame): min x, min y, max x, max y.
  Eigen::Vector4d mapBounds() const;
  // The loaded map's obstacles (cells at least occupied_threshold occupied), map frame: what
  // stops rays and the robot, and the ground truth of exploration coverage.
  const exploration::OccupancyImage& obstacles() const;
  const GridmapSimulatorConfig& config() const;
  // What the objects file holds (empty before load() or without one).
  const std::vector<DynamicObject>& objects() const;
  const std::vector<WorldRegion>& regions() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The ground-truth file written beside a rawlog, the name MRPT's datasets use: <rawlog>.GT.txt.
std::string groundTruthPathFor(const std::string& rawlog_path);

// Writes simulated scans as an MRPT rawlog in the Actions/SensoryFrame format (per scan: a
// CActionRobotMovement2D odometry increment, then a CSensoryFrame with one
// CObservation2DRangeScan labelled config.laser_label, stdError = range_noise), gzip-compressed
// like GridmapNavSimul's, and the true pose of each scan as `t x y phi` lines in <rawlog>.GT.txt.
class SimulationRecorder {
 public:
  SimulationRecorder();
  ~SimulationRecorder();
  SimulationRecorder(const SimulationRecorder&) = delete;
  SimulationRecorder& operator=(const SimulationRecorder&) = delete;

  // Starts both files under temporary names beside them; false with a one-line `error` when they
  // cannot be written.
  bool open(const std::string& rawlog_path, const std::string& laser_label, std::string* error);
  bool write(const SimulatedScan& scan, std::string* error);
  // Finishes both files, checks the rawlog reads back, syncs them and renames them into place
  // (atomic_files.h). A recorder destroyed before close(), or a close() that fails, leaves any old
  // files of those names as they were and no temporary files.
  bool close(std::string* error);
  uint64_t written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Result of a whole run into a rawlog.
struct SimulationSummary {
  uint64_t scans = 0;
  double first_stamp = 0.0;
  double last_stamp = 0.0;
  double path_length = 0.0;          // m driven (truth, kidnap jump excluded)
  double odometry_error = 0.0;       // m, |odometry - aligned truth| at the last scan
  bool kidnapped = false;            // the kidnap happened (it may come after the end)
  uint64_t moving_object_scans = 0;  // scans that saw the moving object
  uint64_t object_scans = 0;         // scans with a ray ending on an object (config.objects)
  uint64_t collisions = 0;           // GridmapSimulator::collisions()
  bool stuck = false;                // the route ended early, held by a wall
};

// Runs `config` to the end into `rawlog_path` and its ground truth. False with a one-line error.
// With `truth_scans_path`, also writes there per scan one line: stamp, true robot pose (x y phi),
// laser pose on the robot (x y yaw), ray count n, n ranges (m, 0 = no return), then n object
// indices (-1 = a wall): what scoring a run against the truth needs without reading the rawlog.
bool simulateToRawlog(const GridmapSimulatorConfig& config, const std::string& rawlog_path,
                      SimulationSummary* summary, std::string* error,
                      const std::string& truth_scans_path = "");

}  // namespace io
}  // namespace evidential_slam
