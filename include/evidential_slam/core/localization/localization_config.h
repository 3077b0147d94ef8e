// Parameters of localization on a fixed map. amcl's names and defaults where amcl has the
// parameter. Not rows of parameters.def yet: no front end reads them (the mode is not wired).
#pragma once

#include <cmath>
#include <string>

namespace evidential_slam {

struct LocalizationConfig {
  int min_particles = 100;     // KLD-sampling's floor
  int max_particles = 5000;    // its ceiling; global localization draws this many
  double kld_err = 0.01;       // largest error between the true distribution and the particles'
  double kld_z = 0.99;         // upper standard normal quantile (amcl's value, used as amcl does)
  double kld_bin_xy = 0.5;     // m, KLD histogram bin in x and y (amcl's fixed value)
  double kld_bin_angle = M_PI / 18.0;  // rad, ... and in heading
  double update_min_d = 0.2;           // m travelled before an update
  double update_min_a = M_PI / 6.0;    // rad turned before an update
  int resample_interval = 2;           // updates between resamplings
  int laser_max_beams = 30;            // beams weighed per scan, evenly spread over the hits
  double recovery_alpha_slow = 0.0;    // slow average's decay (0 = no recovery; amcl: 0.001)
  double recovery_alpha_fast = 0.0;    // fast average's decay (0 = no recovery; amcl: 0.1)
  double initial_cov_xx = 0.25;        // m², the spread drawn around an initial pose
  double initial_cov_yy = 0.25;        // m²
  double initial_cov_aa = (M_PI / 12.0) * (M_PI / 12.0);  // rad²

  // False, with the first offending parameter in `why`, outside the ranges above's meaning.
  bool isValid(std::string* why) const;
};

}  // namespace evidential_slam
