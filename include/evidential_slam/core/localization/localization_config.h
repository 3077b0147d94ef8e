// Parameters of localization on a fixed map: the rows of ES_LOCALIZATION_PARAMETERS
// (parameters.def), amcl's names and defaults where amcl has the parameter.
#pragma once

#include <string>

#include "evidential_slam/core/parameter_fields/localization.h"

namespace evidential_slam {

struct LocalizationConfig {
  LocalizationConfig();  // the table's defaults
  ES_LOCALIZATION_FIELDS

  // False, with the first offending parameter in `why`, outside a row's range, when
  // min_particles is above max_particles, laser_model_type is not beam, beam_traced or
  // likelihood_field, or laser_z_hit + laser_z_rand is 0.
  bool isValid(std::string* why) const;
  bool likelihoodField() const { return laser_model_type == "likelihood_field"; }
  bool beamTraced() const { return laser_model_type == "beam_traced"; }
};

}  // namespace evidential_slam
