// The grid-map simulator (io/gridmap_simulator.h) and its command line (io/simulate_args.h): laser
// ranges against analytic distances in a synthetic room, odometry against the truth, the two
// faults against an unfaulted run with the same seed, the rawlog read back through RawlogReader,
// collisions of the robot's disc with the walls, and clear one-line errors on bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/io/simulate_args.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

using io::GridmapSimulator;
using io::GridmapSimulatorConfig;
using io::SimulatedScan;
namespace fs = std::filesystem;

constexpr double kResolution = 0.05;
constexpr int kRoomPixels = 200;  // 10 m x 10 m, centred: the map spans -5..5 m
constexpr int kWallPixels = 4;    // inner wall faces at +-4.8 m
constexpr double kInnerWall = 0.5 * kRoomPixels * kResolution - kWallPixels * kResolution;

// A square room as a binary PGM: white inside, a black border kWallPixels thick.
std::string writeRoom(const fs::path& dir) {
  const fs::path path = dir / "room.pgm";
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << kRoomPixels << " " << kRoomPixels << "\n255\n";
  for (int r = 0; r < kRoomPixels; ++r) {
    for (int c = 0; c < kRoomPixels; ++c) {
      const bool wall = r < kWallPixels || c < kWallPixels || r >= kRoomPixels - kWallPixels ||
                        c >= kRoomPixels - kWallPixels;
      out.put(static_cast<char>(wall ? 0 : 255));
    }
  }
  return path.string();
}

std::string writeWaypoints(const fs::path& dir, const std::string& text) {
  const fs::path path = dir / "waypoints.txt";
  test::writeText(path, text);
  return path.string();
}

// Room, cmd_vel mode, no noise at all.
GridmapSimulatorConfig roomConfig(const fs::path& dir) {
  GridmapSimulatorConfig c;
  c.map = writeRoom(dir);
  c.resolution = kResolution;
  c.range_noise = 0.0;
  c.bearing_noise = 0.0;
  c.odometry_noise_xy = c.odometry_noise_theta = c.odometry_noise_theta_per_m = 0.0;
  return c;
}

// Distance from (x, y) along `direction` to the room's inner wall faces.
double distanceToRoomWall(double x, double y, double direction) {
  const double cx = std::cos(direction), sy = std::sin(direction);
  double t = 1e9;
  if (cx > 1e-9) t = std::min(t, (kInnerWall - x) / cx);
  if (cx < -1e-9) t = std::min(t, (-kInnerWall - x) / cx);
  if (sy > 1e-9) t = std::min(t, (kInnerWall - y) / sy);
  if (sy < -1e-9) t = std::min(t, (-kInnerWall - y) / sy);
  return t;
}

std::vector<SimulatedScan> runAll(const GridmapSimulatorConfig& config, size_t max_scans,
                                  double v = 0.0, double w = 0.0) {
  GridmapSimulator sim(config);
  std::string error;
  EXPECT_TRUE(sim.load(&error)) << error;
  sim.setVelocityCommand(v, w);
  std::vector<SimulatedScan> scans;
  SimulatedScan s;
  while (scans.size() < max_scans && sim.step(&s)) scans.push_back(s);
  return scans;
}

void expectPoseNear(const Pose2& a, const Pose2& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(normalizeAngle(a.theta - b.theta), 0.0, tolerance);
}

TEST(GridmapSimulator, RangesMatchTheAnalyticDistanceToTheWalls) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.range_noise = 0.01;
  c.laser_x = 0.3;  // the laser's mounting must be applied
  c.start_x = -1.0;
  c.start_y = 0.5;
  c.start_theta = 0.4;
  GridmapSimulator sim(c);
  std::string error;
  ASSERT_TRUE(sim.load(&error)) << error;
  const Eigen::Vector4d bounds = sim.mapBounds();
  EXPECT_NEAR(bounds[0], -5.0, 1e-6);
  EXPECT_NEAR(bounds[3], 5.0, 1e-6);
  SimulatedScan s;
  ASSERT_TRUE(sim.step(&s));
  ASSERT_EQ(s.scan.size(), 361u);
  EXPECT_DOUBLE_EQ(s.stamp, c.start_time);
  EXPECT_FLOAT_EQ(s.scan.range_sigma, 0.01f);
  EXPECT_NEAR(s.scan.bearings.front(), -M_PI / 2, 1e-6);
  EXPECT_NEAR(s.scan.bearings.back(), M_PI / 2, 1e-6);
  const Pose2 sensor = Pose2(-1.0, 0.5, 0.4).compose(Pose2(0.3, 0.0, 0.0));
  double sum = 0.0;
  for (size_t i = 0; i < s.scan.size(); ++i) {
    const double expected =
        distanceToRoomWall(sensor.x, sensor.y, sensor.theta + s.scan.bearings[i]);
    ASSERT_TRUE(s.scan.valid[i]) << "ray " << i;
    // Noise (4 sigma) plus MRPT's ray casting, which samples every 0.8 cell along the ray.
    EXPECT_NEAR(s.scan.ranges[i], expected, 4 * 0.01 + kResolution) << "ray " << i;
    sum += s.scan.ranges[i] - expected;
  }
  // The casting stops at the first sample inside the wall: on average it overshoots by about half a
  // sampling step, never by more than a cell.
  const double bias = sum / s.scan.size();
  EXPECT_GT(bias, 0.0);
  EXPECT_LT(bias, kResolution);
}

