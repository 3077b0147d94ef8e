// Localization on a fixed map (core/localization): KLD-sampling's sample counts by hand, and the
// localizer in a hand-made room with a block against one wall (an asymmetric room): tracking from
// a spread start and global localization with either laser model, the particle count shrinking as
// the cloud converges, the motion gate, resets, the anomaly of a removed block, and the refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../test_support.h"
#include "evidential_slam/core/localization/kld_sampling.h"
#include "evidential_slam/core/localization/likelihood_field.h"
#include "evidential_slam/core/localization/localizer.h"
#include "evidential_slam/core/motion_model.h"
#include "evidential_slam/core/particle_filter.h"
#include "evidential_slam/core/slam_engine.h"

namespace evidential_slam {
namespace {

// n(k) = ceil((k - 1) / (2 err) (1 - 2/(9(k - 1)) + sqrt(2/(9(k - 1))) z)^3), by hand:
// k = 2, err = 0.01, z = 0.99: x = 1 - 0.2222222 + 0.4714045 * 0.99 = 1.2444689, 50 x^3 = 96.37.
// k = 11, z = 3: x = 1 - 0.0222222 + 0.1490712 * 3 = 1.4249914, 500 x^3 = 1446.8.
TEST(KldSampling, SampleLimitByHand) {
  EXPECT_EQ(kldSampleLimit(2, 0.01, 0.99, 1, 100000), 97u);
  EXPECT_EQ(kldSampleLimit(11, 0.01, 3.0, 1, 100000), 1447u);
  EXPECT_EQ(kldSampleLimit(2, 0.01, 0.99, 100, 5000), 100u);   // the floor
  EXPECT_EQ(kldSampleLimit(11, 0.01, 3.0, 100, 1000), 1000u);  // the ceiling
  EXPECT_EQ(kldSampleLimit(1, 0.01, 0.99, 100, 5000), 100u);   // one bin: the floor
  EXPECT_EQ(kldSampleLimit(0, 0.01, 0.99, 100, 5000), 100u);
  // More bins, more samples; a larger error allowed, fewer.
  EXPECT_LT(kldSampleLimit(20, 0.01, 0.99, 1, 100000), kldSampleLimit(40, 0.01, 0.99, 1, 100000));
  EXPECT_GT(kldSampleLimit(20, 0.01, 0.99, 1, 100000), kldSampleLimit(20, 0.05, 0.99, 1, 100000));
}

TEST(KldSampling, BinsOfXYAndHeading) {
  KldBins bins(0.5, 0.1);
  EXPECT_TRUE(bins.insert(Pose2(0.1, 0.1, 0.01)));
  EXPECT_FALSE(bins.insert(Pose2(0.4, 0.4, 0.09)));
  EXPECT_TRUE(bins.insert(Pose2(0.6, 0.1, 0.01)));
  EXPECT_TRUE(bins.insert(Pose2(-0.1, 0.1, 0.01)));
  EXPECT_TRUE(bins.insert(Pose2(0.1, 0.1, 0.11)));
  EXPECT_TRUE(bins.insert(Pose2(0.1, 0.1, -0.01)));
  EXPECT_EQ(bins.count(), 5u);
  bins.clear();
  EXPECT_EQ(bins.count(), 0u);
}

// The room (walls at x, y = ±2 m) with a solid block against its east wall, seen from every
// side: 360 beams over a full turn from `pose`. The block makes the room asymmetric.
constexpr double kBlockX0 = 1.6, kBlockX1 = 2.0, kBlockY0 = 0.3, kBlockY1 = 1.3;
LaserScan blockRoomScan(const Pose2& pose, double stamp, bool with_block) {
  LaserScan scan;
  scan.stamp = stamp;
  scan.max_range = 30.0f;
  for (int i = 0; i < 360; ++i) {
    const double bearing = -M_PI + i * (2 * M_PI / 360);
    const double a = pose.theta + bearing;
    const double c = std::cos(a), s = std::sin(a);
    double t = testing_room::roomWallRange(pose, c, s);
    if (with_block) {
      // Ray and box, slab by slab.
      double t0 = 0.0, t1 = 1e9;
      const auto slab = [&](double o, double d, double lo, double hi) {
        if (std::abs(d) < 1e-12) return o >= lo && o <= hi;
        double ta = (lo - o) / d, tb = (hi - o) / d;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        return t0 <= t1;
      };
      if (slab(pose.x, c, kBlockX0, kBlockX1) && slab(pose.y, s, kBlockY0, kBlockY1)) {
        t = std::min(t, t0);
      }
    }
    scan.ranges.push_back(static_cast<float>(t));
    scan.bearings.push_back(static_cast<float>(bearing));
    scan.valid.push_back(1);
  }
  return scan;
}

// The map frame is the room's shifted by half a cell, so that its walls (at whole metres) lie on
// cell centres, where a hit puts an occupied mass above 1/2 (on a cell border, 0.48 in each of two
// cells).
constexpr double kShift = 0.025;
Pose2 inMap(const Pose2& room) { return Pose2(room.x + kShift, room.y + kShift, room.theta); }

SlamConfig slamConfig() {
  SlamConfig c = testing_room::withoutRealRobotSettings(SlamConfig());
  c.threads = 1;
  c.seed = 3;
  return c;
}

// The room, mapped from exact poses (no matcher, no motion noise).
EvidentialGridMap roomMap(bool with_block = true) {
  SlamConfig exact = slamConfig();
  exact.particles = 1;
  exact.matcher.enabled = false;
  exact.motion = testing_room::noiselessMotion();
  SlamEngine engine(exact);
  const std::vector<Pose2> poses = {Pose2(0, 0, 0),         Pose2(-0.6, -0.6, 0.0),
                                    Pose2(-0.6, 0.3, 0.0),  Pose2(1.3, -1.2, 1.5),
                                    Pose2(-1.3, 1.2, -0.5), Pose2(1.2, 1.6, 3.0)};
  double stamp = 1.0;
  for (int lap = 0; lap < 2; ++lap) {
    for (const Pose2& p : poses) {
      engine.processScan(inMap(p), blockRoomScan(p, stamp++, with_block));
    }
  }
  return engine.bestMap();
}

double distance(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// A route through the room (the true poses, room frame) and the odometry of it, drifting: 2 % too
// long and turning 0.01 rad too far per step.
struct Route {
  std::vector<Pose2> truth, odometry;
};
Route route(int steps, const Pose2& start = Pose2(-1.2, -1.2, 0.6)) {
  Route r;
  Pose2 truth = start, odometry(5.0, 3.0, -1.0);
  for (int i = 0; i < steps; ++i) {
    r.truth.push_back(truth);
    r.odometry.push_back(odometry);
    const Pose2 step(0.12, 0.0, i % 12 < 6 ? 0.25 : -0.2);
    const Pose2 next = truth.compose(step);
    if (std::abs(next.x) > 1.5 || std::abs(next.y) > 1.5) {
      truth = truth.compose(Pose2(0.0, 0.0, 1.2));
      odometry = odometry.compose(Pose2(0.0, 0.0, 1.21));
    } else {
      truth = next;
      odometry = odometry.compose(Pose2(0.1224, 0.0, step.theta + 0.01));
    }
  }
  return r;
}

LocalizationConfig localizationConfig(
    const std::string& model = LocalizationConfig().laser_model_type) {
  LocalizationConfig c;
  c.laser_model_type = model;
  c.min_particles = 50;
  c.max_particles = 3000;
  c.update_min_d = 0.1;
  c.update_min_a = 0.2;
  c.resample_interval = 1;
  c.selective_resampling = false;  // resampled at every update (SelectiveResampling tests it)
  return c;
}

// Started 0.4 m and 0.3 rad off with a covariance that covers that, the estimate settles on the
// truth; KLD-sampling drew hundreds of particles for the spread start and keeps far fewer once
// the cloud has converged: within `converged_bins` bins, `shrink` times fewer than at the start.
void convergesFromASpreadStart(const std::string& model, size_t converged_bins, size_t shrink) {
  Localizer loc(localizationConfig(model), slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  const Route r = route(60);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << 0.25, 0.25, 0.1;
  const Pose2 start = inMap(r.truth[0]).compose(Pose2(0.3, -0.25, 0.3));
  ASSERT_TRUE(loc.resetAt(start, cov, nullptr));
  const size_t initial = loc.particles().size();
  EXPECT_GT(initial, 300u);
  size_t processed = 0;
  for (size_t i = 0; i < r.truth.size(); ++i) {
    const LocalizationUpdate u =
        loc.processScan(r.odometry[i], blockRoomScan(r.truth[i], 1.0 + 0.1 * i, true));
    ASSERT_FALSE(u.rejected) << u.why;
    processed += u.processed ? 1 : 0;
    if (i >= 10) {
      EXPECT_LT(distance(loc.estimate().mean, inMap(r.truth[i])), 0.05) << i;
      EXPECT_LT(std::abs(normalizeAngle(loc.estimate().mean.theta - r.truth[i].theta)), 0.03) << i;
    }
  }
  EXPECT_GT(processed, 30u);
  const size_t converged = kldSampleLimit(converged_bins, 0.01, 0.99, 50, 3000);
  EXPECT_LE(loc.particles().size(), converged);
  EXPECT_LT(shrink * loc.particles().size(), initial);
  EXPECT_LT(loc.estimate().covariance(0, 0), 0.01);
  // The map -> odom correction maps the odometry onto the estimate.
  const Pose2 on_map = loc.mapToOdom().compose(r.odometry.back());
  EXPECT_LT(distance(on_map, loc.estimate().mean), 1e-9);
  EXPECT_EQ(loc.trajectory().size(), r.truth.size());
}

// The default model (beam): a converged cloud straddles at most one bin border in x, y and
// heading, at most 8 bins.
TEST(Localizer, ConvergesFromASpreadStartAndShrinksTheCloud) {
  convergesFromASpreadStart(LocalizationConfig().laser_model_type, 8, 4);
}

// amcl's weight 1 + Σ p^3 is flat near the optimum (a beam ending 0.1 m off a wall keeps
// (0.84 / 0.955)^3 = 0.68 of its share), so the cloud stays about 0.1 m wide (covariance
// 0.006-0.008 m^2 here against 0.0003 with the beam model): twice the bins.
TEST(Localizer, LikelihoodFieldConvergesFromASpreadStartAndTracks) {
  convergesFromASpreadStart("likelihood_field", 16, 2);
}

// Global localization in the asymmetric room: max_particles over its free space (then drawn where
// the first scan fits: global_search), the estimate on the truth within a few updates, and the
// cloud shrinks as KLD-sampling asks: below `shrunk_below` particles from update `shrunk_by` on,
// within `converged_bins` bins at the end.
void globalLocalization(const std::string& model, size_t shrunk_by, size_t converged_bins,
                        size_t shrunk_below = 600) {
  LocalizationConfig c = localizationConfig(model);
  c.max_particles = 2000;
  Localizer loc(c, slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  ASSERT_TRUE(loc.globalLocalization(nullptr));
  EXPECT_EQ(loc.particles().size(), 2000u);
  double x_min = 1e9, x_max = -1e9;
  for (const LocalizationParticle& p : loc.particles()) {
    x_min = std::min(x_min, p.pose.x);
    x_max = std::max(x_max, p.pose.x);
    EXPECT_LT(std::abs(p.pose.x - kShift), 2.0);  // inside the room
    EXPECT_LT(std::abs(p.pose.y - kShift), 2.0);
  }
  EXPECT_LT(x_min, -1.5);
  EXPECT_GT(x_max, 1.5);
  const Route r = route(40);
  for (size_t i = 0; i < r.truth.size(); ++i) {
    loc.processScan(r.odometry[i], blockRoomScan(r.truth[i], 1.0 + 0.1 * i, true));
    if (i >= 15) {
      EXPECT_LT(distance(loc.estimate().mean, inMap(r.truth[i])), 0.05) << i;
    }
    if (i >= shrunk_by) {
      EXPECT_LT(loc.particles().size(), shrunk_below) << i;
    }
  }
  EXPECT_LE(loc.particles().size(), kldSampleLimit(converged_bins, 0.01, 0.99, 50, 2000));
}

// The default model (beam): from the first resampling on, the scans have singled the pose out.
TEST(Localizer, GlobalLocalizationInAnAsymmetricRoom) {
  globalLocalization(LocalizationConfig().laser_model_type, 0, 8);
}

// amcl's weight bounds what one scan can single out (at most 1 + 30 p^3 against 1 over 30 beams),
// so the cloud of 2000 takes a few updates more to shrink; converged, it is about 0.1 m wide, twice
// the bins (as LikelihoodFieldConvergesFromASpreadStartAndTracks).
// The mixture proposal's samples around the scan match (scan_proposal_fraction) add to that width
// where the match scores the scan above the prediction: up to 651 particles (beam: below 600).
TEST(Localizer, LikelihoodFieldGlobalLocalizationInAnAsymmetricRoom) {
  globalLocalization("likelihood_field", 8, 16, 800);
}

// Global localization with few particles: the errors of the estimate along a route, from
// globalLocalization with `search` on or off.
std::vector<double> globalErrors(bool search, int particles, uint64_t seed) {
  LocalizationConfig c = localizationConfig();
  c.min_particles = particles;
  c.max_particles = particles;
  c.global_search = search;
  SlamConfig slam = slamConfig();
  slam.seed = seed;
  Localizer loc(c, slam);
  EXPECT_TRUE(loc.setMap(roomMap(), nullptr));
  EXPECT_TRUE(loc.globalLocalization(nullptr));
  const Route r = route(30);
  std::vector<double> errors;
  for (size_t i = 0; i < r.truth.size(); ++i) {
    loc.processScan(r.odometry[i], blockRoomScan(r.truth[i], 1.0 + 0.1 * i, true));
    errors.push_back(distance(loc.estimate().mean, inMap(r.truth[i])) +
                     std::abs(normalizeAngle(loc.estimate().mean.theta - r.truth[i].theta)));
  }
  return errors;
}

// 50 particles over the room's 16 m² and every heading: a uniform spread rarely puts one in the
// scan matcher's basin around the truth, and the cloud settles metres off on 3 of 5 seeds (with
// global_search off). The search of the first scan puts the hypotheses where the scan fits (the
// block makes the room asymmetric: one pose fits): the estimate is on the truth (position error
// in m plus heading error in rad below 0.05) from the first update, on every seed.
TEST(Localizer, GlobalSearchFindsThePoseAtTheFirstScan) {
  int uniform_lost = 0;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const std::vector<double> errors = globalErrors(true, 50, seed);
    for (size_t i = 0; i < errors.size(); ++i) EXPECT_LT(errors[i], 0.05) << seed << " " << i;
    const std::vector<double> uniform = globalErrors(false, 50, seed);
    uniform_lost += uniform.back() > 1.0 ? 1 : 0;
  }
  EXPECT_GE(uniform_lost, 2);
}

// The ray-traced beam model (laser_model_type beam_traced, the lookup's reference) converges as
// the lookup does.
TEST(Localizer, TracedBeamModelConvergesFromASpreadStart) {
  convergesFromASpreadStart("beam_traced", 8, 4);
}

// The beam model builds its lookup once, at the first update, and reports its size.
TEST(Localizer, BeamModelBuildsItsLookupOnce) {
  Localizer loc(localizationConfig(), slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  ASSERT_TRUE(loc.resetAt(inMap(Pose2(0, 0, 0)), Eigen::Matrix3d::Identity() * 1e-4, nullptr));
  EXPECT_EQ(loc.stats().lookup_bytes, 0u);
  loc.processScan(Pose2(0, 0, 0), blockRoomScan(Pose2(0, 0, 0), 1.0, true));
  const size_t bytes = loc.stats().lookup_bytes;
  const CellBox box = loc.map().observedBox();
  EXPECT_GE(bytes, static_cast<size_t>(box.width()) * box.height() * 10u);  // masses, 2 fields
  EXPECT_GT(loc.stats().lookup_build_s, 0.0);
  loc.processScan(Pose2(0.2, 0, 0), blockRoomScan(Pose2(0.2, 0, 0), 1.1, true));
  EXPECT_EQ(loc.stats().lookup_bytes, bytes);
}

// amcl's selective resampling: a scan without a hit beam weighs every particle alike (N_eff = N),
// so the cloud is not resampled; a scan that singles out the pose is. Without it both are.
TEST(Localizer, SelectiveResamplingOnlyWhenTheWeightsConcentrate) {
  for (const bool selective : {true, false}) {
    LocalizationConfig c = localizationConfig();
    c.selective_resampling = selective;
    Localizer loc(c, slamConfig());
    ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    cov.diagonal() << 0.04, 0.04, 0.02;
    ASSERT_TRUE(loc.resetAt(inMap(Pose2(0, 0, 0)), cov, nullptr));
    LaserScan blind = blockRoomScan(Pose2(0, 0, 0), 1.0, true);
    for (uint8_t& v : blind.valid) v = 0;  // no returns: nothing to weigh
    const double drawn = static_cast<double>(loc.particles().size());
    const LocalizationUpdate flat = loc.processScan(Pose2(0, 0, 0), blind);
    ASSERT_TRUE(flat.processed);
    EXPECT_NEAR(flat.effective_particles, drawn, 1e-6 * drawn);
    EXPECT_EQ(flat.resampled, !selective);
    const LocalizationUpdate sharp =
        loc.processScan(Pose2(0.2, 0, 0), blockRoomScan(Pose2(0.2, 0, 0), 1.1, true));
    ASSERT_TRUE(sharp.processed);
    EXPECT_TRUE(sharp.resampled);
  }
}

// Short readings: on the map of the room without the block, the block's beams end short in
// confident free space. Their rate, measured at the estimate, rises to about the block's share of
// the weighed beams, and the pose is still tracked; in the room as mapped it stays near 0.
TEST(Localizer, ShortReadingsRateFollowsAnUnexpectedObstacle) {
  const Route r = route(40);
  double rates[2] = {0.0, 0.0};
  for (const bool block_in_map : {true, false}) {
    Localizer loc(localizationConfig(), slamConfig());
    ASSERT_TRUE(loc.setMap(roomMap(block_in_map), nullptr));
    ASSERT_TRUE(loc.resetAt(inMap(r.truth[0]), Eigen::Matrix3d::Identity() * 1e-3, nullptr));
    double rate = 0.0;
    int updates = 0;
    for (size_t i = 0; i < r.truth.size(); ++i) {
      const LocalizationUpdate u =
          loc.processScan(r.odometry[i], blockRoomScan(r.truth[i], 1.0 + 0.1 * i, true));
      EXPECT_LT(distance(loc.estimate().mean, inMap(r.truth[i])), 0.07) << i;
      if (u.processed && i >= 20) {
        rate += u.short_rate;
        ++updates;
      }
    }
    rates[block_in_map ? 0 : 1] = rate / std::max(1, updates);
  }
  EXPECT_LT(rates[0], 0.02);
  EXPECT_GT(rates[1], 0.03);
}

// A kidnap: after tracking `kidnap_at` scans of the route, the robot is carried 2 m (and turned)
// while its odometry goes on as if it had made one ordinary step, then drives on from there.
// Returns the error of the estimate at each scan after the kidnap.
std::vector<double> kidnapped(const LocalizationConfig& c, int* respread_at = nullptr,
                              uint64_t seed = slamConfig().seed, int kidnap_at = 70,
                              const ConflictAlarmConfig& alarm = ConflictAlarmConfig(),
                              int* kidnap_alarm_at = nullptr) {
  SlamConfig slam = slamConfig();
  slam.seed = seed;
  Localizer loc(c, slam, alarm);
  EXPECT_TRUE(loc.setMap(roomMap(), nullptr));
  const Route before = route(kidnap_at);
  const Pose2 last = before.truth.back();
  Pose2 carried;
  for (int k = 0; k < 12; ++k) {  // 2 m away, inside the route's part of the room
    const double a = k * M_PI / 6;
    carried = Pose2(last.x + 2.0 * std::cos(a), last.y + 2.0 * std::sin(a), last.theta + 2.0);
    if (std::abs(carried.x) < 1.4 && std::abs(carried.y) < 1.4) break;
  }
  EXPECT_NEAR(distance(carried, last), 2.0, 1e-9);
  EXPECT_LT(std::max(std::abs(carried.x), std::abs(carried.y)), 1.4);
  const Route after = route(40, carried);
  EXPECT_TRUE(loc.resetAt(inMap(before.truth[0]), Eigen::Matrix3d::Identity() * 1e-3, nullptr));
  double stamp = 1.0;
  for (int i = 0; i < kidnap_at; ++i) {
    const LocalizationUpdate u =
        loc.processScan(before.odometry[i], blockRoomScan(before.truth[i], stamp += 0.1, true));
    EXPECT_FALSE(u.respread) << i;  // no false alarm while tracking
  }
  EXPECT_LT(distance(loc.estimate().mean, inMap(last)), 0.05);
  // The odometry after the kidnap: one ordinary step, then the new route's increments.
  const Pose2 step(0.12, 0.0, 0.1);
  Pose2 odometry = before.odometry.back().compose(step);
  std::vector<double> errors;
  for (size_t i = 0; i < after.truth.size(); ++i) {
    if (i > 0) odometry = odometry.compose(after.odometry[i - 1].between(after.odometry[i]));
    const LocalizationUpdate u =
        loc.processScan(odometry, blockRoomScan(after.truth[i], stamp += 0.1, true));
    if (u.respread && respread_at != nullptr && *respread_at < 0) {
      *respread_at = static_cast<int>(i);
    }
    if (u.kidnap_alarm.rising && kidnap_alarm_at != nullptr && *kidnap_alarm_at < 0) {
      *kidnap_alarm_at = static_cast<int>(i);
    }
    errors.push_back(distance(loc.estimate().mean, inMap(after.truth[i])));
  }
  return errors;
}

// The kidnap makes the scans at the estimate contradict the map far more than while tracking:
// the conflict alarm fires within a few scans, the particles are spread over the free space, and
// the estimate is back on the truth within 20 scans of the kidnap and stays there. Without the
// recovery the filter stays where the robot was.
TEST(Localizer, KidnapIsDetectedAndRecovered) {
  LocalizationConfig c = localizationConfig();
  c.max_particles = 2000;
  c.kidnap_recovery = true;
  int respread_at = -1;
  const std::vector<double> errors = kidnapped(c, &respread_at);
  EXPECT_GE(respread_at, 0);
  EXPECT_LE(respread_at, 5);
  for (size_t i = 20; i < errors.size(); ++i) EXPECT_LT(errors[i], 0.1) << i;

  c.kidnap_recovery = false;
  respread_at = -1;
  const std::vector<double> lost = kidnapped(c, &respread_at);
  EXPECT_EQ(respread_at, -1);
  EXPECT_GT(lost[20], 0.5);
}

// The kidnap alarm alone (the conflict alarm off, as where a noisy laser contradicts nothing
// confident), 20 updates after the start: its baseline began at the first updates (the cloud
// started narrow), so it is armed; the scans at the particles fall far below the baseline's
// plausibility, the alarm fires within 3 scans and the estimate is back on the truth by 20 scans.
// With the threshold out of reach (1000 envelopes) nothing fires and the filter
// stays lost.
TEST(Localizer, KidnapAlarmOnPlausibilityDetectsAnEarlyKidnap) {
  ConflictAlarmConfig off;
  off.enabled = false;
  LocalizationConfig c = localizationConfig();
  c.max_particles = 2000;
  c.kidnap_recovery = true;
  int respread_at = -1, alarm_at = -1;
  const std::vector<double> errors =
      kidnapped(c, &respread_at, slamConfig().seed, 20, off, &alarm_at);
  EXPECT_GE(alarm_at, 0);
  EXPECT_LE(alarm_at, 3);
  EXPECT_EQ(respread_at, alarm_at);
  for (size_t i = 20; i < errors.size(); ++i) EXPECT_LT(errors[i], 0.1) << i;

  c.kidnap_alarm_factor = 1000.0;
  respread_at = alarm_at = -1;
  const std::vector<double> lost =
      kidnapped(c, &respread_at, slamConfig().seed, 20, off, &alarm_at);
  EXPECT_EQ(alarm_at, -1);
  EXPECT_EQ(respread_at, -1);
  EXPECT_GT(lost[20], 0.5);
}

// The kidnap's recovery with 50 particles: spread uniformly (global_search off), the cloud is
// still 1-2 m off 2 to 20 scans after the spread on 2 of 4 seeds; drawn where the scan at the
// alarm fits, it is on the truth (below 0.05 m) from the next update on, on every seed.
TEST(Localizer, KidnapRecoverySearchesWhereTheScanFits) {
  int uniform_late = 0;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    for (bool search : {true, false}) {
      LocalizationConfig c = localizationConfig();
      c.min_particles = 50;
      c.max_particles = 50;
      c.kidnap_recovery = true;
      c.global_search = search;
      int at = -1;
      const std::vector<double> errors = kidnapped(c, &at, seed);
      ASSERT_GE(at, 0) << seed;
      EXPECT_LE(at, 5) << seed;
      bool late = false;
      for (size_t i = static_cast<size_t>(at) + 2; i < errors.size(); ++i) {
        if (search) {
          EXPECT_LT(errors[i], 0.05) << seed << " " << i;
        }
        late = late || errors[i] > 0.5;
      }
      if (!search) uniform_late += late ? 1 : 0;
    }
  }
  EXPECT_GE(uniform_late, 1);
}

// Odometry that under-reports every turn by 30 % (0.25 rad turned, 0.175 reported: 0.075 rad of
// heading error per update, as real wheels slip; the SLAM's alpha_* of the real preset spread such
// a step's heading by 0.013 rad, 6 σ short of it): the proposal samples the drift (odom_drift_*, a
// heading σ of √(0.006 · 0.175 + 0.006 · 0.12) = 0.042 rad here) and the estimate stays on the
// truth (worst position error in m plus heading error in rad over the run below 0.1). With the
// drift off (the floors alone) and no mixture proposal the same run loses the heading (above 0.3).
double worstErrorWithSlippingTurns(const LocalizationConfig& c) {
  Localizer loc(c, slamConfig());
  EXPECT_TRUE(loc.setMap(roomMap(), nullptr));
  Pose2 truth(-1.2, -1.2, 0.6), odometry(5.0, 3.0, -1.0);
  EXPECT_TRUE(loc.resetAt(inMap(truth), Eigen::Matrix3d::Identity() * 1e-4, nullptr));
  double worst = 0.0;
  for (int i = 0; i < 60; ++i) {
    loc.processScan(odometry, blockRoomScan(truth, 1.0 + 0.1 * i, true));
    worst = std::max(worst, distance(loc.estimate().mean, inMap(truth)) +
                                std::abs(normalizeAngle(loc.estimate().mean.theta - truth.theta)));
    const double turn = i % 12 < 6 ? 0.25 : -0.2;
    const Pose2 next = truth.compose(Pose2(0.12, 0.0, turn));
    if (std::abs(next.x) > 1.5 || std::abs(next.y) > 1.5) {
      truth = truth.compose(Pose2(0.0, 0.0, 1.2));
      odometry = odometry.compose(Pose2(0.0, 0.0, 0.7 * 1.2));
    } else {
      truth = next;
      odometry = odometry.compose(Pose2(0.12, 0.0, 0.7 * turn));
    }
  }
  return worst;
}

TEST(Localizer, TracksOdometryThatSlipsInTurns) {
  LocalizationConfig c = localizationConfig();
  EXPECT_LT(worstErrorWithSlippingTurns(c), 0.1);
  c.odom_drift_rot_rot = c.odom_drift_rot_trans = c.odom_drift_trans_trans =
      c.odom_drift_trans_rot = 0.0;
  // Without the drift, the mixture proposal (the samples drawn around the scan match) still
  // tracks it; without either it is lost.
  EXPECT_LT(worstErrorWithSlippingTurns(c), 0.1);
  c.odom_failure_rate = 0.0;
  EXPECT_GT(worstErrorWithSlippingTurns(c), 0.3);
}

// Odometry that reports the robot driving forward while it backs up (a reversed reading, as
// freiburg-079's raw odometry does for 0.7 m), for `reversed` updates of 0.12 m, then right again:
// the errors of the estimate (position, m) after each update. The drift proposal's along-track σ
// is √(0.006 · 0.12) = 0.027 m per update, 9 σ short of the 0.24 m each reversed update misses by.
std::vector<double> errorsWithReversedOdometry(const LocalizationConfig& c, int reversed,
                                               int from = 8, int updates = 22,
                                               std::vector<uint64_t>* matches = nullptr) {
  Localizer loc(c, slamConfig());
  EXPECT_TRUE(loc.setMap(roomMap(), nullptr));
  Pose2 truth(-1.3, -0.5, 0.0), odometry(5.0, 3.0, -1.0);
  EXPECT_TRUE(loc.resetAt(inMap(truth), Eigen::Matrix3d::Identity() * 1e-4, nullptr));
  std::vector<double> errors;
  for (int i = 0; i < updates; ++i) {
    const LocalizationUpdate u =
        loc.processScan(odometry, blockRoomScan(truth, 1.0 + 0.1 * i, true));
    EXPECT_TRUE(u.processed);
    errors.push_back(distance(loc.estimate().mean, inMap(truth)));
    if (matches != nullptr) matches->push_back(loc.stats().proposal_matches);
    const bool backing = i >= from && i < from + reversed;
    truth = truth.compose(Pose2(backing ? -0.12 : 0.12, 0.0, 0.0));
    odometry = odometry.compose(Pose2(0.12, 0.0, 0.0));
  }
  return errors;
}

// The mixture proposal (odom_failure_*, scan_proposal_fraction) tracks the robot through 4
// reversed updates (0.96 m of odometry error), within 0.1 m at every update; the drift alone loses
// it by about that much and is still more than 0.5 m off 10 updates later.
TEST(Localizer, MixtureProposalTracksReversedOdometry) {
  LocalizationConfig c = localizationConfig();
  const std::vector<double> mixed = errorsWithReversedOdometry(c, 4);
  EXPECT_LT(*std::max_element(mixed.begin(), mixed.end()), 0.1);
  c.odom_failure_rate = 0.0;  // the odometry never fails: the drift alone
  const std::vector<double> drift = errorsWithReversedOdometry(c, 4);
  EXPECT_GT(*std::min_element(drift.end() - 8, drift.end()), 0.5);
}

// While the odometry is right the mixture proposal changes little: the same run without the
// reversal stays within 0.05 m either way.
TEST(Localizer, MixtureProposalKeepsTracking) {
  LocalizationConfig c = localizationConfig();
  const std::vector<double> mixed = errorsWithReversedOdometry(c, 0);
  EXPECT_LT(*std::max_element(mixed.begin(), mixed.end()), 0.05);
  c.odom_failure_rate = 0.0;
  const std::vector<double> drift = errorsWithReversedOdometry(c, 0);
  EXPECT_LT(*std::max_element(drift.begin(), drift.end()), 0.05);
}

// The mixture proposal matches the scan only where the odometry's prediction explains it worse
// than at any recent update (or the last scan was less plausible than usual): not while the
// odometry is right once the gate's baseline holds 10 updates, but at the reversed updates, where
// it still tracks.
TEST(Localizer, MixtureProposalMatchesOnlyWhereThePredictionFalls) {
  const LocalizationConfig c = localizationConfig();
  std::vector<uint64_t> matches;
  const std::vector<double> right = errorsWithReversedOdometry(c, 0, 16, 24, &matches);
  EXPECT_LT(*std::max_element(right.begin(), right.end()), 0.05);
  // The first update is weighed without motion (no proposal); the next 10 build the baseline.
  EXPECT_GE(matches[11], 10u);
  EXPECT_LE(matches.back() - matches[11], 2u);  // at most 2 of the last 12 right updates
  matches.clear();
  const std::vector<double> reversed = errorsWithReversedOdometry(c, 4, 16, 24, &matches);
  EXPECT_LT(*std::max_element(reversed.begin(), reversed.end()), 0.1);
  // The updates after the reversed moves 16-19: each matched.
  EXPECT_EQ(matches[20] - matches[16], 4u);
}

// Scans within update_min_d and update_min_a of the last update only move the estimate by the
// odometry; the first scan after a reset is always weighed.
TEST(Localizer, MotionGate) {
  Localizer loc(localizationConfig(), slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  ASSERT_TRUE(loc.resetAt(inMap(Pose2(0, 0, 0)), Eigen::Matrix3d::Identity() * 1e-4, nullptr));
  EXPECT_TRUE(loc.processScan(Pose2(0, 0, 0), blockRoomScan(Pose2(0, 0, 0), 1.0, true)).processed);
  const LocalizationUpdate small =
      loc.processScan(Pose2(0.05, 0, 0.1), blockRoomScan(Pose2(0.05, 0, 0.1), 1.1, true));
  EXPECT_FALSE(small.processed);
  EXPECT_FALSE(small.rejected);
  EXPECT_LT(distance(loc.estimate().mean, inMap(Pose2(0.05, 0, 0))), 0.03);
  EXPECT_TRUE(
      loc.processScan(Pose2(0.11, 0, 0), blockRoomScan(Pose2(0.11, 0, 0), 1.2, true)).processed);
  EXPECT_TRUE(loc.processScan(Pose2(0.11, 0, 0.21), blockRoomScan(Pose2(0.11, 0, 0.21), 1.3, true))
                  .processed);
  EXPECT_EQ(loc.stats().scans_processed, 3u);
  EXPECT_EQ(loc.stats().scans_received, 4u);
}

// A robot standing still for a minute (600 scans at 10 Hz), its odometry jittering by a few
// millimetres and its scans by range noise: no update passes the motion gate (amcl's
// update_min_d/_a), so the published pose moves by the odometry's jitter only, < 0.01 m.
TEST(Localizer, StandingStillThePoseStays) {
  LocalizationConfig c = localizationConfig();
  c.update_min_d = LocalizationConfig().update_min_d;  // amcl's defaults
  c.update_min_a = LocalizationConfig().update_min_a;
  Localizer loc(c, slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  const Route r = route(30);
  ASSERT_TRUE(loc.resetAt(inMap(r.truth[0]), Eigen::Matrix3d::Identity() * 1e-3, nullptr));
  double stamp = 1.0;
  for (size_t i = 0; i < r.truth.size(); ++i) {
    loc.processScan(r.odometry[i], blockRoomScan(r.truth[i], stamp += 0.1, true));
  }
  const Pose2 still = loc.estimate().mean;
  Rng rng = Rng::forStream(11, 0, 0);
  double moved = 0.0;
  uint64_t processed = 0;
  for (int i = 0; i < 600; ++i) {
    const Pose2 jitter(0.002 * rng.gaussian(), 0.002 * rng.gaussian(), 0.002 * rng.gaussian());
    LaserScan scan = blockRoomScan(r.truth.back(), stamp += 0.1, true);
    for (float& range : scan.ranges) range += static_cast<float>(0.01 * rng.gaussian());
    processed += loc.processScan(r.odometry.back().compose(jitter), scan).processed ? 1 : 0;
    moved = std::max(moved, distance(loc.estimate().mean, still));
  }
  EXPECT_EQ(processed, 0u);
  EXPECT_LT(moved, 0.01);
}

// resetAt moves the cloud (the kidnapped robot told where it is) and the next scan is weighed
// there; the configured initial covariance is used when none is given.
TEST(Localizer, ResetMovesTheCloud) {
  LocalizationConfig c = localizationConfig();
  c.initial_cov_xx = c.initial_cov_yy = 0.01;
  c.initial_cov_aa = 0.01;
  Localizer loc(c, slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  ASSERT_TRUE(loc.resetAt(inMap(Pose2(-1.0, -1.0, 0.0)), nullptr));
  double sx = 0.0;
  for (const LocalizationParticle& p : loc.particles()) {
    const double dx = p.pose.x - inMap(Pose2(-1.0, -1.0, 0.0)).x;
    sx += dx * dx;
  }
  EXPECT_NEAR(std::sqrt(sx / loc.particles().size()), 0.1, 0.03);
  loc.processScan(Pose2(3, 3, 0), blockRoomScan(Pose2(-1.0, -1.0, 0.0), 1.0, true));
  EXPECT_LT(distance(loc.estimate().mean, inMap(Pose2(-1.0, -1.0, 0.0))), 0.05);
  ASSERT_TRUE(loc.resetAt(inMap(Pose2(0.8, -1.0, 1.0)), nullptr));
  const LocalizationUpdate u =
      loc.processScan(Pose2(3.5, 3, 0), blockRoomScan(Pose2(0.8, -1.0, 1.0), 2.0, true));
  EXPECT_TRUE(u.processed);
  EXPECT_LT(distance(loc.estimate().mean, inMap(Pose2(0.8, -1.0, 1.0))), 0.05);
}

// On the map made with the block, scans of the room without it pass through the block's cells: the
// anomaly marks the block and hardly anything else, while the pose stays within 7 cm (the scans
// contradict the map where the block was).
TEST(Localizer, AnomalyMarksARemovedObstacle) {
  Localizer loc(localizationConfig(), slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(true), nullptr));
  const Route r = route(40);
  ASSERT_TRUE(loc.resetAt(inMap(r.truth[0]), Eigen::Matrix3d::Identity() * 1e-3, nullptr));
  for (size_t i = 0; i < r.truth.size(); ++i) {
    loc.processScan(r.odometry[i], blockRoomScan(r.truth[i], 1.0 + 0.1 * i, false));
    EXPECT_LT(distance(loc.estimate().mean, inMap(r.truth[i])), 0.07) << i;
  }
  double block = 0.0, elsewhere = 0.0;
  loc.anomaly().forEach([&](int x, int y, float bits) {
    const Eigen::Vector2d p = loc.map().cellCenter(CellIndex{x, y});
    const Eigen::Vector2d q = p - Eigen::Vector2d(kShift, kShift);  // room frame
    const bool in_block = q.x() > kBlockX0 - 0.1 && q.x() < kBlockX1 - 0.05 &&
                          q.y() > kBlockY0 - 0.1 && q.y() < kBlockY1 + 0.1;
    (in_block ? block : elsewhere) += bits;
  });
  EXPECT_GT(block, 50.0);
  EXPECT_LT(elsewhere, 0.05 * block);
  // Localizing in the room as it was mapped adds next to none.
  Localizer same(localizationConfig(), slamConfig());
  ASSERT_TRUE(same.setMap(roomMap(true), nullptr));
  ASSERT_TRUE(same.resetAt(inMap(r.truth[0]), Eigen::Matrix3d::Identity() * 1e-3, nullptr));
  for (size_t i = 0; i < r.truth.size(); ++i) {
    same.processScan(r.odometry[i], blockRoomScan(r.truth[i], 1.0 + 0.1 * i, true));
  }
  EXPECT_LT(same.anomaly().total(), 0.05 * block);
}

// The proposal is the motion model alone: a cloud drawn 4 cm beside the truth is weighed where it
// is (no particle is matched onto the scan), while the estimate is its mean refined by one scan
// match, kept because the scan is more plausible there. Without the matcher the estimate stays
// the cloud's mean.
TEST(Localizer, OneScanMatchRefinesTheEstimateNotTheParticles) {
  const Pose2 truth = inMap(Pose2(-0.5, 0.4, 0.3));
  const Pose2 start = truth.compose(Pose2(0.04, 0.0, 0.0));
  const LaserScan scan = blockRoomScan(Pose2(-0.5, 0.4, 0.3), 1.0, true);
  const auto particleMean = [](const Localizer& loc) {
    double x = 0.0, y = 0.0;
    for (const LocalizationParticle& p : loc.particles()) {
      x += p.weight * p.pose.x;
      y += p.weight * p.pose.y;
    }
    return Pose2(x, y, 0.0);
  };

  Localizer loc(localizationConfig(), slamConfig());
  ASSERT_TRUE(loc.setMap(roomMap(), nullptr));
  ASSERT_TRUE(loc.resetAt(start, Eigen::Matrix3d::Identity() * 1e-6, nullptr));
  ASSERT_TRUE(loc.processScan(Pose2(0, 0, 0), scan).processed);
  EXPECT_NEAR(distance(particleMean(loc), truth), 0.04, 0.005);
  EXPECT_LT(distance(loc.estimate().mean, truth), 0.01);
  EXPECT_EQ(loc.stats().scan_matches, 1u);

  SlamConfig no_matcher = slamConfig();
  no_matcher.matcher.enabled = false;
  Localizer plain(localizationConfig(), no_matcher);
  ASSERT_TRUE(plain.setMap(roomMap(), nullptr));
  ASSERT_TRUE(plain.resetAt(start, Eigen::Matrix3d::Identity() * 1e-6, nullptr));
  ASSERT_TRUE(plain.processScan(Pose2(0, 0, 0), scan).processed);
  EXPECT_NEAR(distance(plain.estimate().mean, truth), 0.04, 0.005);
  EXPECT_EQ(plain.stats().scan_matches, 0u);
}

// With laser_model_type likelihood_field, a cloud of identical particles scores the weighed beams
// (at most laser_max_beams hits, evenly spread) exactly as the map's LikelihoodField does: for the
// map given to setMap, and for the cap given to reconfigure (the field is computed again for
// both). The beam model scores them otherwise.
TEST(Localizer, LikelihoodFieldWeighsTheBeams) {
  const Pose2 room(-0.5, 0.4, 0.3);
  const LaserScan scan = blockRoomScan(room, 1.0, true);
  const SlamConfig slam = slamConfig();
  const EvidentialGridMap with_block = roomMap(true), without_block = roomMap(false);
  const LocalizationConfig config = localizationConfig("likelihood_field");
  const SensorModelConfig sensor = slam.sensor.forSensorNoise(0.0, with_block.resolution());
  const size_t hits = ParticleFilter::hitBeamSubset(scan, sensor, 1).ranges.size();
  const int stride =
      static_cast<int>(std::ceil(static_cast<double>(hits) / config.laser_max_beams));
  const LaserScan weighed = ParticleFilter::hitBeamSubset(scan, sensor, stride);
  ASSERT_EQ(weighed.ranges.size(), 30u);
  const auto expected = [&](const EvidentialGridMap& map, double cap) {
    return LikelihoodField(map, cap).logLikelihood(inMap(room), weighed, config.laser_sigma_hit,
                                                   config.laser_z_hit, config.laser_z_rand) /
           30.0;
  };
  const auto measured = [&](Localizer* loc) {
    EXPECT_TRUE(loc->resetAt(inMap(room), Eigen::Matrix3d::Zero(), nullptr));
    const LocalizationUpdate u = loc->processScan(Pose2(0, 0, 0), scan);
    EXPECT_TRUE(u.processed);
    return u.mean_log_plausibility;
  };
  Localizer loc(config, slam);
  ASSERT_TRUE(loc.setMap(with_block, nullptr));
  const double on_block_map = measured(&loc);
  EXPECT_NEAR(on_block_map, expected(with_block, 2.0), 1e-9);
  ASSERT_TRUE(loc.setMap(without_block, nullptr));
  EXPECT_NEAR(measured(&loc), expected(without_block, 2.0), 1e-9);
  // Without the block, the beams ending on it are far from any plausible end.
  EXPECT_LT(measured(&loc), on_block_map - 0.05);
  LocalizationConfig capped = config;
  capped.laser_likelihood_max_dist = 0.1;
  ASSERT_TRUE(loc.reconfigure(capped, slam, nullptr));
  EXPECT_NEAR(measured(&loc), expected(without_block, 0.1), 1e-9);

  Localizer beam(localizationConfig("beam"), slam);
  ASSERT_TRUE(beam.setMap(with_block, nullptr));
  EXPECT_GT(std::abs(measured(&beam) - on_block_map), 0.01);
}

// With likelihood_field, one update (no resampling yet) leaves each particle's weight in
// proportion to amcl's 1 + Σ p^3 of the weighed beams at its pose, not tempered by
// likelihood_temperature and not the product of the p.
TEST(Localizer, LikelihoodFieldWeightsAreAmclsUntempered) {
  const Pose2 room(-0.5, 0.4, 0.3);
  const LaserScan scan = blockRoomScan(room, 1.0, true);
  const SlamConfig slam = slamConfig();
  const EvidentialGridMap map = roomMap(true);
  LocalizationConfig config = localizationConfig("likelihood_field");
  config.resample_interval = 2;
  const SensorModelConfig sensor = slam.sensor.forSensorNoise(0.0, map.resolution());
  const size_t hits = ParticleFilter::hitBeamSubset(scan, sensor, 1).ranges.size();
  const int stride =
      static_cast<int>(std::ceil(static_cast<double>(hits) / config.laser_max_beams));
  const LaserScan weighed = ParticleFilter::hitBeamSubset(scan, sensor, stride);
  Localizer loc(config, slam);
  ASSERT_TRUE(loc.setMap(map, nullptr));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << 0.01, 0.01, 0.01;
  ASSERT_TRUE(loc.resetAt(inMap(room), cov, nullptr));
  ASSERT_TRUE(loc.processScan(Pose2(0, 0, 0), scan).processed);
  const std::vector<LocalizationParticle>& particles = loc.particles();
  ASSERT_GT(particles.size(), 10u);
  const LikelihoodField field(map, config.laser_likelihood_max_dist);
  const auto score = [&](const Pose2& pose) {
    return field.score(pose.compose(weighed.sensor_pose), weighed, config.laser_sigma_hit,
                       config.laser_z_hit, config.laser_z_rand);
  };
  const FieldScore first = score(particles[0].pose);
  double spread = 0.0;
  for (const LocalizationParticle& p : particles) {
    const FieldScore s = score(p.pose);
    EXPECT_NEAR(p.weight / particles[0].weight, s.amcl_weight / first.amcl_weight, 1e-9);
    spread = std::max(spread, std::abs(s.log_likelihood - first.log_likelihood));
  }
  // The particles differ enough that a product of the p would have weighed them otherwise.
  EXPECT_GT(spread, 1.0);
}

TEST(Localizer, RefusesBadInput) {
  Localizer loc(localizationConfig(), slamConfig());
  std::string why;
  EXPECT_FALSE(loc.resetAt(Pose2(0, 0, 0), &why));
  EXPECT_EQ(why, "no map to localize on");
  EXPECT_FALSE(loc.globalLocalization(&why));
  EXPECT_FALSE(loc.setMap(EvidentialGridMap(0.05), &why));
  EXPECT_EQ(why, "the map has no observed cell");
  ASSERT_TRUE(loc.setMap(roomMap(), &why));
  const LocalizationUpdate none =
      loc.processScan(Pose2(0, 0, 0), blockRoomScan(Pose2(0, 0, 0), 1.0, true));
  EXPECT_TRUE(none.rejected);
  EXPECT_EQ(none.why, "no particles: give an initial pose or start a global localization");
  EXPECT_FALSE(loc.resetAt(Pose2(NAN, 0, 0), &why));
  EXPECT_EQ(why, "the pose is not finite");
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(0, 0) = -1.0;
  EXPECT_FALSE(loc.resetAt(Pose2(0, 0, 0), bad, &why));
  EXPECT_EQ(why, "the covariance is not positive semi-definite");
  bad = Eigen::Matrix3d::Identity();
  bad(0, 1) = 0.5;
  EXPECT_FALSE(loc.resetAt(Pose2(0, 0, 0), bad, &why));
  EXPECT_EQ(why, "the covariance is not symmetric");
  ASSERT_TRUE(loc.resetAt(Pose2(0, 0, 0), &why));
  LaserScan broken = blockRoomScan(Pose2(0, 0, 0), 1.0, true);
  broken.bearings.pop_back();
  EXPECT_TRUE(loc.processScan(Pose2(0, 0, 0), broken).rejected);
  EXPECT_TRUE(
      loc.processScan(Pose2(INFINITY, 0, 0), blockRoomScan(Pose2(0, 0, 0), 1.0, true)).rejected);
  EXPECT_EQ(loc.stats().scans_rejected, 3u);

  LocalizationConfig c;
  c.min_particles = 10;
  c.max_particles = 5;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "min_particles must not be above max_particles");
  c = LocalizationConfig();
  c.kld_err = 0.0;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why.rfind("kld_err must be in", 0), 0u) << why;
  c = LocalizationConfig();
  c.laser_model_type = "field";
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "laser_model_type must be beam, beam_traced or likelihood_field, not 'field'");
  c = LocalizationConfig();
  c.laser_z_hit = c.laser_z_rand = 0.0;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "laser_z_hit + laser_z_rand must be above 0");
  EXPECT_THROW(Localizer(c, slamConfig()), std::invalid_argument);
}

}  // namespace
}  // namespace evidential_slam
