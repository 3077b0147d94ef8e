// Localization on a map of a world that changed since (issue 35): the simulator drives a loop in a
// room with a pillar, the SLAM maps it; then the pillar is gone and another stands elsewhere (a
// second map image), and the same loop is localized on the first map. The pose stays within
// 0.1 m, and the anomaly marks both changed pillars while the walls hardly hold any.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evidential_slam/core/localization/localizer.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/core/slam_engine.h"
#include "evidential_slam/io/gridmap_simulator.h"
#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

constexpr int kPixels = 160;  // 8 m at 0.05 m, centred on the origin
constexpr double kRes = 0.05;
struct Box {
  double x0, y0, x1, y1;
  bool contains(double x, double y, double margin) const {
    return x >= x0 - margin && x <= x1 + margin && y >= y0 - margin && y <= y1 + margin;
  }
};
const Box kRemoved{0.9, -0.3, 1.5, 0.3};  // in the first world only
const Box kAdded{-1.5, 0.5, -0.9, 1.1};   // in the second world only

// The room (walls 0.2 m thick) with the given pillars, as a binary PGM.
std::string writeWorld(const fs::path& path, const std::vector<Box>& pillars) {
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << kPixels << " " << kPixels << "\n255\n";
  for (int r = 0; r < kPixels; ++r) {
    for (int c = 0; c < kPixels; ++c) {
      const double x = (c + 0.5) * kRes - 0.5 * kPixels * kRes;
      const double y = 0.5 * kPixels * kRes - (r + 0.5) * kRes;
      bool wall = r < 4 || c < 4 || r >= kPixels - 4 || c >= kPixels - 4;
      for (const Box& b : pillars) wall = wall || b.contains(x, y, 0.0);
      out.put(static_cast<char>(wall ? 0 : 255));
    }
  }
  return path.string();
}

std::vector<SimulatedScan> simulate(const fs::path& dir, const std::string& world, int seed) {
  GridmapSimulatorConfig c;
  c.map = world;
  c.resolution = kRes;
  c.waypoints = (dir / "loop.txt").string();
  test::writeText(c.waypoints, "-2.6 -2.6\n2.6 -2.6\n2.6 2.6\n-2.6 2.6\n-2.6 -2.4\n");
  c.seed = seed;
  GridmapSimulator sim(c);
  std::string error;
  EXPECT_TRUE(sim.load(&error)) << error;
  std::vector<SimulatedScan> scans;
  SimulatedScan s;
  while (sim.step(&s)) scans.push_back(s);
  return scans;
}

// The settings for simulated odometry (config/sim.yaml).
SlamConfig simConfig() {
  SlamConfig c;
  c.matcher.heading_window = 0.0;
  c.sensor.forward_conflict_as_unknown = false;
  c.along_track_prior = false;
  c.matcher.icp_iterations = 12;
  c.long_step.beam_spacing = 0.0;
  c.long_step.forward_sigma = 0.0;
  c.motion.alpha_rot_rot = 0.02;
  c.particles = 20;
  c.seed = 1;
  c.threads = 2;
  return c;
}

TEST(LocalizationOnAChangedWorld, ThePoseHoldsAndTheChangesStandOut) {
  const fs::path dir = test::scratchDir();
  const std::vector<SimulatedScan> before =
      simulate(dir, writeWorld(dir / "before.pgm", {kRemoved}), 1);
  const std::vector<SimulatedScan> after =
      simulate(dir, writeWorld(dir / "after.pgm", {kAdded}), 2);
  ASSERT_GT(before.size(), 200u);
  ASSERT_GT(after.size(), 200u);

  // Map the first world. Its map frame is the start pose's (both runs start there).
  SlamEngine slam(simConfig());
  for (const SimulatedScan& s : before) slam.processScan(s.odometry, s.scan);
  const EvidentialGridMap map = slam.bestMap();
  const Pose2 start = before.front().true_pose;

  LocalizationConfig lc;
  lc.min_particles = 50;
  lc.max_particles = 500;
  Localizer loc(lc, simConfig());
  std::string why;
  ASSERT_TRUE(loc.setMap(map, &why)) << why;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << 0.01, 0.01, 0.003;
  ASSERT_TRUE(loc.resetAt(Pose2(0, 0, 0), cov, &why)) << why;
  double worst = 0.0, sum = 0.0;
  for (const SimulatedScan& s : after) {
    const LocalizationUpdate u = loc.processScan(s.odometry, s.scan);
    ASSERT_FALSE(u.rejected) << u.why;
    const Pose2 truth = start.inverse().compose(s.true_pose);
    const Pose2 estimate = loc.estimate().mean;
    const double error = std::hypot(estimate.x - truth.x, estimate.y - truth.y);
    worst = std::max(worst, error);
    sum += error;
  }
  EXPECT_LT(worst, 0.1);
  RecordProperty("worst_position_error_mm", static_cast<int>(std::lround(worst * 1000)));

  // The anomaly, per region of the world: the two pillars (0.15 m around them) and the walls'
  // hit cells elsewhere (m(o) + m(∅) >= 0.5 in the map).
  double removed = 0.0, added = 0.0, elsewhere = 0.0;
  loc.anomaly().forEach([&](int x, int y, float bits) {
    const Eigen::Vector2d m = map.cellCenter(CellIndex{x, y});
    const Pose2 w = start.compose(Pose2(m.x(), m.y(), 0.0));
    if (kRemoved.contains(w.x, w.y, 0.15)) {
      removed += bits;
    } else if (kAdded.contains(w.x, w.y, 0.15)) {
      added += bits;
    } else {
      elsewhere += bits;
    }
  });
  size_t wall_cells = 0, flagged_wall_cells = 0;
  map.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
    for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) {
      const Cell& c = tile.cells[static_cast<size_t>(k)];
      if (layerValue(c, Layer::kOccupied) + layerValue(c, Layer::kConflict) < 0.5) continue;
      const int x = tx * EvidentialGridMap::kTileSize + (k & (EvidentialGridMap::kTileSize - 1));
      const int y = ty * EvidentialGridMap::kTileSize + (k >> EvidentialGridMap::kTileBits);
      const Eigen::Vector2d m = map.cellCenter(CellIndex{x, y});
      const Pose2 w = start.compose(Pose2(m.x(), m.y(), 0.0));
      if (kRemoved.contains(w.x, w.y, 0.15) || kAdded.contains(w.x, w.y, 0.15)) continue;
      ++wall_cells;
      flagged_wall_cells += loc.anomaly().at(x, y) > 0.0f ? 1 : 0;
    }
  });
  EXPECT_GT(removed, 20.0);
  EXPECT_GT(added, 20.0);
  EXPECT_LT(elsewhere, 0.2 * std::min(removed, added));
  EXPECT_GT(wall_cells, 500u);
  EXPECT_LT(flagged_wall_cells, wall_cells / 20);
  RecordProperty("anomaly_removed_bits", static_cast<int>(removed));
  RecordProperty("anomaly_added_bits", static_cast<int>(added));
  RecordProperty("anomaly_elsewhere_bits", static_cast<int>(elsewhere));
  std::printf("mean %.3f m, worst %.3f m; anomaly removed %.1f, added %.1f, elsewhere %.1f "
              "bits; %zu of %zu wall cells flagged; %zu scans\n",
              sum / after.size(), worst, removed, added, elsewhere, flagged_wall_cells,
              wall_cells, after.size());
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