TEST(GridmapSimulator, RaysBeyondMaxRangeAreNoReturnAndCloserOnesHit) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.laser_x = 0.0;
  c.start_x = 3.5;
  c.laser_max_range = 3.0;
  const auto scans = runAll(c, 1);
  ASSERT_EQ(scans.size(), 1u);
  const LaserScan& s = scans[0].scan;
  size_t checked_near_limit = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    const double expected = distanceToRoomWall(3.5, 0.0, s.bearings[i]);
    if (expected < 2.9) {
      EXPECT_TRUE(s.valid[i]) << "ray " << i << " at " << expected << " m";
      EXPECT_NEAR(s.ranges[i], expected, kResolution);
      checked_near_limit += expected > 2.5;  // beyond MRPT's own 0.8 x max_range cut
    } else if (expected > 3.1) {
      EXPECT_FALSE(s.valid[i]) << "ray " << i << " at " << expected << " m";
    }
  }
  EXPECT_GT(checked_near_limit, 5u);
}

TEST(GridmapSimulator, NoiselessOdometryEqualsTheTruthAlongAWaypointRoute) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.waypoints = writeWaypoints(dir,
                               "# a square, then back to the middle\n"
                               "-3 -3\n3 -3   # first leg\n\n3 3\n-3 3\n0 0\n");
  const auto scans = runAll(c, 100000);
  ASSERT_GT(scans.size(), 100u);
  const Pose2 start = scans.front().true_pose;
  EXPECT_NEAR(start.x, -3.0, 1e-9);
  EXPECT_NEAR(start.y, -3.0, 1e-9);
  EXPECT_NEAR(start.theta, 0.0, 1e-9);
  for (size_t i = 0; i < scans.size(); ++i) {
    EXPECT_NEAR(scans[i].stamp, c.start_time + i * c.scan_period, 1e-9);
    expectPoseNear(scans[i].odometry, start.between(scans[i].true_pose), 1e-9);
  }
  // It got to the last waypoint, then stopped, within the speed limits.
  EXPECT_LT(scans.back().true_pose.translation().norm(), c.waypoint_tolerance);
  for (size_t i = 1; i < scans.size(); ++i) {
    const double moved =
        (scans[i].true_pose.translation() - scans[i - 1].true_pose.translation()).norm();
    EXPECT_LE(moved, c.linear_speed * c.scan_period + 1e-9);
  }
  // Three 6 m legs and the 4.24 m diagonal (less the waypoint tolerances) at 0.5 m/s, plus four
  // turns of at most 135 degrees at 0.8 rad/s.
  const double took = scans.back().stamp - scans.front().stamp;
  EXPECT_GT(took, 21.8 / c.linear_speed);
  EXPECT_LT(took, 22.3 / c.linear_speed + 4 * 3.0);
}

TEST(GridmapSimulator, NoisyOdometryDriftsAndTheSeedFixesIt) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.odometry_noise_xy = 0.05;
  c.odometry_noise_theta = 0.05;
  c.odometry_noise_theta_per_m = 0.05;
  c.range_noise = 0.02;
  const auto a = runAll(c, 200, 0.3, 0.1);
  const auto b = runAll(c, 200, 0.3, 0.1);
  c.seed = 2;
  const auto other = runAll(c, 200, 0.3, 0.1);
  ASSERT_EQ(a.size(), 200u);
  ASSERT_EQ(other.size(), 200u);
  const Pose2 start = a.front().true_pose;
  const double drift =
      (a.back().odometry.translation() - start.between(a.back().true_pose).translation()).norm();
  EXPECT_GT(drift, 1e-3);
  for (size_t i = 0; i < a.size(); ++i) {
    expectPoseNear(a[i].odometry, b[i].odometry, 0.0);
    EXPECT_EQ(a[i].scan.ranges, b[i].scan.ranges);
  }
  EXPECT_NE(a.back().odometry.x, other.back().odometry.x);
  EXPECT_NE(a.back().scan.ranges, other.back().scan.ranges);
}

TEST(GridmapSimulator, KidnapMovesTheTruthButNotTheOdometry) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.odometry_noise_xy = 0.02;  // with noise: both runs must draw the same odometry errors
  c.range_noise = 0.01;
  const auto plain = runAll(c, 80, 0.3, 0.05);
  c.kidnap_time = c.start_time + 3.05;  // between two scans: the jump comes before the next one
  c.kidnap_dx = 0.5;
  c.kidnap_dy = -0.4;
  c.kidnap_dtheta = 0.3;
  const auto kidnapped = runAll(c, 80, 0.3, 0.05);
  ASSERT_EQ(plain.size(), 80u);
  ASSERT_EQ(kidnapped.size(), 80u);
  size_t kidnap_scans = 0;
  for (size_t i = 0; i < plain.size(); ++i) {
    expectPoseNear(kidnapped[i].odometry, plain[i].odometry, 0.0);
    const bool after = kidnapped[i].stamp >= c.kidnap_time;
    const bool first_after = after && i > 0 && kidnapped[i - 1].stamp < c.kidnap_time;
    EXPECT_EQ(kidnapped[i].kidnapped, first_after) << i;
    if (!after) {
      expectPoseNear(kidnapped[i].true_pose, plain[i].true_pose, 0.0);
      EXPECT_EQ(kidnapped[i].scan.ranges, plain[i].scan.ranges);
    } else if (kidnapped[i].kidnapped) {
      ++kidnap_scans;
      const Pose2& p = plain[i].true_pose;
      expectPoseNear(kidnapped[i].true_pose, Pose2(p.x + 0.5, p.y - 0.4, p.theta + 0.3), 1e-9);
      EXPECT_NE(kidnapped[i].scan.ranges, plain[i].scan.ranges);
    }
  }
  EXPECT_EQ(kidnap_scans, 1u);
  EXPECT_NEAR(kidnapped[31].stamp, c.start_time + 3.1, 1e-9);
  EXPECT_TRUE(kidnapped[31].kidnapped);
}

