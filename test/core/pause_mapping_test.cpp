// Mapping paused (SlamEngine::setMappingPaused, ParticleFilter::setMapUpdates): scans still move,
// match and weigh the particles, but no map changes.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "evidential_slam/core/slam_engine.h"
#include "test_support.h"
#include "cell_support.h"

namespace evidential_slam {
namespace {

using testing_cells::sameCells;
using testing_room::roomScan;

SlamConfig smallConfig() {
  SlamConfig c;
  c.particles = 8;
  c.threads = 1;
  c.seed = 5;
  return c;
}

// The robot drives through the room with its box (an asymmetric room), one processed scan per pose.
const std::vector<Pose2> kPath = {Pose2(0, 0, 0),         Pose2(-0.6, 0, 0.1),
                                  Pose2(-0.6, -0.6, 0.2), Pose2(0, -0.6, 0.0),
                                  Pose2(0.6, -0.6, -0.1), Pose2(0.6, 0.0, 0.0)};

ScanUpdate step(SlamEngine* engine, size_t i) {
  return engine->processScan(kPath[i], roomScan(kPath[i], 1.0 + i, true));
}

// A paused step proposes, matches and weighs exactly as an update from the same state would (the
// weights read the map before the scan either way), and leaves every particle's map as it was.
TEST(PauseMappingTest, PausedStepWeighsLikeAnUpdateAndLeavesTheMaps) {
  SlamEngine mapping(smallConfig()), paused(smallConfig());
  for (size_t i = 0; i < 3; ++i) {
    step(&mapping, i);
    step(&paused, i);
  }
  std::vector<EvidentialGridMap> before;
  for (const Particle& p : paused.filter().particles()) before.push_back(p.map);
  const double weight_before =
      paused.filter().particles()[paused.filter().bestIndex()].cumulative_log_weight;
  paused.setMappingPaused(true);
  EXPECT_TRUE(paused.mappingPaused());
  EXPECT_FALSE(paused.filter().mapUpdates());

  const ScanUpdate m = step(&mapping, 3);
  const ScanUpdate p = step(&paused, 3);
  ASSERT_TRUE(m.processed);
  ASSERT_TRUE(p.processed);
  EXPECT_GT(m.conflict_mass_added + m.external_conflict_added, 0.0);
  EXPECT_EQ(p.conflict_mass_added, 0.0);
  EXPECT_EQ(p.external_conflict_added, 0.0);
  const std::vector<Particle>& a = mapping.filter().particles();
  const std::vector<Particle>& b = paused.filter().particles();
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].pose.x, b[k].pose.x) << k;
    EXPECT_EQ(a[k].pose.y, b[k].pose.y) << k;
    EXPECT_EQ(a[k].pose.theta, b[k].pose.theta) << k;
    EXPECT_NEAR(a[k].cumulative_log_weight, b[k].cumulative_log_weight,
                1e-9 * std::abs(a[k].cumulative_log_weight) + 1e-9)
        << k;
  }
  EXPECT_NE(b[paused.filter().bestIndex()].cumulative_log_weight, weight_before)
      << "the paused step did not weigh the particles";
  // No map changed: each particle holds one of the maps the particles held before.
  for (const Particle& particle : b) {
    bool found = false;
    for (const EvidentialGridMap& map : before) found |= sameCells(particle.map, map);
    EXPECT_TRUE(found);
  }
  EXPECT_FALSE(sameCells(mapping.bestMap(), paused.bestMap()));
}

// While paused the pose follows the robot on the map; resumed, the map grows again. A reset keeps
// the pause: the first scan then leaves the new map empty.
TEST(PauseMappingTest, LocalizesWhilePausedAndMapsAgainWhenResumed) {
  SlamEngine engine(smallConfig());
  for (size_t i = 0; i < 3; ++i) step(&engine, i);
  engine.setMappingPaused(true);
  const EvidentialGridMap frozen = engine.bestMap();
  for (size_t i = 3; i < 5; ++i) {
    ASSERT_TRUE(step(&engine, i).processed);
    const Pose2 pose = engine.bestPose();
    EXPECT_NEAR(pose.x, kPath[i].x, 0.03) << i;
    EXPECT_NEAR(pose.y, kPath[i].y, 0.03) << i;
    EXPECT_NEAR(pose.theta, kPath[i].theta, 0.02) << i;
    EXPECT_TRUE(sameCells(engine.bestMap(), frozen)) << i;
  }
  engine.setMappingPaused(false);
  ASSERT_TRUE(step(&engine, 5).processed);
  EXPECT_FALSE(sameCells(engine.bestMap(), frozen));

  engine.setMappingPaused(true);
  engine.reset();
  EXPECT_TRUE(engine.mappingPaused());
  ASSERT_TRUE(step(&engine, 0).processed);
  EXPECT_EQ(engine.bestMap().allocatedTiles(), 0u);
}

}  // namespace
}  // namespace evidential_slam
