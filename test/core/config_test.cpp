// Tests of the parameter table (parameters.h), validation (config.h) and of
// LaserScan::isConsistent (laser_scan.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/parameters.h"
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

// The defaults are the documented ones (algorithm.md §3-§5; paper: K = 100) and the real-robot
// settings (docs/decisions.md): the wide-basin match, conflict read as ignorance, the along-track
// prior, ICP to 30 iterations, less rotation noise, and after a long step 1° matching and a wider
// forward model.
TEST(ConfigTest, DefaultValues) {
  const SlamConfig c;
  EXPECT_EQ(c.particles, 100);
  EXPECT_DOUBLE_EQ(c.resolution, 0.05);
  EXPECT_DOUBLE_EQ(c.update_min_distance, 0.5);
  EXPECT_NEAR(c.update_min_angle, 0.17453292519943295, 1e-12);  // 10° = π/18
  EXPECT_DOUBLE_EQ(c.likelihood_temperature, 20.0);
  EXPECT_DOUBLE_EQ(c.resample_threshold, 0.5);
  EXPECT_DOUBLE_EQ(c.constrained_merge_ratio, 0.5);
  EXPECT_DOUBLE_EQ(c.constrained_merge_distance, 0.05);
  EXPECT_DOUBLE_EQ(c.constrained_merge_angle, 0.02);
  EXPECT_DOUBLE_EQ(c.sensor.random_weight, 0.2);
  EXPECT_DOUBLE_EQ(c.sensor.prior_occupied, 0.4);
  EXPECT_DOUBLE_EQ(c.sensor.hit_sigma, 0.025);
  EXPECT_DOUBLE_EQ(c.sensor.forward_sigma, 0.025);
  EXPECT_DOUBLE_EQ(c.sensor.forward_window, 3.0);
  EXPECT_DOUBLE_EQ(c.sensor.free_gap, 3.0);
  EXPECT_DOUBLE_EQ(c.matcher.heading_window, 0.35);
  EXPECT_TRUE(c.sensor.forward_conflict_as_unknown);
  EXPECT_TRUE(c.along_track_prior);
  EXPECT_EQ(c.matcher.icp_iterations, 30);
  EXPECT_DOUBLE_EQ(c.motion.alpha_rot_rot, 0.005);
  EXPECT_DOUBLE_EQ(c.long_step.beam_spacing, M_PI / 180.0);
  EXPECT_DOUBLE_EQ(c.long_step.forward_sigma, 0.05);
  EXPECT_DOUBLE_EQ(c.long_step.distance, 0.8);
  EXPECT_DOUBLE_EQ(c.long_step.angle, 0.3);
}