TEST(GridmapSimulator, MovingObjectReplacesExactlyTheBearingWindowDuringItsInterval) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.range_noise = 0.01;
  c.laser_rays = 181;  // 1 degree apart
  const auto plain = runAll(c, 40, 0.2, 0.1);
  c.moving_object_start = c.start_time + 1.0;
  c.moving_object_end = c.start_time + 2.0;
  c.moving_object_bearing_min = -0.2;  // rays between -11 and +11 degrees: 23 of them
  c.moving_object_bearing_max = 0.2;
  c.moving_object_distance = 0.8;
  const auto with_object = runAll(c, 40, 0.2, 0.1);
  ASSERT_EQ(with_object.size(), 40u);
  size_t scans_with_object = 0;
  for (size_t i = 0; i < plain.size(); ++i) {
    const double t = with_object[i].stamp;
    const bool during = t >= c.moving_object_start - 1e-9 && t <= c.moving_object_end + 1e-9;
    EXPECT_EQ(with_object[i].moving_object, during) << i;
    scans_with_object += during;
    expectPoseNear(with_object[i].true_pose, plain[i].true_pose, 0.0);
    size_t replaced = 0;
    const LaserScan& s = with_object[i].scan;
    for (size_t k = 0; k < s.size(); ++k) {
      const bool in_window = s.bearings[k] >= -0.2 && s.bearings[k] <= 0.2;
      if (during && in_window) {
        ++replaced;
        EXPECT_TRUE(s.valid[k]);
        EXPECT_NEAR(s.ranges[k], 0.8, 4 * 0.01) << "scan " << i << " ray " << k;
      } else {
        EXPECT_EQ(s.ranges[k], plain[i].scan.ranges[k]) << "scan " << i << " ray " << k;
        EXPECT_EQ(s.valid[k], plain[i].scan.valid[k]);
      }
    }
    EXPECT_EQ(replaced, during ? 23u : 0u) << i;
  }
  EXPECT_EQ(scans_with_object, 11u);  // 1.0, 1.1, ..., 2.0 s after the start
}

TEST(GridmapSimulator, WorldObjectsStopRaysWhilePresentAndNameTheRaysTheyStop) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.laser_rays = 181;
  c.laser_x = 0.0;
  // A disc of radius 0.5 crossing from (2, -3) to (2, 3) during [1.5, 2.5] s, at (2, 0), dead
  // ahead of the robot (at the origin, facing +x), at 2.0 s; and a bar (a door panel) along y = 3
  // from x = -1 to 1, 0.1 m thick, present until 1.2 s.
  const fs::path objects = dir / "objects.txt";
  test::writeText(objects,
                  "# person, door\n"
                  "disc 1.5 2.5 2 -3 2 3 0.5\n"
                  "bar 0 1.2 -1 3 1 3 0.05\n");
  c.objects = objects.string();
  const auto scans = runAll(c, 20);  // stamps 1.0, 1.1, ..., 2.9 s
  ASSERT_EQ(scans.size(), 20u);
  for (const SimulatedScan& s : scans) {
    ASSERT_EQ(s.object_hit.size(), 181u);
    const size_t ahead = 90, left = 180;  // bearing 0 and +90 degrees
    const bool disc_ahead = std::abs(s.stamp - 2.0) < 1e-6;
    if (disc_ahead) {
      EXPECT_EQ(s.object_hit[ahead], 0);
      EXPECT_NEAR(s.scan.ranges[ahead], 1.5, 1e-5);  // the disc's near side
    } else if (s.stamp < 1.5 - 1e-6 || s.stamp > 2.5 + 1e-6) {
      EXPECT_EQ(s.object_hit[ahead], -1) << s.stamp;
      EXPECT_NEAR(s.scan.ranges[ahead], kInnerWall, kResolution) << s.stamp;
    }
    if (s.stamp <= 1.2 + 1e-6) {
      EXPECT_EQ(s.object_hit[left], 1) << s.stamp;
      EXPECT_NEAR(s.scan.ranges[left], 2.95, 1e-5) << s.stamp;
    } else {
      EXPECT_EQ(s.object_hit[left], -1) << s.stamp;
      EXPECT_NEAR(s.scan.ranges[left], kInnerWall, kResolution) << s.stamp;
    }
  }
  // Rays not stopped by an object read as they would without the file.
  GridmapSimulatorConfig none = c;
  none.objects.clear();
  const auto plain = runAll(none, 20);
  for (size_t i = 0; i < scans.size(); ++i) {
    for (size_t k = 0; k < 181; ++k) {
      if (scans[i].object_hit[k] < 0) {
        EXPECT_EQ(scans[i].scan.ranges[k], plain[i].scan.ranges[k]);
      }
    }
  }
}

