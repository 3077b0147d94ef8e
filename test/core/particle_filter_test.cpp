// Tests of the particle filter (particle_filter.h).
// First systematic (low-variance) resampling, ParticleFilter::systematicResample: with N
// particles the sample positions are (u0 + i)/N, i = 0..N-1, and position u selects the first
// particle whose cumulative weight exceeds u. Expected parents are worked out by hand below.
// Then filter-level invariants: shared maps after initialize, log-domain normalisation, best =
// highest cumulative weight, path bookkeeping, determinism for a seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_set>
#include <vector>

#include "evidential_slam/core/motion_model.h"
#include "evidential_slam/core/particle_filter.h"
#include "evidential_slam/core/sensor_model.h"
#include "test_support.h"

namespace evidential_slam {
namespace {

std::vector<size_t> sorted(std::vector<size_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::vector<int> counts(const std::vector<size_t>& parents, size_t n) {
  std::vector<int> c(n, 0);
  for (size_t p : parents) {
    EXPECT_LT(p, n);
    if (p < n) ++c[p];
  }
  return c;
}

// weights {0.5, 0.25, 0.25, 0}, u0 = 0.1: positions 0.1/4 = 0.025, 1.1/4 = 0.275, 2.1/4 = 0.525,
// 3.1/4 = 0.775; cumulative 0.5, 0.75, 1.0, 1.0 -> parents 0, 0, 1, 2.
TEST(SystematicResampleTest, HandWorkedExample) {
  const auto parents = ParticleFilter::systematicResample({0.5, 0.25, 0.25, 0.0}, 0.1);
  ASSERT_EQ(parents.size(), 4u);
  EXPECT_EQ(sorted(parents), (std::vector<size_t>{0, 0, 1, 2}));
}

// weights {0.1, 0.2, 0.3, 0.4}, u0 = 0.5: positions 0.125, 0.375, 0.625, 0.875;
// cumulative 0.1, 0.3, 0.6, 1.0 -> parents 1, 2, 3, 3 (particle 0 is skipped by chance).
TEST(SystematicResampleTest, SecondHandWorkedExample) {
  const auto parents = ParticleFilter::systematicResample({0.1, 0.2, 0.3, 0.4}, 0.5);
  ASSERT_EQ(parents.size(), 4u);
  EXPECT_EQ(sorted(parents), (std::vector<size_t>{1, 2, 3, 3}));
}

// When N w_i are integers (4 * {0.5, 0.25, 0.25, 0} = {2, 1, 1, 0}) every u0 gives exactly those
// counts; u0 = (k + 0.5)/100 keeps positions off the cumulative boundaries.
TEST(SystematicResampleTest, IntegerExpectedCountsAreExact) {
  for (int k = 0; k < 100; ++k) {
    const double u0 = (k + 0.5) / 100.0;
    const auto parents = ParticleFilter::systematicResample({0.5, 0.25, 0.25, 0.0}, u0);
    ASSERT_EQ(parents.size(), 4u);
    EXPECT_EQ(counts(parents, 4), (std::vector<int>{2, 1, 1, 0})) << "u0 = " << u0;
  }
}

// Low variance: each count is floor(N w_i) or ceil(N w_i). N = 5, weights {0.1, 0.2, 0.3, 0.4, 0}:
// N w = {0.5, 1, 1.5, 2, 0} -> counts in {0,1}, {1}, {1,2}, {2}, {0}, total 5.
TEST(SystematicResampleTest, CountsAreFloorOrCeil) {
  const std::vector<double> w = {0.1, 0.2, 0.3, 0.4, 0.0};
  for (int k = 0; k < 100; ++k) {
    const double u0 = (k + 0.5) / 100.0;
    const auto c = counts(ParticleFilter::systematicResample(w, u0), 5);
    SCOPED_TRACE(testing::Message() << "u0 = " << u0);
    EXPECT_TRUE(c[0] == 0 || c[0] == 1);
    EXPECT_EQ(c[1], 1);
    EXPECT_TRUE(c[2] == 1 || c[2] == 2);
    EXPECT_EQ(c[3], 2);
    EXPECT_EQ(c[4], 0);
    EXPECT_EQ(c[0] + c[1] + c[2] + c[3] + c[4], 5);
  }
}

// A zero-weight particle is never chosen, wherever it sits (first, middle, last) and for every
// u0 in [0, 1) on a 0.001 grid, including u0 = 0 (position 0 must not select a leading zero
// weight).
TEST(SystematicResampleTest, ZeroWeightNeverChosen) {
  const std::vector<std::vector<double>> cases = {
      {0.0, 0.5, 0.0, 0.5}, {0.25, 0.0, 0.75, 0.0}, {0.5, 0.5, 0.0}, {0.0, 0.0, 1.0}, {1.0, 0.0}};
  for (const auto& w : cases) {
    for (int k = 0; k < 1000; ++k) {
      const double u0 = k / 1000.0;
      const auto parents = ParticleFilter::systematicResample(w, u0);
      ASSERT_EQ(parents.size(), w.size());
      for (size_t p : parents) {
        ASSERT_LT(p, w.size());
        EXPECT_GT(w[p], 0.0) << "u0 = " << u0 << " chose zero-weight particle " << p;
      }
    }
  }
}

// Uniform weights: every particle is chosen exactly once (positions (u0 + i)/N fall one in each
// interval [i/N, (i+1)/N)).
TEST(SystematicResampleTest, UniformWeightsKeepEveryParticleOnce) {
  for (double u0 : {0.05, 0.3, 0.5, 0.77, 0.999}) {
    const auto parents = ParticleFilter::systematicResample(std::vector<double>(5, 0.2), u0);
    EXPECT_EQ(sorted(parents), (std::vector<size_t>{0, 1, 2, 3, 4})) << "u0 = " << u0;
  }
  // Paper setting K = 100.
  const auto parents = ParticleFilter::systematicResample(std::vector<double>(100, 0.01), 0.37);
  ASSERT_EQ(parents.size(), 100u);
  const auto s = sorted(parents);
  for (size_t i = 0; i < 100; ++i) EXPECT_EQ(s[i], i);
}

// One particle carrying all the weight is copied N times.
TEST(SystematicResampleTest, DegenerateWeights) {
  const auto parents = ParticleFilter::systematicResample({0.0, 0.0, 1.0, 0.0, 0.0}, 0.6);
  EXPECT_EQ(parents, (std::vector<size_t>(5, 2)));
}

using testing_room::roomScan;

SlamConfig filterConfig(int particles) {
  SlamConfig c = testing_room::withoutRealRobotSettings(SlamConfig());
  c.particles = particles;
  c.threads = 1;
  c.seed = 17;
  return c;
}

// filterConfig without merging: every particle is a group (and a hypothesis) of its own.
SlamConfig unmergedConfig(int particles) {
  SlamConfig c = filterConfig(particles);
  c.merge_distance = 0.0;
  c.merge_angle = 0.0;
  c.constrained_merge_ratio = 0.0;
  return c;
}

// initialize(): K particles at the given pose, all sharing one map (copy-on-write tiles), so the
// filter's map memory equals that of a single map.
TEST(ParticleFilterTest, InitializeSharesOneMap) {
  ParticleFilter filter(filterConfig(8));
  const Pose2 start(-1.0, 0.2, 0.1);
  filter.initialize(start, roomScan(start), 0);
  ASSERT_EQ(filter.particles().size(), 8u);
  for (const Particle& p : filter.particles()) {
    EXPECT_NEAR(p.pose.x, start.x, 1e-12);
    EXPECT_NEAR(p.pose.y, start.y, 1e-12);
    EXPECT_NEAR(p.pose.theta, start.theta, 1e-12);
    ASSERT_NE(p.path, nullptr);
    EXPECT_EQ(p.path->step, 0);
  }
  std::unordered_set<const EvidentialGridMap::Tile*> seen;
  const size_t one_map = filter.particles()[0].map.accumulateUniqueTileBytes(&seen);
  EXPECT_GT(one_map, 0u);
  EXPECT_EQ(filter.mapMemoryBytes(), one_map);
  // The shared map holds the first scan.
  const EvidentialGridMap& map = filter.particles()[0].map;
  EXPECT_FALSE(map.observedBox().empty());
}

// update(): weights are normalised in the log domain (max log weight 0), N_eff in [1, K], the
// best particle has the highest cumulative weight, paths grow by one node per step.
TEST(ParticleFilterTest, UpdateInvariants) {
  ParticleFilter filter(filterConfig(8));
  Pose2 truth(-1.0, 0.2, 0.0);
  filter.initialize(truth, roomScan(truth), 0);
  for (int step = 1; step <= 3; ++step) {
    const Pose2 increment(0.5, 0.0, 0.0);
    truth = truth.compose(increment);
    const FilterStepInfo info = filter.update(increment, roomScan(truth), step);
    EXPECT_GE(info.effective_sample_size, 1.0 - 1e-9);
    EXPECT_LE(info.effective_sample_size, 8.0 + 1e-9);
    double max_log = -1e300, max_cum = -1e300;
    for (const Particle& p : filter.particles()) {
      max_log = std::max(max_log, p.log_weight);
      max_cum = std::max(max_cum, p.cumulative_log_weight);
      ASSERT_NE(p.path, nullptr);
      EXPECT_EQ(p.path->step, step);
      ASSERT_NE(p.path->parent, nullptr);
      EXPECT_EQ(p.path->parent->step, step - 1);
      EXPECT_TRUE(std::isfinite(p.log_weight));
    }
    EXPECT_NEAR(max_log, 0.0, 1e-12);
    EXPECT_DOUBLE_EQ(filter.best().cumulative_log_weight, max_cum);
  }
}

// Resampling: a parent drawn several times gives each child a whole copy of itself (the last child
// takes the parent over, the others copy it), so every child has its parent's pose, path and map.
// resample_threshold 1 resamples whenever the weights differ; without merging, every particle is
// its own hypothesis before it.
TEST(ParticleFilterTest, ResampledChildrenAreWholeCopiesOfTheirParents) {
  SlamConfig config = unmergedConfig(8);
  config.resample_threshold = 1.0;
  ParticleFilter filter(config);
  const Pose2 start(-1.0, 0.2, 0.0);
  filter.initialize(start, roomScan(start), 0);
  const Pose2 increment(0.5, 0.05, 0.05);
  const FilterStepInfo info =
      filter.update(increment, roomScan(start.compose(Pose2(0.45, 0.0, 0.0))), 1);
  ASSERT_TRUE(info.resampled);
  std::map<uint64_t, const Particle*> first_of_map;
  size_t copies = 0;
  for (const Particle& p : filter.particles()) {
    ASSERT_NE(p.path, nullptr);
    EXPECT_EQ(p.path->step, 1);
    EXPECT_EQ(p.path->pose.x, p.pose.x);
    EXPECT_FALSE(p.map.observedBox().empty());
    const auto found = first_of_map.find(p.map_id);
    if (found == first_of_map.end()) {
      first_of_map[p.map_id] = &p;
      continue;
    }
    ++copies;  // a sibling: the same pose, path node and tiles
    const Particle& sibling = *found->second;
    EXPECT_EQ(p.pose.x, sibling.pose.x);
    EXPECT_EQ(p.pose.theta, sibling.pose.theta);
    EXPECT_EQ(p.path, sibling.path);
    std::unordered_set<const EvidentialGridMap::Tile*> seen;
    const size_t bytes = sibling.map.accumulateUniqueTileBytes(&seen);
    EXPECT_GT(bytes, 0u);
    EXPECT_EQ(p.map.accumulateUniqueTileBytes(&seen), 0u);  // every tile shared with the sibling
  }
  EXPECT_GT(copies, 0u);  // some parent was drawn more than once
}

// The best particle's conflict figures are those of its scan on its map before the update, the
// open-space part included, although groups that cannot hold the best particle skip that pass: a
// scan taken 0.6 m from where the odometry puts it (no matcher) puts hits into the room's open
// space. Without resampling the particles keep their indices, so the best particle's map before
// the update is known.
TEST(ParticleFilterTest, BestParticleConflictIncludesItsOpenSpacePart) {
  for (const int threads : {1, 2}) {
    SlamConfig config = unmergedConfig(8);
    config.threads = threads;
    config.matcher.enabled = false;
    config.resample_threshold = 0.0;
    ParticleFilter filter(config);
    const Pose2 start(-1.0, 0.2, 0.0);
    filter.initialize(start, roomScan(start), 0);
    const std::vector<Particle> before = filter.particles();
    const LaserScan scan = roomScan(start.compose(Pose2(0.6, 0.0, 0.0)));
    const FilterStepInfo info = filter.update(Pose2(0.0, 0.0, 0.0), scan, 1);
    ASSERT_FALSE(info.resampled);
    ASSERT_FALSE(info.long_step);
    ASSERT_EQ(filter.lastUpdateGroups(), 8u);
    const size_t best = filter.bestIndex();

    const BeamModel model(config.sensor.forSensorNoise(0.0, config.resolution), config.resolution);
    EvidentialGridMap map = before[best].map;
    TracedScan traced;
    ScanAccumulator scratch;
    ScanConflict expected;
    model.traceScan(filter.particles()[best].pose.compose(scan.sensor_pose), scan, &traced);
    const double bits = model.integrateScan(traced, &map, &scratch, &expected);
    EXPECT_GT(expected.open_space_added, 0.0);
    EXPECT_EQ(info.best_conflict.open_space_added, expected.open_space_added) << threads;
    EXPECT_EQ(info.best_conflict.mass_added, expected.mass_added) << threads;
    EXPECT_EQ(info.best_conflict_added_bits, bits) << threads;
  }
}

// along_track_prior adds to each particle's weight the log prior of how far it went along the
// odometry's direction: with the same seed the proposals are the same, so the weights differ by
// exactly that (no resampling, so the particles stay in step).
TEST(ParticleFilterTest, AlongTrackPriorEntersTheWeights) {
  SlamConfig off = filterConfig(8);
  off.resample_threshold = 0.0;
  SlamConfig on = off;
  on.along_track_prior = true;
  ParticleFilter a(off), b(on);
  const Pose2 start(-1.0, 0.2, 0.0);
  a.initialize(start, roomScan(start), 0);
  b.initialize(start, roomScan(start), 0);
  const Pose2 increment(0.5, 0.0, 0.0);
  const Pose2 truth = start.compose(Pose2(0.4, 0.0, 0.0));  // the odometry says 25 % too much
  a.update(increment, roomScan(truth), 1);
  b.update(increment, roomScan(truth), 1);
  bool scored = false;
  for (size_t i = 0; i < 8; ++i) {
    const Particle& pa = a.particles()[i];
    const Particle& pb = b.particles()[i];
    ASSERT_EQ(pa.pose.x, pb.pose.x);
    ASSERT_EQ(pa.pose.y, pb.pose.y);
    const double prior = alongTrackLogPrior(start, pa.pose, increment, off.motion, 3.0);
    EXPECT_NEAR(pb.cumulative_log_weight - pa.cumulative_log_weight, prior, 1e-9) << i;
    scored = scored || prior < -1e-3;
  }
  EXPECT_TRUE(scored);
}

// The particles after one update of a filter started at `start` in roomScan's room, with an
// odometry increment 5 cm longer than the robot went; the step must be long exactly when
// `long_step` says.
std::vector<Particle> afterOneStep(const SlamConfig& config, const Pose2& increment,
                                   bool long_step) {
  const Pose2 start(-1.0, 0.2, 0.0);
  ParticleFilter filter(config);
  filter.initialize(start, roomScan(start), 0);
  const Pose2 truth = start.compose(Pose2(increment.x - 0.05, 0.0, 0.0));
  EXPECT_EQ(filter.update(increment, roomScan(truth), 1).long_step, long_step);
  return filter.particles();
}

// A filter config without resampling whose long steps are 0.8 m or 0.3 rad.
SlamConfig longStepConfig() {
  SlamConfig c = filterConfig(8);
  c.resample_threshold = 0.0;
  c.long_step.distance = 0.8;
  c.long_step.angle = 0.3;
  return c;
}

// A long-step setting, on in `on`: after a long step the filter behaves as `everywhere` (the
// setting's value on every step), after a short one as `base` (without it), as `observe` sees the
// particles; and the setting makes a difference both ways.
template <typename Observe>
void expectLongStepSetting(const SlamConfig& base, const SlamConfig& on,
                           const SlamConfig& everywhere, Observe observe) {
  const Pose2 long_step(0.85, 0.05, 0.05), short_step(0.5, 0.05, 0.05);
  const auto run = [&](const SlamConfig& config, const Pose2& increment, bool long_step) {
    return observe(afterOneStep(config, increment, long_step));
  };
  EXPECT_EQ(run(on, long_step, true), run(everywhere, long_step, false));
  EXPECT_NE(run(on, long_step, true), run(base, long_step, false));
  EXPECT_EQ(run(on, short_step, false), run(base, short_step, false));
  EXPECT_NE(run(on, short_step, false), run(everywhere, short_step, false));
}

// long_step_beam_spacing: a step at least long_step_distance long (or turning long_step_angle) is
// matched at that spacing, a shorter one at beam_spacing. roomScan's 1° beams: the long step is
// matched on every beam, exactly as with beam_spacing 1°; the short one as without the option.
TEST(ParticleFilterTest, LongStepsAreMatchedAtTheLongStepSpacing) {
  const SlamConfig base = longStepConfig();
  SlamConfig every_beam = base;
  every_beam.matcher.beam_spacing = 0.017453292519943295;
  SlamConfig on = base;
  on.long_step.beam_spacing = 0.017453292519943295;
  expectLongStepSetting(base, on, every_beam, [](const std::vector<Particle>& particles) {
    std::vector<std::array<double, 3>> poses;
    for (const Particle& p : particles) poses.push_back({p.pose.x, p.pose.y, p.pose.theta});
    return poses;
  });
}

// long_step_forward_sigma: after a long step the weights come from the forward model at that σ_f,
// exactly as with forward_sigma set to it; after a short step from forward_sigma's.
TEST(ParticleFilterTest, LongStepsAreWeighedAtTheLongStepForwardSigma) {
  const SlamConfig base = longStepConfig();
  SlamConfig wide = base;
  wide.sensor.forward_sigma = 0.05;
  SlamConfig on = base;
  on.long_step.forward_sigma = 0.05;
  expectLongStepSetting(base, on, wide, [](const std::vector<Particle>& particles) {
    std::vector<double> weights;
    for (const Particle& p : particles) weights.push_back(p.cumulative_log_weight);
    return weights;
  });
}

// Same seed and thread count: identical results (config.h promises determinism).
TEST(ParticleFilterTest, DeterministicForSeed) {
  ParticleFilter a(filterConfig(6)), b(filterConfig(6));
  Pose2 truth(-1.0, 0.2, 0.0);
  a.initialize(truth, roomScan(truth), 0);
  b.initialize(truth, roomScan(truth), 0);
  for (int step = 1; step <= 2; ++step) {
    const Pose2 increment(0.5, 0.05, 0.05);
    truth = truth.compose(increment);
    a.update(increment, roomScan(truth), step);
    b.update(increment, roomScan(truth), step);
  }
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(a.particles()[i].pose.x, b.particles()[i].pose.x);
    EXPECT_EQ(a.particles()[i].pose.y, b.particles()[i].pose.y);
    EXPECT_EQ(a.particles()[i].pose.theta, b.particles()[i].pose.theta);
    EXPECT_EQ(a.particles()[i].cumulative_log_weight, b.particles()[i].cumulative_log_weight);
  }
}

// A scan that declares its range noise is modelled with it: one beam along +x with z = 2.0 m
// (the hit at x = 2.0 lies inside cell (40, 0), whose centre is 2.025 m away: s = +0.025 m).
// m_hit = Φ((s + Δ/2)/σ) - Φ((s - Δ/2)/σ) = Φ(0.05/σ) - Φ(0), η = 1/(1 - 0.4(1 - m_hit)),
// o = 0.8·η·m_hit. Default model (σ = 0.025): m_hit = Φ(2) - 0.5 = 0.4772499, η = 1.2643824,
// o = 0.4827411. Declared σ = 0.3: m_hit = Φ(1/6) - 0.5 = 0.0661838, η = 1.5962366, o = 0.0845160.
TEST(ParticleFilterTest, DeclaredRangeNoiseWidensTheModel) {
  SlamConfig config = testing_room::withoutRealRobotSettings(SlamConfig());
  config.particles = 2;
  config.threads = 1;
  LaserScan scan;
  scan.max_range = 30.0f;
  scan.ranges = {2.0f};
  scan.bearings = {0.0f};
  scan.valid = {1};
  const Pose2 origin(0.0, 0.001, 0.0);  // cell (0, 0); x = 0 keeps s = 2.025 - 2.0 exactly

  ParticleFilter precise(config);
  precise.initialize(origin, scan, 0);
  const Cell& precise_hit = precise.best().map.cell(40, 0);
  EXPECT_NEAR(precise_hit.occupied(), 0.4827411, 2e-3);

  scan.range_sigma = 0.3f;
  ParticleFilter noisy(config);
  noisy.initialize(origin, scan, 0);
  const Cell& noisy_hit = noisy.best().map.cell(40, 0);
  EXPECT_NEAR(noisy_hit.occupied(), 0.0845160, 2e-3);
}

// forSensorNoise: σ_i = max(σ_i, σ_range), σ_f = max(σ_f, √(σ_range² + Δ²/12)); a sensor more
// precise than the configured model, or one that declares nothing, leaves it unchanged.
TEST(SensorNoiseTest, ModelFollowsDeclaredNoise) {
  const SensorModelConfig base;  // σ_i = σ_f = 0.025
  const SensorModelConfig noisy = base.forSensorNoise(0.3, 0.05);
  EXPECT_DOUBLE_EQ(noisy.hit_sigma, 0.3);
  EXPECT_NEAR(noisy.forward_sigma, 0.3003470, 1e-6);                  // √(0.09 + 0.0025/12)
  const SensorModelConfig precise = base.forSensorNoise(0.01, 0.05);  // √(1e-4 + 2.08e-4) = 0.0176
  EXPECT_DOUBLE_EQ(precise.hit_sigma, 0.025);
  EXPECT_DOUBLE_EQ(precise.forward_sigma, 0.025);
  EXPECT_DOUBLE_EQ(base.forSensorNoise(0.0, 0.05).hit_sigma, 0.025);
  EXPECT_DOUBLE_EQ(base.forSensorNoise(std::nan(""), 0.05).forward_sigma, 0.025);

  // Matcher: kernel σ = max(0.05, σ_range), radius = max(0.4, 1.5·σ_range); the target threshold
  // drops to one hit's occupied mass when that is below 0.25 (0.0845 for σ = 0.3 at Δ = 0.05,
  // see DeclaredRangeNoiseWidensTheModel; the default model's 0.6255 leaves 0.25); ICP turns point
  // to point, and matches endpoints twice as densely, when σ_range exceeds a cell.
  const ScanMatcherConfig matcher;
  ASSERT_TRUE(matcher.point_to_line);
  const ScanMatcherConfig noisy_matcher = matcher.forSensorNoise(0.3, 0.0845, 0.05);
  EXPECT_DOUBLE_EQ(noisy_matcher.score_sigma, 0.3);
  EXPECT_DOUBLE_EQ(noisy_matcher.search_radius, 0.45);
  EXPECT_DOUBLE_EQ(noisy_matcher.occupied_threshold, 0.0845);
  EXPECT_FALSE(noisy_matcher.point_to_line);
  EXPECT_DOUBLE_EQ(noisy_matcher.beam_spacing, 0.5 * matcher.beam_spacing);
  const ScanMatcherConfig coarse_cells = matcher.forSensorNoise(0.3, 0.0845, 0.5);
  EXPECT_TRUE(coarse_cells.point_to_line);  // within a 0.5 m cell
  EXPECT_DOUBLE_EQ(coarse_cells.beam_spacing, matcher.beam_spacing);
  const ScanMatcherConfig precise_matcher = matcher.forSensorNoise(0.01, 0.6255, 0.05);
  EXPECT_DOUBLE_EQ(precise_matcher.score_sigma, matcher.score_sigma);
  EXPECT_DOUBLE_EQ(precise_matcher.occupied_threshold, 0.25);
  EXPECT_TRUE(precise_matcher.point_to_line);
  EXPECT_DOUBLE_EQ(precise_matcher.beam_spacing, matcher.beam_spacing);
}

// Particles that share a map and propose the same pose are one hypothesis: the scan is
// integrated once and their maps keep sharing every tile. With zero motion noise (and no matcher)
// all 8 particles propose the same pose after initialize(): one group, and the 8 maps together
// hold exactly the tiles of one. With motion noise each particle proposes its own pose: 8 groups.
TEST(ParticleFilterTest, ParticlesWithOneMapAndPoseIntegrateOnce) {
  SlamConfig config = testing_room::withoutRealRobotSettings(SlamConfig());
  config.particles = 8;
  config.threads = 1;
  config.matcher.enabled = false;
  SlamConfig quiet = config;
  quiet.motion = testing_room::noiselessMotion();
  const Pose2 start(0.01, 0.02, 0.0);
  const Pose2 step(0.5, 0.0, 0.0);

  ParticleFilter merged(quiet);
  merged.initialize(start, roomScan(start), 0);
  merged.update(step, roomScan(start.compose(step)), 1);
  EXPECT_EQ(merged.lastUpdateGroups(), 1u);
  std::unordered_set<const EvidentialGridMap::Tile*> seen;
  const size_t one_map = merged.particles()[0].map.accumulateUniqueTileBytes(&seen);
  EXPECT_GT(one_map, 0u);
  EXPECT_EQ(merged.mapMemoryBytes(), one_map);

  ParticleFilter separate(config);
  separate.initialize(start, roomScan(start), 0);
  separate.update(step, roomScan(start.compose(step)), 1);
  EXPECT_EQ(separate.lastUpdateGroups(), 8u);
  EXPECT_GT(separate.mapMemoryBytes(), one_map);
}

// A group's members let go of their maps before the group's leader integrates the scan (they
// take the leader's afterwards), so a group of all 8 particles writes its one map in place: every
// tile allocated before the update is the same tile after it, none cloned.
TEST(ParticleFilterTest, OneGroupWritesItsMapInPlace) {
  SlamConfig config = testing_room::withoutRealRobotSettings(SlamConfig());
  config.particles = 8;
  config.threads = 1;
  config.matcher.enabled = false;
  config.motion = testing_room::noiselessMotion();
  const Pose2 start(0.01, 0.02, 0.0);
  const Pose2 step(0.2, 0.0, 0.0);
  ParticleFilter filter(config);
  filter.initialize(start, roomScan(start), 0);
  const auto tilesOf = [](const EvidentialGridMap& map) {
    std::map<std::pair<int, int>, const EvidentialGridMap::Tile*> tiles;
    testing_room::forEachAllocatedTile(map,
                                       [&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
                                         tiles[{tx, ty}] = &tile;
                                       });
    return tiles;
  };
  const auto before = tilesOf(filter.particles()[0].map);
  ASSERT_FALSE(before.empty());
  filter.update(step, roomScan(start.compose(step)), 1);
  ASSERT_EQ(filter.lastUpdateGroups(), 1u);
  const auto after = tilesOf(filter.particles()[0].map);
  for (const auto& [where, tile] : before) {
    ASSERT_EQ(after.count(where), 1u);
    EXPECT_EQ(after.at(where), tile) << "tile " << where.first << " " << where.second;
  }
  for (const Particle& p : filter.particles()) EXPECT_EQ(tilesOf(p.map), after);
}

// The wide-basin match (a default) recovers a heading error ICP alone does not: after one update
// without merging (unmergedConfig) the 8 particles have 8 maps (8 hypotheses), and when the next
// odometry increment is 0.9 rad (52°) off in heading, which ICP from the prediction does not
// recover (point to line recovers 0.6 rad in this small room), each hypothesis runs the multi-start
// search over ±0.95 rad and every particle is brought back onto the truth. With the search off
// (config/sim.yaml) ICP alone stays caught: the best particle is more than 0.1 rad off.
TEST(ParticleFilterTest, WideMatchRecoversLargeHeadingError) {
  const auto run = [](bool wide, size_t* searches) {
    SlamConfig config = unmergedConfig(8);
    if (wide) {
      config = testing_room::withRealRobotSettings(config);
      config.matcher.heading_window = 0.95;
    }
    ParticleFilter filter(config);
    Pose2 truth(-0.5, -0.3, 0.1);
    const auto scan = [](const Pose2& p) { return testing_room::roomScan(p, 0.0, true); };
    filter.initialize(truth, scan(truth), 0);
    const Pose2 step(0.3, 0.0, 0.0);
    truth = truth.compose(step);
    filter.update(step, scan(truth), 1);
    EXPECT_EQ(filter.lastUpdateGroups(), 8u);
    const Pose2 turn(0.3, 0.0, 0.9);  // the robot really went straight
    truth = truth.compose(step);
    filter.update(turn, scan(truth), 2);
    *searches = filter.lastWideMatches();
    for (const Particle& p : filter.particles()) {
      if (!wide) break;
      EXPECT_NEAR(p.pose.x, truth.x, 0.05);
      EXPECT_NEAR(p.pose.y, truth.y, 0.05);
      EXPECT_NEAR(normalizeAngle(p.pose.theta - truth.theta), 0.0, 0.02);
    }
    return std::abs(normalizeAngle(filter.best().pose.theta - truth.theta));
  };
  size_t searches = 0;
  EXPECT_LT(run(true, &searches), 0.02);
  EXPECT_EQ(searches, 8u);
  EXPECT_GT(run(false, &searches), 0.1);
  EXPECT_EQ(searches, 0u);
}

// constrained_merge_ratio: with the ordinary merge off (merge_distance 0), 8 particles sampled
// with motion noise and refined are 8 groups. In the room, where the scan fixes the position
// every way, a 0.5 ratio merges them all within the wider radius (the refinements end within
// centimetres); in a corridor, which leaves the position along it free, it merges none, even
// with a 1 m radius: the spread along it is kept. The same with the wide-basin match (measured
// at the match) and without it (measured at the refined pose). A matcher that is
// point to point (a noisy laser) does not merge wider.
TEST(ParticleFilterTest, ConstrainedMergeOnlyWhereTheScanFixesThePosition) {
  const auto groups = [](bool wide_match, bool corridor, double ratio, bool to_line = true) {
    SlamConfig config = filterConfig(8);
    if (wide_match) config = testing_room::withRealRobotSettings(config);
    config.merge_distance = 0.0;
    config.constrained_merge_ratio = ratio;
    config.constrained_merge_distance = 1.0;
    config.constrained_merge_angle = 0.1;
    config.matcher.point_to_line = to_line;
    ParticleFilter filter(config);
    const auto scan = [corridor](const Pose2& p) {
      return corridor ? testing_room::corridorScan(p) : testing_room::roomScan(p, 0.0, true);
    };
    const Pose2 start(-0.5, -0.3, 0.1), step(0.3, 0.0, 0.0);
    filter.initialize(start, scan(start), 0);
    filter.update(step, scan(start.compose(step)), 1);
    return filter.lastUpdateGroups();
  };
  for (const bool wide_match : {true, false}) {
    SCOPED_TRACE(testing::Message() << "wide-basin match " << wide_match);
    EXPECT_EQ(groups(wide_match, false, 0.0), 8u);
    EXPECT_EQ(groups(wide_match, false, 0.5), 1u);
    EXPECT_EQ(groups(wide_match, true, 0.0), 8u);
    EXPECT_EQ(groups(wide_match, true, 0.5), 8u);
    EXPECT_EQ(groups(wide_match, false, 0.5, /*to_line=*/false), 8u);
  }
}

// hitBeamSubset keeps exactly the beams traceScan makes hits, every stride-th of them: on a room
// scan with invalid (no-return), NaN, too short (< min_range) and too long (>= usable_range)
// readings mixed in, the subset's log plausibility (stride 1) equals the whole scan's at stride 2,
// bit for bit, and it holds half of the hit beams (rounded up).
TEST(ParticleFilterTest, HitBeamSubsetMatchesStridedPlausibility) {
  const SensorModelConfig sensor;
  const BeamModel model(sensor, 0.05);
  const Pose2 pose(-0.4, 0.3, 0.2);
  LaserScan scan = testing_room::roomScan(pose, 0.0, true);
  EvidentialGridMap map(0.05);
  TracedScan traced;
  ScanAccumulator scratch;
  model.traceScan(pose, scan, &traced);
  model.integrateScan(traced, &map, &scratch);
  int hits = 0;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    switch (i % 7) {
      case 1:
        scan.valid[i] = 0;
        break;
      case 3:
        scan.ranges[i] = std::nanf("");
        break;
      case 4:
        scan.ranges[i] = 0.01f;
        break;
      case 5:
        scan.ranges[i] = 25.0f;
        break;
      default:
        ++hits;
    }
  }
  const Pose2 moved = pose.compose(Pose2(0.03, -0.02, 0.01));
  model.traceScan(moved, scan, &traced);
  const double whole = model.scanLogPlausibility(map, traced, 2);
  const LaserScan subset = ParticleFilter::hitBeamSubset(scan, sensor, 2);
  EXPECT_EQ(subset.ranges.size(), static_cast<size_t>((hits + 1) / 2));
  model.traceScan(moved, subset, &traced);
  EXPECT_EQ(model.scanLogPlausibility(map, traced, 1), whole);
  EXPECT_LT(whole, 0.0);
}

}  // namespace
}  // namespace evidential_slam
