// Parameters of the SLAM core, one struct per component. Every field, its default, range and
// meaning are rows of the parameter table (parameters.def); the structs declare their fields from
// it. Why a default is what it is: docs/decisions.md.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "evidential_slam/core/parameter_fields/filter.h"
#include "evidential_slam/core/parameter_fields/long_step.h"
#include "evidential_slam/core/parameter_fields/motion_model.h"
#include "evidential_slam/core/parameter_fields/scan_matcher.h"
#include "evidential_slam/core/parameter_fields/sensor_model.h"

namespace evidential_slam {

// Forward (plausibility) and inverse (GBT) laser models, algorithm.md §3-§4.
struct SensorModelConfig {
  SensorModelConfig();  // the table's defaults
  ES_SENSOR_MODEL_FIELDS

  bool isValid(std::string* why) const;
  // The model for a sensor that declares `range_sigma` of range noise: the σ's are never below
  // the sensor's (σ_i ≥ σ_range, σ_f ≥ √(σ_range² + Δ²/12), algorithm.md §3), so a noisy laser
  // is not treated as a precise one.
  SensorModelConfig forSensorNoise(double range_sigma, double resolution) const;
};

// Odometry motion model (Probabilistic Robotics, sample_motion_model_odometry).
struct MotionModelConfig {
  MotionModelConfig();  // the table's defaults
  ES_MOTION_MODEL_FIELDS

  bool isValid(std::string* why) const;
};

// Refinement of each particle's sampled pose against its own map: ICP on nearest occupied cells
// (wide capture), then a short hill climb on a smooth endpoint score (sub-cell precision). With
// heading_window > 0, each hypothesis (map and pose) is first matched by ICP from its odometry
// prediction and, unless that explains the scan, from the prediction turned by ±heading_step ...
// ±heading_window and from no and from reversed translation, the forward model choosing; the
// particles are then sampled around the chosen pose (the wide-basin match).
struct ScanMatcherConfig {
  ScanMatcherConfig();  // the table's defaults
  ES_SCAN_MATCHER_FIELDS

  bool isValid(std::string* why) const;
  // Matching for a sensor with `range_sigma` of range noise: kernel and search radius widened,
  // and a cell is a match target once it holds one hit's worth of occupied mass
  // (`hit_occupied_mass`, the inverse model's m(o) at the hit) if that is below the threshold.
  // ICP is point to point, and the endpoints twice as dense, when the noise exceeds a cell
  // (`resolution`): a wall's evidence is then a band several cells thick, and the line through a
  // few of its cells is not the wall's.
  ScanMatcherConfig forSensorNoise(double range_sigma, double hit_occupied_mass,
                                   double resolution) const;
};

// Settings that apply after a long odometry step, where the prediction is further from the match
// and the scan overlaps less with the map.
struct LongStepConfig {
  LongStepConfig();  // the table's defaults
  ES_LONG_STEP_FIELDS

  bool isValid(std::string* why) const;
  // Some setting differs after a long step.
  bool enabled() const { return beam_spacing > 0.0 || forward_sigma > 0.0; }
  // True when an odometry step of `step_distance` m and `step_angle` rad is long.
  bool isLong(double step_distance, double step_angle) const {
    return step_distance >= distance || std::abs(step_angle) >= angle;
  }
};

struct SlamConfig {
  SlamConfig();  // the table's defaults
  ES_FILTER_FIELDS
  SensorModelConfig sensor;
  MotionModelConfig motion;
  ScanMatcherConfig matcher;
  LongStepConfig long_step;

  bool isValid(std::string* why) const;
  // True when an odometry step is long and a long-step setting is on.
  bool isLongStep(double distance, double angle) const {
    return long_step.enabled() && long_step.isLong(distance, angle);
  }
};

}  // namespace evidential_slam