TEST(GridmapSimulator, ABadObjectsFileGivesAOneLineErrorNamingTheLine) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  const fs::path objects = dir / "objects.txt";
  test::writeText(objects, "disc 0 1 0 0 1 1 0.3\nbox 0 1 0 0 1 1 0.3\n");
  c.objects = objects.string();
  GridmapSimulator sim(c);
  std::string error;
  EXPECT_FALSE(sim.load(&error));
  EXPECT_NE(error.find("line 2"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  test::writeText(objects, "disc 2 1 0 0 1 1 0.3\n");  // ends before it starts
  GridmapSimulator sim2(c);
  EXPECT_FALSE(sim2.load(&error));
  EXPECT_NE(error.find("line 1"), std::string::npos) << error;
}

TEST(GridmapSimulator, GlassPassesEachBeamWithItsProbabilityAndReturnsTheRestAtItsFace) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.laser_rays = 181;
  c.laser_x = 0.0;
  // A pane 0.1 m thick along x = 2, |y| <= 3, ahead of the robot at the origin: every ray within
  // 55 degrees of ahead crosses it (atan(3 / 2.05) = 55.7 degrees).
  const fs::path objects = dir / "objects.txt";
  for (const double p : {0.3, 0.8}) {
    std::ostringstream text;
    text << "glass 2 -3 2 3 0.05 " << p << "\n";
    test::writeText(objects, text.str());
    c.objects = objects.string();
    const auto scans = runAll(c, 60);
    ASSERT_EQ(scans.size(), 60u);
    size_t passed = 0, returned = 0;
    for (const SimulatedScan& s : scans) {
      for (size_t k = 0; k < s.scan.ranges.size(); ++k) {
        const double b = s.scan.bearings[k];
        if (std::abs(b) > 55.0 * M_PI / 180.0) continue;
        ASSERT_TRUE(s.scan.valid[k]);
        if (std::abs(s.scan.ranges[k] - 1.95 / std::cos(b)) < 1e-3) {
          ++returned;
        } else {
          EXPECT_NEAR(s.scan.ranges[k], distanceToRoomWall(0, 0, b), kResolution);
          ++passed;
        }
      }
    }
    // 60 scans x 111 rays: the binomial's sigma is below 0.006.
    const double fraction = static_cast<double>(passed) / static_cast<double>(passed + returned);
    EXPECT_EQ(passed + returned, 60u * 111u);
    EXPECT_NEAR(fraction, p, 0.025) << "pass probability " << p;
  }
}

TEST(GridmapSimulator, ClutterReturnsBeamsWithItsRangeScatterAndStopsTheRobot) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.laser_rays = 181;
  c.laser_x = 0.0;
  // Clutter round x = 2.5, |y| <= 1, 0.5 m deep on either side: its face is x = 2 for |y| <= 1.
  const fs::path objects = dir / "objects.txt";
  test::writeText(objects, "clutter 2.5 -1 2.5 1 0.5 0.2\n");
  c.objects = objects.string();
  const auto scans = runAll(c, 60);
  double sum = 0.0, sum2 = 0.0;
  size_t n = 0;
  for (const SimulatedScan& s : scans) {
    for (size_t k = 0; k < s.scan.ranges.size(); ++k) {
      const double b = s.scan.bearings[k];
      if (std::abs(2.0 * std::tan(b)) > 0.9) continue;  // rays meeting the flat face
      const double e = s.scan.ranges[k] - 2.0 / std::cos(b);
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  ASSERT_GT(n, 1000u);
  const double mean = sum / n, stddev = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.02);
  EXPECT_NEAR(stddev, 0.2, 0.02);
  // The robot (radius 0.2) driving ahead stops at the clutter: one collision, at x = 1.8.
  GridmapSimulator sim(c);
  std::string error;
  ASSERT_TRUE(sim.load(&error)) << error;
  sim.setVelocityCommand(0.5, 0.0);
  SimulatedScan s;
  for (int i = 0; i < 100 && sim.step(&s); ++i) {
  }
  EXPECT_EQ(sim.collisions(), 1u);
  EXPECT_NEAR(sim.truePose().x, 2.0 - kResolution / 2 - c.robot_radius, kResolution);
  ASSERT_EQ(sim.regions().size(), 1u);
  EXPECT_EQ(sim.regions()[0].kind, io::RegionKind::kClutter);
}