// Parameters by their names: each type parses, the named field and no other changes.
TEST(ConfigTest, SetsParametersByName) {
  Parameters p;
  std::string why;
  ASSERT_TRUE(setParameter("resample_threshold", "0.3", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.slam.resample_threshold, 0.3);
  ASSERT_TRUE(setParameter("particles", "7", &p, &why)) << why;
  EXPECT_EQ(p.slam.particles, 7);
  ASSERT_TRUE(setParameter("weight_beam_stride", "3", &p, &why)) << why;
  EXPECT_EQ(p.slam.sensor.weight_beam_stride, 3);
  ASSERT_TRUE(setParameter("scan_matching", "false", &p, &why)) << why;
  EXPECT_FALSE(p.slam.matcher.enabled);
  ASSERT_TRUE(setParameter("scan_matching", "1", &p, &why)) << why;
  EXPECT_TRUE(p.slam.matcher.enabled);
  ASSERT_TRUE(setParameter("matcher_heading_window", "0.2", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.slam.matcher.heading_window, 0.2);
  ASSERT_TRUE(setParameter("matcher_point_to_line", "false", &p, &why)) << why;
  EXPECT_FALSE(p.slam.matcher.point_to_line);
  ASSERT_TRUE(setParameter("long_step_beam_spacing", "0.02", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.slam.long_step.beam_spacing, 0.02);
  ASSERT_TRUE(setParameter("long_step_distance", "0.9", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.slam.long_step.distance, 0.9);
  ASSERT_TRUE(setParameter("alpha_rot_trans", "1e-3", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.slam.motion.alpha_rot_trans, 0.001);
  ASSERT_TRUE(setParameter("motion_min_sigma_xy", "0.01", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.slam.motion.min_sigma_xy, 0.01);
  ASSERT_TRUE(setParameter("conflict_alarm_factor", "6", &p, &why)) << why;
  EXPECT_DOUBLE_EQ(p.conflict_alarm.threshold_factor, 6.0);
  ASSERT_TRUE(setParameter("export_octomap", "true", &p, &why)) << why;
  EXPECT_TRUE(p.session.export_octomap);
  const Parameters d;
  EXPECT_EQ(p.slam.likelihood_temperature, d.slam.likelihood_temperature);
  EXPECT_EQ(p.slam.motion.alpha_rot_rot, d.slam.motion.alpha_rot_rot);
  EXPECT_EQ(p.slam.sensor.hit_sigma, d.slam.sensor.hit_sigma);
  EXPECT_EQ(p.slam.long_step.angle, d.slam.long_step.angle);
}

// Unknown names, node-only names and bad values fail with a one-line reason naming the parameter
// and change nothing.
TEST(ConfigTest, RejectsUnknownParametersAndBadValues) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"resample", "0.3"},
      {"resample_threshold", ""},
      {"resample_threshold", "0.3x"},
      {"resample_threshold", "nan"},
      {"resample_threshold", "inf"},
      {"resample_threshold", "1.5"},  // out of range
      {"weight_beam_stride", "2.5"},
      {"weight_beam_stride", "99999999999"},
      {"particles", "1000000000"},  // a billion particles
      {"usable_range", "1e9"},
      {"resolution", "1e-6"},
      {"scan_matching", "yes"},
      {"map_frame", "world"},  // the node's only
  };
  for (const auto& [name, value] : bad) {
    Parameters p;
    std::string why;
    EXPECT_FALSE(setParameter(name, value, &p, &why)) << name << "=" << value;
    EXPECT_FALSE(why.empty());
    EXPECT_EQ(why.find('\n'), std::string::npos);
    EXPECT_NE(why.find(name), std::string::npos) << why;
    EXPECT_EQ(p.slam.resample_threshold, Parameters().slam.resample_threshold);
    EXPECT_EQ(p.slam.sensor.weight_beam_stride, Parameters().slam.sensor.weight_beam_stride);
    EXPECT_EQ(p.slam.particles, Parameters().slam.particles);
    EXPECT_TRUE(p.slam.matcher.enabled);
  }
  EXPECT_TRUE(isNodeParameter("map_frame"));
  EXPECT_FALSE(isNodeParameter("particles"));
}

// Every row of the table can be set to its range's ends (numbers) or both ways (switches), the
// value reads back as set, the names are unique, and each range holds its default.
TEST(ConfigTest, EveryParameterIsSettableWithinItsRange) {
  const std::vector<ParameterSpec> specs = sharedParameterSpecs();
  EXPECT_GT(specs.size(), 50u);
  const Parameters defaults;
  std::map<std::string, std::string> default_values;
  for (const auto& [name, value] : parameterValues(defaults)) default_values[name] = value;
  EXPECT_EQ(default_values.size(), specs.size());  // unique names
  for (const ParameterSpec& spec : specs) {
    const std::string type = spec.type;
    std::vector<std::string> values;
    if (type == "bool") {
      values = {"true", "false"};
    } else if (type == "std::string") {
      values = {default_values[spec.name]};  // strings have no range: isValid checks them
    } else {
      char lo[40], hi[40];
      std::snprintf(lo, sizeof(lo), "%.17g", spec.min);
      std::snprintf(hi, sizeof(hi), "%.17g", spec.max);
      values = {lo, hi};
      // The default is within the range.
      const double d = std::stod(default_values[spec.name]);
      EXPECT_GE(d, spec.min) << spec.name;
      EXPECT_LE(d, spec.max) << spec.name;
    }
    for (const std::string& v : values) {
      Parameters p;
      std::string why;
      EXPECT_TRUE(setParameter(spec.name, v, &p, &why)) << spec.name << "=" << v << ": " << why;
      for (const auto& [name, value] : parameterValues(p)) {
        if (name != spec.name) continue;
        if (type == "std::string") {
          EXPECT_EQ(value, v) << spec.name;
        } else {
          EXPECT_DOUBLE_EQ(type == "bool" ? (value == "true") : std::stod(value),
                           type == "bool" ? (v == "true") : std::stod(v))
              << spec.name;
        }
      }
    }
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
  c.long_step.beam_spacing = -0.01;
  expectInvalid(c, "long_step beam_spacing < 0");
  c = SlamConfig();
  c.long_step.distance = std::nan("");
  expectInvalid(c, "long_step distance NaN");
  c = SlamConfig();
  c.long_step.angle = -0.1;
  expectInvalid(c, "long_step angle < 0");
  c = SlamConfig();
  c.matcher.icp_iterations = 101;
  expectInvalid(c, "icp_iterations > 100");
  c.matcher.icp_iterations = -1;
  expectInvalid(c, "icp_iterations < 0");
  c = SlamConfig();
  c.sensor.random_weight = 1.0;
  expectInvalid(c, "random_weight = 1");
  c = SlamConfig();
  c.sensor.random_weight = -0.1;
  expectInvalid(c, "random_weight < 0");
  c = SlamConfig();
  c.sensor.prior_occupied = 0.0;
  expectInvalid(c, "prior_occupied = 0");
  c = SlamConfig();
  c.sensor.prior_occupied = 1.0;
  expectInvalid(c, "prior_occupied = 1");
  c = SlamConfig();
  c.sensor.min_range = 30.0;
  expectInvalid(c, "min_range above usable_range");
  c = SlamConfig();
  c.constrained_merge_ratio = 1.5;
  expectInvalid(c, "constrained_merge_ratio > 1");
  c.constrained_merge_ratio = -0.1;
  expectInvalid(c, "constrained_merge_ratio < 0");
  c = SlamConfig();
  c.constrained_merge_angle = std::nan("");
  expectInvalid(c, "constrained_merge_angle NaN");
  Parameters p;
  p.session.free_thresh = 0.7;  // above occupied_thresh
  std::string why;
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("free_thresh"), std::string::npos) << why;
  p = Parameters();
  p.conflict_alarm.threshold_factor = 1.0;
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("conflict_alarm_factor"), std::string::npos) << why;
}

// Further values that would break the models (a zero or negative σ divides by zero, NaN
// propagates, negative motion noise variances): equally invalid.
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
  c.long_step.forward_sigma = -0.01;
  expectInvalid(c, "long_step forward_sigma < 0");
  c.long_step.forward_sigma = std::nan("");
  expectInvalid(c, "long_step forward_sigma NaN");
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
  LongStepConfig l;
  l.distance = 0.8;
  l.angle = 0.3;
  EXPECT_FALSE(l.isLong(0.79, 0.29));
  EXPECT_FALSE(l.isLong(0.79, -0.29));
  EXPECT_TRUE(l.isLong(0.8, 0.0));
  EXPECT_TRUE(l.isLong(0.0, 0.3));
  EXPECT_TRUE(l.isLong(0.1, -0.31));

  SlamConfig c;
  c.long_step.beam_spacing = 0.0;
  c.long_step.forward_sigma = 0.0;
  EXPECT_FALSE(c.isLongStep(5.0, 1.0));  // no long-step setting on
  c.long_step.beam_spacing = 0.0175;
  EXPECT_TRUE(c.isLongStep(0.8, 0.0));
  EXPECT_FALSE(c.isLongStep(0.79, 0.29));
  c.long_step.beam_spacing = 0.0;
  c.long_step.forward_sigma = 0.05;
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
