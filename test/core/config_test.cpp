// Tests of parameter validation (config.h) and of LaserScan::isConsistent (laser_scan.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/laser_scan.h"

namespace evidential_slam {
namespace {

// The shipped defaults are valid, component by component and as a whole.
TEST(ConfigTest, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(SlamConfig().isValid(&why)) << why;
  EXPECT_TRUE(SensorModelConfig().isValid(&why)) << why;
  EXPECT_TRUE(MotionModelConfig().isValid(&why)) << why;
  EXPECT_TRUE(ScanMatcherConfig().isValid(&why)) << why;
}

// The defaults are the documented ones (algorithm.md §3-§5; paper: K = 100).
TEST(ConfigTest, DefaultValues) {
  const SlamConfig c;
  EXPECT_EQ(c.particles, 100);
  EXPECT_DOUBLE_EQ(c.resolution, 0.05);
  EXPECT_DOUBLE_EQ(c.update_min_distance, 0.5);
  EXPECT_NEAR(c.update_min_angle, 0.17453292519943295, 1e-12);  // 10° = π/18
  EXPECT_DOUBLE_EQ(c.likelihood_temperature, 20.0);
  EXPECT_DOUBLE_EQ(c.resample_threshold, 0.5);
  EXPECT_FALSE(c.along_track_prior);
  EXPECT_DOUBLE_EQ(c.constrained_merge_ratio, 0.5);
  EXPECT_DOUBLE_EQ(c.constrained_merge_distance, 0.05);
  EXPECT_DOUBLE_EQ(c.constrained_merge_angle, 0.02);
  EXPECT_DOUBLE_EQ(c.sensor.random_weight, 0.2);
  EXPECT_DOUBLE_EQ(c.sensor.forward_unknown_weight, 1.0);
  EXPECT_FALSE(c.sensor.forward_conflict_as_unknown);
  EXPECT_DOUBLE_EQ(c.sensor.prior_occupied, 0.4);
  EXPECT_DOUBLE_EQ(c.sensor.hit_sigma, 0.025);
  EXPECT_DOUBLE_EQ(c.sensor.forward_sigma, 0.025);
  EXPECT_DOUBLE_EQ(c.sensor.forward_window, 3.0);
  EXPECT_DOUBLE_EQ(c.sensor.free_gap, 3.0);
}

// The real-robot preset turns on the wide-basin match (±20° in 5° steps), the forward model's
// reading of conflict as ignorance, the along-track prior, ICP to 30 iterations, less rotation
// noise from rotation, and after a long step 1° matching and a wider forward model; it changes
// nothing else.
TEST(ConfigTest, RealRobotPreset) {
  SlamConfig c;
  applyRealRobotPreset(&c);
  std::string why;
  EXPECT_TRUE(c.isValid(&why)) << why;
  EXPECT_DOUBLE_EQ(c.matcher.heading_window, 0.35);
  EXPECT_EQ(SlamConfig().matcher.heading_window, 0.0);  // off by default
  EXPECT_TRUE(c.sensor.forward_conflict_as_unknown);
  EXPECT_FALSE(SlamConfig().sensor.forward_conflict_as_unknown);
  EXPECT_TRUE(c.along_track_prior);
  EXPECT_FALSE(SlamConfig().along_track_prior);
  EXPECT_EQ(c.matcher.icp_iterations, 30);
  EXPECT_EQ(SlamConfig().matcher.icp_iterations, 12);
  EXPECT_FALSE(c.matcher.interleave_subsets);  // not shown to help (config.h)
  EXPECT_DOUBLE_EQ(c.matcher.long_step_beam_spacing, M_PI / 180.0);
  EXPECT_EQ(SlamConfig().matcher.long_step_beam_spacing, 0.0);  // off by default
  EXPECT_DOUBLE_EQ(c.motion.alpha_rot_rot, 0.005);
  EXPECT_DOUBLE_EQ(SlamConfig().motion.alpha_rot_rot, 0.02);
  EXPECT_DOUBLE_EQ(c.sensor.long_step_forward_sigma, 0.05);
  EXPECT_EQ(SlamConfig().sensor.long_step_forward_sigma, 0.0);  // off by default
  EXPECT_DOUBLE_EQ(c.sensor.forward_sigma, 0.025);              // not in the preset
  c.matcher.heading_window = 0.0;
  const SlamConfig d;
  EXPECT_EQ(c.matcher.heading_step, d.matcher.heading_step);
  EXPECT_EQ(c.matcher.search_radius, d.matcher.search_radius);
  EXPECT_EQ(c.motion.alpha_rot_trans, d.motion.alpha_rot_trans);
  EXPECT_EQ(c.motion.alpha_trans_trans, d.motion.alpha_trans_trans);
  EXPECT_EQ(c.update_min_distance, d.update_min_distance);
  EXPECT_EQ(c.constrained_merge_ratio, d.constrained_merge_ratio);
  EXPECT_EQ(c.sensor.hit_sigma, d.sensor.hit_sigma);
  EXPECT_EQ(c.particles, d.particles);
}

// Parameters by their ROS names: each type parses, the named field and no other changes.
TEST(ConfigTest, SetsParametersByName) {
  SlamConfig c;
  std::string why;
  ASSERT_TRUE(setSlamParameter("resample_threshold", "0.3", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.resample_threshold, 0.3);
  ASSERT_TRUE(setSlamParameter("weight_beam_stride", "3", &c, &why)) << why;
  EXPECT_EQ(c.sensor.weight_beam_stride, 3);
  ASSERT_TRUE(setSlamParameter("scan_matching", "false", &c, &why)) << why;
  EXPECT_FALSE(c.matcher.enabled);
  ASSERT_TRUE(setSlamParameter("scan_matching", "1", &c, &why)) << why;
  EXPECT_TRUE(c.matcher.enabled);
  ASSERT_TRUE(setSlamParameter("matcher_heading_window", "0.2", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.matcher.heading_window, 0.2);
  ASSERT_TRUE(c.matcher.point_to_line);
  ASSERT_TRUE(setSlamParameter("matcher_point_to_line", "false", &c, &why)) << why;
  EXPECT_FALSE(c.matcher.point_to_line);
  ASSERT_TRUE(setSlamParameter("matcher_icp_iterations", "30", &c, &why)) << why;
  EXPECT_EQ(c.matcher.icp_iterations, 30);
  ASSERT_TRUE(setSlamParameter("matcher_beam_spacing", "0.01", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.matcher.beam_spacing, 0.01);
  ASSERT_TRUE(setSlamParameter("matcher_interleave_subsets", "true", &c, &why)) << why;
  EXPECT_TRUE(c.matcher.interleave_subsets);
  ASSERT_TRUE(setSlamParameter("matcher_long_step_beam_spacing", "0.02", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.matcher.long_step_beam_spacing, 0.02);
  ASSERT_TRUE(setSlamParameter("matcher_long_step_distance", "0.9", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.matcher.long_step_distance, 0.9);
  ASSERT_TRUE(setSlamParameter("matcher_long_step_angle", "0.25", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.matcher.long_step_angle, 0.25);
  ASSERT_TRUE(setSlamParameter("long_step_forward_sigma", "0.04", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.sensor.long_step_forward_sigma, 0.04);
  ASSERT_TRUE(setSlamParameter("alpha_rot_trans", "1e-3", &c, &why)) << why;
  EXPECT_DOUBLE_EQ(c.motion.alpha_rot_trans, 0.001);
  const SlamConfig d;
  EXPECT_EQ(c.likelihood_temperature, d.likelihood_temperature);
  EXPECT_EQ(c.motion.alpha_rot_rot, d.motion.alpha_rot_rot);
  EXPECT_EQ(c.sensor.hit_sigma, d.sensor.hit_sigma);
  EXPECT_EQ(c.particles, d.particles);
}

// Unknown names and unparsable values fail with a one-line reason and change nothing.
TEST(ConfigTest, RejectsUnknownParametersAndBadValues) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"particles", "10"},  // start-up, not a run-time parameter: --particles
      {"resample", "0.3"},
      {"resample_threshold", ""},
      {"resample_threshold", "0.3x"},
      {"resample_threshold", "nan"},
      {"resample_threshold", "inf"},
      {"weight_beam_stride", "2.5"},
      {"weight_beam_stride", "99999999999"},
      {"scan_matching", "yes"},
  };
  for (const auto& [name, value] : bad) {
    SlamConfig c;
    std::string why;
    EXPECT_FALSE(setSlamParameter(name, value, &c, &why)) << name << "=" << value;
    EXPECT_FALSE(why.empty());
    EXPECT_EQ(why.find('\n'), std::string::npos);
    EXPECT_NE(why.find(name), std::string::npos) << why;
    EXPECT_EQ(c.resample_threshold, SlamConfig().resample_threshold);
    EXPECT_EQ(c.sensor.weight_beam_stride, SlamConfig().sensor.weight_beam_stride);
    EXPECT_TRUE(c.matcher.enabled);
  }
}

// Every listed name can be set, and the list has each name once.
TEST(ConfigTest, EveryParameterNameIsSettable) {
  const std::vector<std::string> names = slamParameterNames();
  EXPECT_EQ(names.size(), 36u);
  for (size_t i = 0; i < names.size(); ++i) {
    SlamConfig c;
    std::string why;
    EXPECT_TRUE(setSlamParameter(names[i], "1", &c, &why)) << names[i] << ": " << why;
    for (size_t j = 0; j < i; ++j) EXPECT_NE(names[i], names[j]);
  }
}

// Each invalid value makes the whole config invalid and says why.
void expectInvalid(const SlamConfig& c, const char* what) {
  std::string why;
  EXPECT_FALSE(c.isValid(&why)) << what;
  EXPECT_FALSE(why.empty()) << what;
}

TEST(ConfigTest, InvalidValuesAreRejected) {
  SlamConfig c;
  c.particles = 0;
  expectInvalid(c, "particles = 0");
  c = SlamConfig();
  c.particles = -5;
  expectInvalid(c, "particles = -5");
  c = SlamConfig();
  c.resolution = -0.05;
  expectInvalid(c, "resolution < 0");
  c = SlamConfig();
  c.resolution = 0.0;
  expectInvalid(c, "resolution = 0");
  c = SlamConfig();
  c.matcher.heading_window = -0.1;
  expectInvalid(c, "heading_window < 0");
  c = SlamConfig();
  c.matcher.heading_step = 0.0;
  expectInvalid(c, "heading_step = 0");
  c = SlamConfig();
  c.matcher.beam_spacing = -0.01;
  expectInvalid(c, "beam_spacing < 0");
  c = SlamConfig();
  c.matcher.long_step_beam_spacing = -0.01;
  expectInvalid(c, "long_step_beam_spacing < 0");
  c = SlamConfig();
  c.matcher.long_step_distance = std::nan("");
  expectInvalid(c, "long_step_distance NaN");
  c = SlamConfig();
  c.matcher.long_step_angle = -0.1;
  expectInvalid(c, "long_step_angle < 0");
  c = SlamConfig();
  c.matcher.icp_iterations = 101;  // a ROS / --param parameter since the real preset sets it
  expectInvalid(c, "icp_iterations > 100");
  c.matcher.icp_iterations = -1;
  expectInvalid(c, "icp_iterations < 0");
  c = SlamConfig();
  c.sensor.random_weight = 1.0;
  expectInvalid(c, "random_weight = 1");
  c = SlamConfig();
  c.sensor.random_weight = 1.5;
  expectInvalid(c, "random_weight = 1.5");
  c = SlamConfig();
  c.sensor.random_weight = -0.1;
  expectInvalid(c, "random_weight < 0");
  c = SlamConfig();
  c.sensor.forward_unknown_weight = 1.5;
  expectInvalid(c, "forward_unknown_weight > 1");
  c.sensor.forward_unknown_weight = -0.1;
  expectInvalid(c, "forward_unknown_weight < 0");
  c = SlamConfig();
  c.sensor.prior_occupied = 0.0;
  expectInvalid(c, "prior_occupied = 0");
  c = SlamConfig();
  c.sensor.prior_occupied = 1.0;
  expectInvalid(c, "prior_occupied = 1");
  c = SlamConfig();
  c.sensor.prior_occupied = -0.2;
  expectInvalid(c, "prior_occupied < 0");
  c = SlamConfig();
  c.sensor.prior_occupied = 1.2;
  expectInvalid(c, "prior_occupied > 1");
  c = SlamConfig();
  c.constrained_merge_ratio = 1.5;
  expectInvalid(c, "constrained_merge_ratio > 1");
  c.constrained_merge_ratio = -0.1;
  expectInvalid(c, "constrained_merge_ratio < 0");
  c = SlamConfig();
  c.constrained_merge_distance = -0.01;
  expectInvalid(c, "constrained_merge_distance < 0");
  c = SlamConfig();
  c.constrained_merge_angle = std::nan("");
  expectInvalid(c, "constrained_merge_angle NaN");
}

// Further values that would break the models (a zero or negative σ divides by zero, NaN
// propagates, negative motion noise variances): not in the minimal list but equally invalid.
TEST(ConfigTest, DegenerateValuesAreRejected) {
  SlamConfig c;
  c.resolution = std::nan("");
  expectInvalid(c, "resolution NaN");
  c = SlamConfig();
  c.sensor.hit_sigma = 0.0;
  expectInvalid(c, "hit_sigma = 0");
  c = SlamConfig();
  c.sensor.forward_sigma = -0.01;
  expectInvalid(c, "forward_sigma < 0");
  c = SlamConfig();
  c.sensor.long_step_forward_sigma = -0.01;
  expectInvalid(c, "long_step_forward_sigma < 0");
  c.sensor.long_step_forward_sigma = std::nan("");
  expectInvalid(c, "long_step_forward_sigma NaN");
  c = SlamConfig();
  c.motion.alpha_trans_trans = -0.1;
  expectInvalid(c, "alpha_trans_trans < 0");
  MotionModelConfig m;
  m.alpha_rot_rot = -0.1;
  std::string why;
  EXPECT_FALSE(m.isValid(&why));
  EXPECT_FALSE(why.empty());
}

// A long step is one at least long_step_distance long or turning at least long_step_angle either
// way; the SLAM treats it apart only while a long-step setting (the matcher's beam spacing or the
// forward model's σ_f) is on.
TEST(ConfigTest, LongStep) {
  ScanMatcherConfig m;
  m.long_step_distance = 0.8;
  m.long_step_angle = 0.3;
  EXPECT_FALSE(m.isLongStep(0.79, 0.29));
  EXPECT_FALSE(m.isLongStep(0.79, -0.29));
  EXPECT_TRUE(m.isLongStep(0.8, 0.0));
  EXPECT_TRUE(m.isLongStep(0.0, 0.3));
  EXPECT_TRUE(m.isLongStep(0.1, -0.31));

  SlamConfig c;
  EXPECT_FALSE(c.isLongStep(5.0, 1.0));  // off by default
  c.matcher.long_step_beam_spacing = 0.0175;
  EXPECT_TRUE(c.isLongStep(0.8, 0.0));
  EXPECT_FALSE(c.isLongStep(0.79, 0.29));
  c.matcher.long_step_beam_spacing = 0.0;
  c.sensor.long_step_forward_sigma = 0.05;
  EXPECT_TRUE(c.isLongStep(0.0, -0.3));
  EXPECT_FALSE(c.isLongStep(0.5, 0.1));
}

// The component configs reject their own invalid values.
TEST(ConfigTest, ComponentValidation) {
  std::string why;
  SensorModelConfig s;
  s.random_weight = 1.0;
  EXPECT_FALSE(s.isValid(&why));
  EXPECT_FALSE(why.empty());
  why.clear();
  s = SensorModelConfig();
  s.prior_occupied = 1.0;
  EXPECT_FALSE(s.isValid(&why));
  EXPECT_FALSE(why.empty());
}

// A scan whose ranges / bearings / valid arrays agree in size is consistent; any mismatch is not.
TEST(LaserScanTest, Consistency) {
  LaserScan scan;
  scan.max_range = 30.0f;
  scan.ranges = {1.0f, 2.0f, 3.0f};
  scan.bearings = {-0.1f, 0.0f, 0.1f};
  scan.valid = {1, 1, 0};
  std::string why;
  EXPECT_TRUE(scan.isConsistent(&why)) << why;
  EXPECT_EQ(scan.size(), 3u);

  LaserScan short_bearings = scan;
  short_bearings.bearings.pop_back();
  why.clear();
  EXPECT_FALSE(short_bearings.isConsistent(&why));
  EXPECT_FALSE(why.empty());

  LaserScan short_valid = scan;
  short_valid.valid.pop_back();
  why.clear();
  EXPECT_FALSE(short_valid.isConsistent(&why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace evidential_slam