TEST(GridmapSimulator, ABadRegionLineGivesAOneLineErrorNamingTheLine) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  const fs::path objects = dir / "objects.txt";
  c.objects = objects.string();
  for (const char* text : {"glass 0 0 1 1 0.1 1.5\n",     // pass probability above 1
                           "glass 0 0 1 1 0.1\n",         // no probability
                           "clutter 0 0 1 1 0.1 0\n",     // no scatter
                           "clutter 0 0 1 1 -0.1 0.2\n",  // negative radius
                           "glass 0 0 1 1 0.1 0.5 7\n"}) {
    test::writeText(objects, std::string("disc 0 1 0 0 1 1 0.3\n") + text);
    GridmapSimulator sim(c);
    std::string error;
    EXPECT_FALSE(sim.load(&error)) << text;
    EXPECT_NE(error.find("line 2"), std::string::npos) << error;
    EXPECT_NE(error.find(std::string(text).substr(0, 5)), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

TEST(GridmapSimulator, TruthScansFileHoldsPosesRangesAndObjectHits) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.laser_rays = 5;
  c.duration = 0.35;  // scans at 1.0 .. 1.3 s
  const fs::path objects = dir / "objects.txt";
  test::writeText(objects, "disc 0 100 2 0 2 0 0.5\n");
  c.objects = objects.string();
  const std::string rawlog = (dir / "sim.rawlog").string();
  const std::string truth = (dir / "sim.scans.txt").string();
  io::SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(io::simulateToRawlog(c, rawlog, &summary, &error, truth)) << error;
  EXPECT_EQ(summary.object_scans, summary.scans);
  std::ifstream in(truth);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) {
    std::istringstream f(line);
    double t, x, y, a, lx, ly, la;
    int n;
    ASSERT_TRUE(f >> t >> x >> y >> a >> lx >> ly >> la >> n);
    ASSERT_EQ(n, 5);
    std::vector<double> r(5);
    std::vector<int> k(5);
    for (double& v : r) f >> v;
    for (int& v : k) f >> v;
    ASSERT_TRUE(static_cast<bool>(f));
    EXPECT_NEAR(lx, c.laser_x, 1e-9);
    EXPECT_EQ(k[2], 0);  // straight ahead: the disc, 2 - 0.5 - laser_x away
    EXPECT_NEAR(r[2], 1.5 - c.laser_x, 1e-5);
    EXPECT_EQ(k[0], -1);
    ++lines;
  }
  EXPECT_EQ(lines, static_cast<int>(summary.scans));
}

// Steps a loaded simulator with velocity command (v, w) for `seconds` of scans.
void driveFor(GridmapSimulator* sim, double v, double w, double seconds) {
  sim->setVelocityCommand(v, w);
  SimulatedScan s;
  const int scans = static_cast<int>(std::lround(seconds / sim->config().scan_period));
  for (int k = 0; k < scans; ++k) ASSERT_TRUE(sim->step(&s));
}

TEST(GridmapSimulator, DrivingIntoAWallStopsAtContactAndCountsOneCollision) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);  // inner wall faces at x, y = ±4.8
  c.start_x = 4.0;
  c.robot_radius = 0.2;
  GridmapSimulator sim(c);
  std::string error;
  ASSERT_TRUE(sim.load(&error)) << error;
  SimulatedScan s;
  ASSERT_TRUE(sim.step(&s));
  EXPECT_EQ(s.collisions, 0u);
  EXPECT_FALSE(s.in_contact);
  // 0.5 m/s for 3 s would take it to x = 5.5: it stops with its disc on the wall, at 4.6.
  driveFor(&sim, 0.5, 0.0, 3.0);
  EXPECT_NEAR(sim.truePose().x, 4.6, 1e-4);
  EXPECT_NEAR(sim.truePose().y, 0.0, 1e-9);
  EXPECT_EQ(sim.collisions(), 1u);  // pushing on is one collision
  EXPECT_NEAR(sim.lastCollisionPosition().x(), 4.6, 0.5 * 0.01 + 1e-9);  // within a 10 ms step
  EXPECT_NEAR(sim.lastCollisionTime(), c.start_time + 1.2, 0.01 + 1e-9);
  ASSERT_TRUE(sim.step(&s));
  EXPECT_EQ(s.collisions, 1u);
  EXPECT_TRUE(s.in_contact);
  // The odometry (noise-free here) saw only the motion that happened.
  EXPECT_NEAR(s.odometry.x, 0.6, 1e-4);
  // Turning in place against the wall is free and no collision.
  driveFor(&sim, 0.0, 0.8, 1.0);
  EXPECT_NEAR(sim.truePose().theta, 0.8, 1e-9);
  EXPECT_EQ(sim.collisions(), 1u);
  // Backing off and driving into it again is a second one.
  driveFor(&sim, 0.0, -0.8, 1.0);
  driveFor(&sim, -0.5, 0.0, 1.0);
  EXPECT_NEAR(sim.truePose().x, 4.1, 1e-4);
  driveFor(&sim, 0.5, 0.0, 2.0);
  EXPECT_NEAR(sim.truePose().x, 4.6, 1e-4);
  EXPECT_EQ(sim.collisions(), 2u);
  EXPECT_FALSE(sim.stuck());  // velocity commands: never "stuck"
}

TEST(GridmapSimulator, ARobotWithoutRadiusStopsAtTheWallsFace) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.start_y = 4.0;
  c.start_theta = M_PI / 2;
  c.robot_radius = 0.0;
  GridmapSimulator sim(c);
  std::string error;
  ASSERT_TRUE(sim.load(&error)) << error;
  SimulatedScan s;
  ASSERT_TRUE(sim.step(&s));
  driveFor(&sim, 0.5, 0.0, 3.0);
  EXPECT_NEAR(sim.truePose().y, 4.8, 1e-4);
  EXPECT_EQ(sim.collisions(), 1u);
}

