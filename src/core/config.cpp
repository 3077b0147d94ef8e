#include "evidential_slam/core/config.h"

#include <algorithm>
#include <cmath>

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
      .require(positiveFinite(forward_window), "forward_window must be > 0")
      .require(nonNegativeFinite(free_gap), "free_gap must be >= 0")
      .require(random_weight > 0.0 && random_weight < 1.0, "random_weight must be in (0, 1)")
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
      .require(beam_stride >= 1, "matcher beam_stride must be >= 1")
      .require(min_match_fraction >= 0.0 && min_match_fraction <= 1.0,
               "matcher min_match_fraction must be in [0, 1]")
      .require(nonNegativeFinite(heading_window) && heading_window <= M_PI,
               "matcher heading_window must be in [0, pi] rad")
      .require(positiveFinite(heading_step) && heading_step >= 0.005,
               "matcher heading_step must be >= 0.005 rad")
      .ok();
}

ScanMatcherConfig ScanMatcherConfig::forSensorNoise(double range_sigma,
                                                    double hit_occupied_mass) const {
  ScanMatcherConfig c = *this;
  if (hit_occupied_mass > 0.0 && hit_occupied_mass < occupied_threshold) {
    c.occupied_threshold = hit_occupied_mass;
  }
  if (!(range_sigma > 0.0) || !std::isfinite(range_sigma)) return c;
  c.score_sigma = std::max(score_sigma, range_sigma);
  c.search_radius = std::max(search_radius, 1.5 * range_sigma);
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
           .ok()) {
    return false;
  }
  return sensor.isValid(why) && motion.isValid(why) && matcher.isValid(why);
}

void applyRealRobotPreset(SlamConfig* config) { config->matcher.heading_window = 0.35; }

}  // namespace evidential_slam
