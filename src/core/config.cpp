#include "evidential_slam/core/config.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>

namespace evidential_slam {
namespace {

// Collects the first failed check's message.
class Checker {
 public:
  explicit Checker(std::string* why) : why_(why) {}
  Checker& require(bool ok, const std::string& what) {
    if (!ok && ok_) {
      ok_ = false;
      if (why_ != nullptr) *why_ = what;
    }
    return *this;
  }
  bool ok() const { return ok_; }

 private:
  std::string* why_;
  bool ok_ = true;
};

bool positiveFinite(double v) { return std::isfinite(v) && v > 0.0; }
bool nonNegativeFinite(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace

bool SensorModelConfig::isValid(std::string* why) const {
  return Checker(why)
      .require(positiveFinite(hit_sigma), "hit_sigma must be > 0")
      .require(positiveFinite(forward_sigma), "forward_sigma must be > 0")
      .require(nonNegativeFinite(long_step_forward_sigma),
               "long_step_forward_sigma must be >= 0 (0 = forward_sigma)")
      .require(positiveFinite(forward_window), "forward_window must be > 0")
      .require(nonNegativeFinite(free_gap), "free_gap must be >= 0")
      .require(random_weight > 0.0 && random_weight < 1.0, "random_weight must be in (0, 1)")
      .require(forward_unknown_weight >= 0.0 && forward_unknown_weight <= 1.0,
               "forward_unknown_weight must be in [0, 1]")
      .require(prior_occupied > 0.0 && prior_occupied < 1.0, "prior_occupied must be in (0, 1)")
      .require(positiveFinite(usable_range), "usable_range must be > 0")
      .require(nonNegativeFinite(min_range) && min_range < usable_range,
               "min_range must be >= 0 and below usable_range")
      .require(weight_beam_stride >= 1, "weight_beam_stride must be >= 1")
      .ok();
}

SensorModelConfig SensorModelConfig::forSensorNoise(double range_sigma, double resolution) const {
  SensorModelConfig c = *this;
  if (!(range_sigma > 0.0) || !std::isfinite(range_sigma)) return c;
  c.hit_sigma = std::max(hit_sigma, range_sigma);
  c.forward_sigma = std::max(forward_sigma,
                             std::sqrt(range_sigma * range_sigma + resolution * resolution / 12.0));
  return c;
}

bool MotionModelConfig::isValid(std::string* why) const {
  return Checker(why)
      .require(nonNegativeFinite(alpha_rot_rot), "alpha_rot_rot must be >= 0")
      .require(nonNegativeFinite(alpha_rot_trans), "alpha_rot_trans must be >= 0")
      .require(nonNegativeFinite(alpha_trans_trans), "alpha_trans_trans must be >= 0")
      .require(nonNegativeFinite(alpha_trans_rot), "alpha_trans_rot must be >= 0")
      .require(nonNegativeFinite(min_sigma_xy), "min_sigma_xy must be >= 0")
      .require(nonNegativeFinite(min_sigma_theta), "min_sigma_theta must be >= 0")
      .ok();
}

bool ScanMatcherConfig::isValid(std::string* why) const {
  return Checker(why)
      .require(positiveFinite(search_radius) && search_radius <= 5.0,
               "matcher search_radius must be in (0, 5] m")
      .require(occupied_threshold > 0.0 && occupied_threshold < 1.0,
               "matcher occupied_threshold must be in (0, 1)")
      .require(icp_iterations >= 0 && icp_iterations <= 100,
               "matcher icp_iterations must be in [0, 100]")
      .require(positiveFinite(linear_step), "matcher linear_step must be > 0")
      .require(positiveFinite(angular_step), "matcher angular_step must be > 0")
      .require(refinements >= 0 && refinements <= 12, "matcher refinements must be in [0, 12]")
      .require(max_iterations >= 0, "matcher max_iterations must be >= 0")
      .require(positiveFinite(score_sigma), "matcher score_sigma must be > 0")
      .require(nonNegativeFinite(beam_spacing) && beam_spacing <= M_PI,
               "matcher beam_spacing must be in [0, pi] rad")
      .require(nonNegativeFinite(long_step_beam_spacing) && long_step_beam_spacing <= M_PI,
               "matcher long_step_beam_spacing must be in [0, pi] rad (0 = off)")
      .require(nonNegativeFinite(long_step_distance), "matcher long_step_distance must be >= 0")
      .require(nonNegativeFinite(long_step_angle), "matcher long_step_angle must be >= 0")
      .require(min_match_fraction >= 0.0 && min_match_fraction <= 1.0,
               "matcher min_match_fraction must be in [0, 1]")
      .require(nonNegativeFinite(heading_window) && heading_window <= M_PI,
               "matcher heading_window must be in [0, pi] rad")
      .require(positiveFinite(heading_step) && heading_step >= 0.005,
               "matcher heading_step must be >= 0.005 rad")
      .ok();
}

ScanMatcherConfig ScanMatcherConfig::forSensorNoise(double range_sigma, double hit_occupied_mass,
                                                    double resolution) const {
  ScanMatcherConfig c = *this;
  if (hit_occupied_mass > 0.0 && hit_occupied_mass < occupied_threshold) {
    c.occupied_threshold = hit_occupied_mass;
  }
  if (!(range_sigma > 0.0) || !std::isfinite(range_sigma)) return c;
  c.score_sigma = std::max(score_sigma, range_sigma);
  c.search_radius = std::max(search_radius, 1.5 * range_sigma);
  if (range_sigma > resolution) {
    c.point_to_line = false;
    c.beam_spacing = 0.5 * beam_spacing;
    c.long_step_beam_spacing = 0.5 * long_step_beam_spacing;
  }
  return c;
}

bool SlamConfig::isValid(std::string* why) const {
  if (!Checker(why)
           .require(particles >= 1 && particles <= 100000, "particles must be in [1, 100000]")
           .require(positiveFinite(resolution) && resolution >= 0.005 && resolution <= 2.0,
                    "resolution must be in [0.005, 2] m")
           .require(threads >= 0 && threads <= 256, "threads must be in [0, 256] (0 = all cores)")
           .require(nonNegativeFinite(update_min_distance), "update_min_distance must be >= 0")
           .require(nonNegativeFinite(update_min_angle), "update_min_angle must be >= 0")
           .require(positiveFinite(likelihood_temperature), "likelihood_temperature must be > 0")
           .require(resample_threshold >= 0.0 && resample_threshold <= 1.0,
                    "resample_threshold must be in [0, 1]")
           .require(nonNegativeFinite(merge_distance), "merge_distance must be >= 0")
           .require(nonNegativeFinite(merge_angle), "merge_angle must be >= 0")
           .require(constrained_merge_ratio >= 0.0 && constrained_merge_ratio <= 1.0,
                    "constrained_merge_ratio must be in [0, 1] (0 = off)")
           .require(nonNegativeFinite(constrained_merge_distance),
                    "constrained_merge_distance must be >= 0")
           .require(nonNegativeFinite(constrained_merge_angle),
                    "constrained_merge_angle must be >= 0")
           .ok()) {
    return false;
  }
  return sensor.isValid(why) && motion.isValid(why) && matcher.isValid(why);
}

void applyRealRobotPreset(SlamConfig* config) {
  config->matcher.heading_window = 0.35;
  config->sensor.forward_conflict_as_unknown = true;
  config->along_track_prior = true;
  config->matcher.icp_iterations = 30;
  config->matcher.long_step_beam_spacing = 0.017453292519943295;  // 1°
  config->motion.alpha_rot_rot = 0.005;
  config->sensor.long_step_forward_sigma = 0.05;
}

namespace {

// The SlamConfig part of the node's run-time parameters (ros/params.cpp lists the same names
// with their dynamic_reconfigure fields; a test in test/ros checks that both agree).
template <typename Visitor>
void forEachSlamParameter(SlamConfig& c, Visitor&& visit) {
  visit("hit_sigma", c.sensor.hit_sigma);
  visit("forward_sigma", c.sensor.forward_sigma);
  visit("long_step_forward_sigma", c.sensor.long_step_forward_sigma);
  visit("forward_window", c.sensor.forward_window);
  visit("free_gap", c.sensor.free_gap);
  visit("random_weight", c.sensor.random_weight);
  visit("forward_unknown_weight", c.sensor.forward_unknown_weight);
  visit("forward_conflict_as_unknown", c.sensor.forward_conflict_as_unknown);
  visit("prior_occupied", c.sensor.prior_occupied);
  visit("usable_range", c.sensor.usable_range);
  visit("min_range", c.sensor.min_range);
  visit("clear_no_return", c.sensor.clear_no_return);
  visit("weight_beam_stride", c.sensor.weight_beam_stride);
  visit("alpha_rot_rot", c.motion.alpha_rot_rot);
  visit("alpha_rot_trans", c.motion.alpha_rot_trans);
  visit("alpha_trans_trans", c.motion.alpha_trans_trans);
  visit("alpha_trans_rot", c.motion.alpha_trans_rot);
  visit("update_min_distance", c.update_min_distance);
  visit("update_min_angle", c.update_min_angle);
  visit("likelihood_temperature", c.likelihood_temperature);
  visit("resample_threshold", c.resample_threshold);
  visit("along_track_prior", c.along_track_prior);
  visit("constrained_merge_ratio", c.constrained_merge_ratio);
  visit("constrained_merge_distance", c.constrained_merge_distance);
  visit("constrained_merge_angle", c.constrained_merge_angle);
  visit("scan_matching", c.matcher.enabled);
  visit("matcher_search_radius", c.matcher.search_radius);
  visit("matcher_point_to_line", c.matcher.point_to_line);
  visit("matcher_interleave_subsets", c.matcher.interleave_subsets);
  visit("matcher_heading_window", c.matcher.heading_window);
  visit("matcher_heading_step", c.matcher.heading_step);
  visit("matcher_icp_iterations", c.matcher.icp_iterations);
  visit("matcher_beam_spacing", c.matcher.beam_spacing);
  visit("matcher_long_step_beam_spacing", c.matcher.long_step_beam_spacing);
  visit("matcher_long_step_distance", c.matcher.long_step_distance);
  visit("matcher_long_step_angle", c.matcher.long_step_angle);
}

// Whole-string parses; false on junk, overflow or a non-finite number.
bool parseValue(const std::string& text, double* out) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *out);
  return r.ec == std::errc() && r.ptr == text.data() + text.size() && std::isfinite(*out);
}
bool parseValue(const std::string& text, int* out) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *out);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}
bool parseValue(const std::string& text, bool* out) {
  if (text == "true" || text == "1") {
    *out = true;
  } else if (text == "false" || text == "0") {
    *out = false;
  } else {
    return false;
  }
  return true;
}
const char* typeWord(double) { return "a number"; }
const char* typeWord(int) { return "an integer"; }
const char* typeWord(bool) { return "true or false"; }

}  // namespace

std::vector<std::string> slamParameterNames() {
  std::vector<std::string> names;
  SlamConfig scratch;
  forEachSlamParameter(scratch, [&names](const char* name, auto&) { names.emplace_back(name); });
  return names;
}

bool setSlamParameter(const std::string& name, const std::string& value, SlamConfig* config,
                      std::string* why) {
  bool found = false, parsed = false;
  std::string type;
  forEachSlamParameter(*config, [&](const char* n, auto& field) {
    if (found || name != n) return;
    found = true;
    auto v = field;
    parsed = parseValue(value, &v);
    if (parsed) field = v;
    type = typeWord(field);
  });
  if (!found) {
    if (why != nullptr) *why = "unknown parameter '" + name + "'";
    return false;
  }
  if (!parsed && why != nullptr) *why = name + " wants " + type + ", not '" + value + "'";
  return parsed;
}

}  // namespace evidential_slam
