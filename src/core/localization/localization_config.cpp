// LocalizationConfig's checks, apart from the Localizer so that what reads parameters (the
// parameter files, their fuzz target) links without the filter.
#include "evidential_slam/core/localization/localization_config.h"

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {

LocalizationConfig::LocalizationConfig() {
  ES_LOCALIZATION_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool LocalizationConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_LOCALIZATION_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (!ok) return false;
  if (min_particles > max_particles) {
    if (why != nullptr) *why = "min_particles must not be above max_particles";
    return false;
  }
  if (laser_model_type != "beam" && laser_model_type != "beam_traced" &&
      laser_model_type != "likelihood_field") {
    if (why != nullptr) {
      *why = "laser_model_type must be beam, beam_traced or likelihood_field, not '" +
             laser_model_type + "'";
    }
    return false;
  }
  if (!(laser_z_hit + laser_z_rand > 0.0)) {
    if (why != nullptr) *why = "laser_z_hit + laser_z_rand must be above 0";
    return false;
  }
  return true;
}

}  // namespace evidential_slam