TEST(GridmapSimulator, ARouteIntoAWallEndsHeldByIt) {
  // The second waypoint lies beyond the east wall: the robot pushes on it for 5 s, then the run
  // ends (it would never arrive) and says so.
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.waypoints = writeWaypoints(dir, "3 0\n6 0\n");
  const std::string rawlog = (dir / "wall.rawlog").string();
  io::SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(io::simulateToRawlog(c, rawlog, &summary, &error)) << error;
  EXPECT_EQ(summary.collisions, 1u);
  EXPECT_TRUE(summary.stuck);
  // 1.6 m to the contact at 0.5 m/s, then 5 s held.
  EXPECT_NEAR(summary.last_stamp - summary.first_stamp, 1.6 / 0.5 + 5.0, 0.25);
  EXPECT_NEAR(summary.path_length, 1.6, 0.01);
}

TEST(GridmapSimulator, ObstaclesAreTheMapsOccupiedCells) {
  const fs::path dir = test::scratchDir();
  GridmapSimulator sim(roomConfig(dir));
  std::string error;
  ASSERT_TRUE(sim.load(&error)) << error;
  const exploration::OccupancyImage& o = sim.obstacles();
  EXPECT_EQ(o.geometry.width, kRoomPixels);
  EXPECT_EQ(o.geometry.height, kRoomPixels);
  EXPECT_NEAR(o.geometry.resolution, kResolution, 1e-6);
  EXPECT_NEAR(o.geometry.origin_x, -5.0, 1e-6);
  EXPECT_NEAR(o.geometry.origin_y, -5.0, 1e-6);
  const int inner = kRoomPixels - 2 * kWallPixels;
  EXPECT_EQ(std::count(o.occupied.begin(), o.occupied.end(), 1),
            kRoomPixels * kRoomPixels - inner * inner);
  EXPECT_TRUE(o.occupiedAt(0, 0));
  EXPECT_FALSE(o.occupiedAt(kWallPixels, kWallPixels));
  EXPECT_TRUE(o.occupiedAt(kWallPixels - 1, kRoomPixels / 2));
}

TEST(GridmapSimulator, RawlogReadsBackWithTheSameScansOdometryAndGroundTruth) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c;
  c.map = test::dataPath("sim_map.png");
  c.waypoints = test::dataPath("sim_map_waypoints.txt");
  c.laser_rays = 91;
  c.scan_period = 0.25;
  c.linear_speed = 1.0;
  c.odometry_noise_xy = 0.05;
  const std::string rawlog = (dir / "sim.rawlog").string();
  io::SimulationSummary summary;
  std::string error;
  ASSERT_TRUE(io::simulateToRawlog(c, rawlog, &summary, &error)) << error;
  EXPECT_GT(summary.path_length, 14.0);
  EXPECT_GT(summary.odometry_error, 0.0);
  const auto expected = runAll(c, 100000);
  ASSERT_EQ(summary.scans, expected.size());

  io::RawlogReader reader;
  ASSERT_TRUE(reader.open(rawlog, &error)) << error;
  io::RawlogScan item;
  size_t n = 0;
  io::RawlogReader::Status status;
  while ((status = reader.next(&item)) == io::RawlogReader::Status::kScan) {
    ASSERT_LT(n, expected.size());
    const SimulatedScan& e = expected[n];
    EXPECT_EQ(item.label, "LASER_SIM");
    EXPECT_NEAR(item.scan.stamp, e.stamp, 1e-6);
    expectPoseNear(item.odometry, e.odometry, 1e-6);
    expectPoseNear(item.scan.sensor_pose, Pose2(0.2, 0.0, 0.0), 1e-9);
    EXPECT_FLOAT_EQ(item.scan.range_sigma, 0.01f);
    EXPECT_FLOAT_EQ(item.scan.max_range, 30.0f);
    ASSERT_EQ(item.scan.size(), 91u);
    for (size_t k = 0; k < item.scan.size(); ++k) {
      EXPECT_FLOAT_EQ(item.scan.ranges[k], e.scan.ranges[k]);
      EXPECT_NEAR(item.scan.bearings[k], e.scan.bearings[k], 1e-5);
      EXPECT_EQ(item.scan.valid[k], e.scan.valid[k]);
    }
    ++n;
  }
  EXPECT_EQ(status, io::RawlogReader::Status::kEnd) << reader.message();
  EXPECT_EQ(n, expected.size());
  EXPECT_EQ(reader.format(), io::RawlogFormat::kActionsSensoryFrames);

  // The ground truth: one `t x y phi` line per scan, the true poses.
  const std::string gt_path = io::groundTruthPathFor(rawlog);
  EXPECT_EQ(gt_path, rawlog + ".GT.txt");
  const std::string text = test::readText(gt_path);
  EXPECT_EQ(static_cast<size_t>(std::count(text.begin(), text.end(), '\n')), expected.size());
  std::vector<StampedPose> truth;
  ASSERT_TRUE(io::readGroundTruth(gt_path, &truth, &error)) << error;
  ASSERT_EQ(truth.size(), expected.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_NEAR(truth[i].stamp, expected[i].stamp, 1e-6);
    expectPoseNear(truth[i].pose, expected[i].true_pose, 1e-6);
  }

  // Same seed, same bytes.
  const std::string again = (dir / "again.rawlog").string();
  ASSERT_TRUE(io::simulateToRawlog(c, again, nullptr, &error)) << error;
  EXPECT_EQ(test::readText(again), test::readText(rawlog));
  EXPECT_EQ(test::readText(again + ".GT.txt"), text);
}

