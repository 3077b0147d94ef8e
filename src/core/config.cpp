#include "evidential_slam/core/config.h"

#include <algorithm>
#include <cmath>

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {
namespace {

bool fail(std::string* why, const char* what) {
  if (why != nullptr) *why = what;
  return false;
}

}  // namespace

SensorModelConfig::SensorModelConfig() {
  ES_SENSOR_MODEL_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool SensorModelConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_SENSOR_MODEL_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (ok && !(min_range < usable_range)) return fail(why, "min_range must be below usable_range");
  return ok;
}

SensorModelConfig SensorModelConfig::forSensorNoise(double range_sigma, double resolution) const {
  SensorModelConfig c = *this;
  if (!(range_sigma > 0.0) || !std::isfinite(range_sigma)) return c;
  c.hit_sigma = std::max(hit_sigma, range_sigma);
  c.forward_sigma = std::max(forward_sigma,
                             std::sqrt(range_sigma * range_sigma + resolution * resolution / 12.0));
  return c;
}

MotionModelConfig::MotionModelConfig() {
  ES_MOTION_MODEL_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool MotionModelConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_MOTION_MODEL_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

ScanMatcherConfig::ScanMatcherConfig() {
  ES_SCAN_MATCHER_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool ScanMatcherConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_SCAN_MATCHER_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
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
  }
  return c;
}

LongStepConfig::LongStepConfig() { ES_LONG_STEP_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool LongStepConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_LONG_STEP_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

SlamConfig::SlamConfig() { ES_FILTER_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool SlamConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_FILTER_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok && sensor.isValid(why) && motion.isValid(why) && matcher.isValid(why) &&
         long_step.isValid(why);
}

}  // namespace evidential_slam
