// Disagreement as a layer (docs/fusion.md §4): two robots of the grid-map simulator
// (io/gridmap_simulator.h) map one world that differs between their visits: for robot 1 the door
// between two rooms is shut and a cabinet stands in the east room; for robot 2 the door is open and
// the cabinet stands elsewhere. Each robot's scans are integrated at its true poses (the fusion is
// under test, not the SLAM) and the two maps are fused by the cautious rule in their shared frame.
// Where the robots saw different things the fused map holds conflict m(∅); where they agree, or
// only one looked, it does not. A probabilistic merge leaves such a cell near 0.5, like a cell no
// one saw.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evidential_slam/core/fusion/map_fusion.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/io/gridmap_simulator.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

constexpr double kRes = 0.05;
constexpr int kWidth = 240, kHeight = 160;  // 12 m x 8 m, centred on the origin
constexpr int kWall = 4;                    // pixels

// Two rooms split by a wall along x = 0 with a 1 m doorway at |y| < 0.5.
std::string writeRooms(const fs::path& dir) {
  const fs::path path = dir / "rooms.pgm";
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << kWidth << " " << kHeight << "\n255\n";
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < kWidth; ++c) {
      const double x = (c + 0.5) * kRes - 0.5 * kWidth * kRes;
      const double y = 0.5 * kHeight * kRes - (r + 0.5) * kRes;
      const bool border = r < kWall || c < kWall || r >= kHeight - kWall || c >= kWidth - kWall;
      const bool inner = std::abs(x) < 0.5 * kWall * kRes && std::abs(y) >= 0.5;
      out.put(static_cast<char>(border || inner ? 0 : 255));
    }
  }
  return path.string();
}

// One robot's map: its scans integrated at its true poses.
EvidentialGridMap mapOf(const fs::path& dir, const std::string& name, const std::string& objects,
                        const std::string& waypoints) {
  io::GridmapSimulatorConfig c;
  c.map = writeRooms(dir);
  c.resolution = kRes;
  c.range_noise = 0.0;
  c.odometry_noise_xy = c.odometry_noise_theta = c.odometry_noise_theta_per_m = 0.0;
  c.laser_max_range = 8.0;
  c.objects = (dir / (name + "_objects.txt")).string();
  test::writeText(c.objects, objects);
  c.waypoints = (dir / (name + "_waypoints.txt")).string();
  test::writeText(c.waypoints, waypoints);
  io::GridmapSimulator sim(c);
  std::string error;
  EXPECT_TRUE(sim.load(&error)) << error;
  const BeamModel model(SensorModelConfig(), kRes);
  EvidentialGridMap map(kRes);
  ScanAccumulator scratch;
  io::SimulatedScan s;
  const Pose2 laser(c.laser_x, c.laser_y, c.laser_yaw);
  while (sim.step(&s)) {
    TracedScan traced;
    model.traceScan(s.true_pose.compose(laser), s.scan, &traced);
    model.integrateScan(traced, &map, &scratch);
  }
  return map;
}

// Over the cells of the box [x0, x1] x [y0, y1] (m): the m(∅) the fusion added beyond the larger
// of the two maps' own (each map holds some where its own scans met at a wall's edge), its
// largest and its mean.
struct Added {
  double max = 0.0, mean = 0.0;
};
Added added(const EvidentialGridMap& fused, const EvidentialGridMap& a, const EvidentialGridMap& b,
            double x0, double y0, double x1, double y1) {
  Added r;
  int n = 0;
  for (double y = y0; y <= y1; y += kRes) {
    for (double x = x0; x <= x1; x += kRes) {
      auto conflict = [&](const EvidentialGridMap& m) {
        return layerValue(m.cell(m.worldToCell(x, y)), Layer::kConflict);
      };
      const double d = conflict(fused) - std::max(conflict(a), conflict(b));
      r.max = std::max(r.max, d);
      r.mean += d;
      ++n;
    }
  }
  if (n > 0) r.mean /= n;
  return r;
}

TEST(FusionDisagreement, ADoorShutForOneRobotAndAMovedCabinetShowAsConflict) {
  const fs::path dir = test::scratchDir();
  // Both robots drive through the east room, up and down in front of the doorway; robot 2 also
  // looks into the west room through the open door.
  const std::string route = "3.5 -2.5\n3.5 2.5\n1.5 2.5\n1.5 -2.5\n";
  // Robot 1: the door shut (a panel across the doorway), the cabinet at (4.5..5.3, 0.3..0.9).
  const EvidentialGridMap a = mapOf(dir, "robot1",
                                    "bar 0 1000 -0.02 -0.5 -0.02 0.5 0.05\n"
                                    "bar 0 1000 4.5 0.6 5.3 0.6 0.3\n",
                                    route);
  // Robot 2: the door open, the cabinet moved to (4.5..5.3, -2.3..-1.7).
  const EvidentialGridMap b = mapOf(dir, "robot2", "bar 0 1000 4.5 -2.0 5.3 -2.0 0.3\n", route);

  EvidentialGridMap fused;
  fusion::FusionReport report;
  std::string why;
  ASSERT_TRUE(fusion::fuseMaps({{&a, Pose2()}, {&b, Pose2()}}, fusion::FusionConfig{}, &fused,
                               &report, &why))
      << why;

  // The fused map marks the doorway (a panel for robot 1, open space for robot 2) and the
  // cabinet's west face at its first place (seen by robot 1, free for robot 2) and at its second
  // (the other way round).
  EXPECT_GT(added(fused, a, b, -0.1, -0.35, 0.05, 0.35).max, 0.5);
  EXPECT_GT(added(fused, a, b, 4.1, 0.35, 4.35, 0.85).max, 0.5);
  EXPECT_GT(added(fused, a, b, 4.1, -2.25, 4.35, -1.75).max, 0.5);
  // Where both saw the same (the north wall, the open east room between the cabinet's places) it
  // adds next to nothing, and where neither looked nothing at all.
  EXPECT_LT(added(fused, a, b, 1.5, 3.7, 5.0, 3.9).mean, 0.02);
  EXPECT_LT(added(fused, a, b, 2.5, -1.2, 3.5, -0.2).max, 0.02);
  EXPECT_EQ(layerValue(fused.cell(fused.worldToCell(7.2, 5.2)), Layer::kConflict), 0.0);
}

}  // namespace
}  // namespace evidential_slam