TEST(GridmapSimulator, LoadsMapServerYamlAndExplicitOrigins) {
  const fs::path dir = test::scratchDir();
  const std::string pgm = writeRoom(dir);
  test::writeText(dir / "room.yaml",
                  "image: room.pgm\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\n"
                  "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  GridmapSimulatorConfig c;
  c.map = (dir / "room.yaml").string();
  GridmapSimulator from_yaml(c);
  std::string error;
  ASSERT_TRUE(from_yaml.load(&error)) << error;
  Eigen::Vector4d b = from_yaml.mapBounds();
  EXPECT_NEAR(b[0], -1.0, 1e-6);
  EXPECT_NEAR(b[1], -2.0, 1e-6);
  EXPECT_NEAR(b[2], 9.0, 1e-6);
  EXPECT_NEAR(b[3], 8.0, 1e-6);

  c.map = pgm;
  c.map_centered = false;
  c.origin_x = -1.0;
  c.origin_y = -2.0;
  c.resolution = 0.1;
  GridmapSimulator from_image(c);
  ASSERT_TRUE(from_image.load(&error)) << error;
  b = from_image.mapBounds();
  EXPECT_NEAR(b[0], -1.0, 1e-6);
  EXPECT_NEAR(b[1], -2.0, 1e-6);
  EXPECT_NEAR(b[2], 19.0, 1e-6);
  EXPECT_NEAR(b[3], 18.0, 1e-6);
  EXPECT_NEAR(from_image.mapResolution(), 0.1, 1e-6);  // MRPT keeps it as a float
}

void expectOneLineError(const std::string& error, const std::string& contains) {
  EXPECT_NE(error.find(contains), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST(GridmapSimulator, BadInputGivesAOneLineError) {
  const fs::path dir = test::scratchDir();
  std::string error;
  GridmapSimulatorConfig c = roomConfig(dir);

  GridmapSimulatorConfig missing = c;
  missing.map = (dir / "nowhere.png").string();
  EXPECT_FALSE(GridmapSimulator(missing).load(&error));
  expectOneLineError(error, "nowhere.png' does not exist");

  GridmapSimulatorConfig not_an_image = c;
  not_an_image.map = (dir / "text.png").string();
  test::writeText(not_an_image.map, "this is not a PNG\n");
  EXPECT_FALSE(GridmapSimulator(not_an_image).load(&error));
  expectOneLineError(error, "cannot load map");

  GridmapSimulatorConfig bad_yaml = c;
  bad_yaml.map = (dir / "bad.yaml").string();
  test::writeText(bad_yaml.map, "image: absent.pgm\nresolution: 0.05\n");
  EXPECT_FALSE(GridmapSimulator(bad_yaml).load(&error));
  expectOneLineError(error, "cannot load map");

  GridmapSimulatorConfig garbage = c;
  garbage.waypoints = writeWaypoints(dir, "1 2\n3 four\n");
  EXPECT_FALSE(GridmapSimulator(garbage).load(&error));
  expectOneLineError(error, "line 2: expected two numbers");

  garbage.waypoints = writeWaypoints(dir, "1 2 3\n4 5\n");
  EXPECT_FALSE(GridmapSimulator(garbage).load(&error));
  expectOneLineError(error, "line 1");

  garbage.waypoints = writeWaypoints(dir, "# only one\n1 2\n");
  EXPECT_FALSE(GridmapSimulator(garbage).load(&error));
  expectOneLineError(error, "at least 2");

  garbage.waypoints = (dir / "no_waypoints.txt").string();
  EXPECT_FALSE(GridmapSimulator(garbage).load(&error));
  expectOneLineError(error, "no_waypoints.txt' does not exist");

  // Bytes of a binary file are shown escaped, not written to the terminal.
  garbage.waypoints = writeWaypoints(dir, std::string("1 2\n\x1b[2J\x01\xff 3\n", 13));
  EXPECT_FALSE(GridmapSimulator(garbage).load(&error));
  expectOneLineError(error, "got '\\x1b[2J\\x01\\xff 3'");

  // A waypoint far off the map would never be reached: the run would not end.
  garbage.waypoints = writeWaypoints(dir, "1 1\n1e9 1\n");
  EXPECT_FALSE(GridmapSimulator(garbage).load(&error));
  expectOneLineError(error, "waypoint 2 of");
  expectOneLineError(error, "lies more than the map's size outside the map");

  GridmapSimulatorConfig invalid = c;
  invalid.linear_speed = -1.0;
  EXPECT_FALSE(GridmapSimulator(invalid).load(&error));
  expectOneLineError(error, "invalid simulator configuration: linear_speed must be > 0");
  invalid = c;
  invalid.range_noise = std::nan("");
  EXPECT_FALSE(invalid.isValid(&error));
  expectOneLineError(error, "range_noise must be a finite number");
  invalid = c;
  invalid.moving_object_start = 5.0;
  invalid.moving_object_end = 4.0;
  EXPECT_FALSE(invalid.isValid(&error));
  expectOneLineError(error, "moving_object_end");
  invalid = c;
  invalid.robot_radius = -0.1;
  EXPECT_FALSE(invalid.isValid(&error));
  expectOneLineError(error, "robot_radius must be >= 0 (m)");
  invalid = c;
  invalid.kidnap_time = 0.5;  // before start_time
  EXPECT_FALSE(invalid.isValid(&error));
  expectOneLineError(error, "kidnap_time");
  EXPECT_TRUE(c.isValid(&error)) << error;

  // A run nothing would end, and an unwritable output.
  EXPECT_FALSE(io::simulateToRawlog(c, (dir / "x.rawlog").string(), nullptr, &error));
  expectOneLineError(error, "give waypoints or a duration");
  c.duration = 1.0;
  EXPECT_FALSE(
      io::simulateToRawlog(c, (dir / "no" / "dir" / "x.rawlog").string(), nullptr, &error));
  expectOneLineError(error, "x.rawlog': No such file or directory");
  EXPECT_TRUE(io::simulateToRawlog(c, (dir / "x.rawlog").string(), nullptr, &error)) << error;
}

TEST(GridmapSimulator, DurationEndsARunWithoutWaypoints) {
  const fs::path dir = test::scratchDir();
  GridmapSimulatorConfig c = roomConfig(dir);
  c.duration = 2.0;
  const auto scans = runAll(c, 1000, 0.1, 0.0);
  ASSERT_EQ(scans.size(), 21u);  // start_time, +0.1, ..., +2.0
  EXPECT_NEAR(scans.back().stamp, c.start_time + 2.0, 1e-9);
  EXPECT_NEAR(scans.back().true_pose.x, 0.2, 1e-9);
}

TEST(SimulateArgs, ParsesFaultsAndSettingsAndRefusesBadUsage) {
  io::SimulateOptions o;
  bool help = false;
  std::string error;
  ASSERT_TRUE(io::parseSimulateArgs(
      {"--map", "m.png", "--waypoints", "w.txt", "--out=o.rawlog", "--seed", "7", "--kidnap",
       "20,1.5,-2,0.5", "--moving-object", "5,8,-0.3,0.3,1.2", "--origin-x", "-3", "--range-noise",
       "0.02", "--duration", "60", "--laser-rays", "181"},
      &o, &help, &error))
      << error;
  EXPECT_FALSE(help);
  EXPECT_EQ(o.config.map, "m.png");
  EXPECT_EQ(o.config.waypoints, "w.txt");
  EXPECT_EQ(o.out, "o.rawlog");
  EXPECT_EQ(o.config.seed, 7);
  EXPECT_DOUBLE_EQ(o.config.kidnap_time, 20.0);
  EXPECT_DOUBLE_EQ(o.config.kidnap_dy, -2.0);
  EXPECT_DOUBLE_EQ(o.config.kidnap_dtheta, 0.5);
  EXPECT_DOUBLE_EQ(o.config.moving_object_bearing_min, -0.3);
  EXPECT_DOUBLE_EQ(o.config.moving_object_distance, 1.2);
  EXPECT_FALSE(o.config.map_centered);
  EXPECT_DOUBLE_EQ(o.config.origin_x, -3.0);
  EXPECT_DOUBLE_EQ(o.config.range_noise, 0.02);
  EXPECT_DOUBLE_EQ(o.config.duration, 60.0);
  EXPECT_EQ(o.config.laser_rays, 181);

  const std::vector<std::string> base = {"--map", "m.png", "--waypoints", "w.txt", "--out", "o"};
  auto refuse = [&](std::vector<std::string> extra, const std::string& contains) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    io::SimulateOptions options;
    bool h = false;
    std::string why;
    EXPECT_FALSE(io::parseSimulateArgs(args, &options, &h, &why)) << contains;
    expectOneLineError(why, contains);
  };
  refuse({"--kidnap", "1,2,3"}, "--kidnap wants T,DX,DY,DTH");
  refuse({"--moving-object", "1,2,3,4,x"}, "--moving-object wants");
  refuse({"--bogus"}, "unknown option '--bogus'");
  refuse({"--seed"}, "--seed needs a value");
  refuse({"--seed", "1.5"}, "--seed wants an integer");
  refuse({"--linear-speed", "fast"}, "--linear-speed wants a number");
  refuse({"--map-centered", "maybe"}, "wants true or false");
  refuse({"--scan-period", "0"}, "scan_period must be > 0");
  io::SimulateOptions options;
  EXPECT_FALSE(io::parseSimulateArgs({"--map", "m.png", "--out", "o"}, &options, &help, &error));
  expectOneLineError(error, "--waypoints is required");

  EXPECT_TRUE(io::parseSimulateArgs({"--help"}, &options, &help, &error));
  EXPECT_TRUE(help);
  // The help documents every setting.
  const std::string usage = io::simulateUsage("evidential_slam_simulate");
  GridmapSimulatorConfig defaults;
  for (const auto& field : io::gridmapSimulatorFields(&defaults)) {
    std::string option = std::string("--") + field.name;
    std::replace(option.begin(), option.end(), '_', '-');
    EXPECT_NE(usage.find(option), std::string::npos) << option;
  }
  EXPECT_NE(usage.find("--kidnap T,DX,DY,DTH"), std::string::npos);
}

}  // namespace
}  // namespace evidential_slam
