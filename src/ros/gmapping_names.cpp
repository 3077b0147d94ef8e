#include "evidential_slam/ros/gmapping_names.h"

namespace evidential_slam {
namespace ros_adapter {

namespace {
using C = GmappingName::Conversion;
}  // namespace

const std::vector<GmappingName>& gmappingNames() {
  // slam_gmapping's σ are standard deviations proportional to the motion (σ = s·|d|, from its
  // MotionModel::drawFromMotion); our α are variances per squared motion, hence the squares.
  static const std::vector<GmappingName> table = {
      {"throttle_scans", "", C::kNone, 0, 0,
       "every scan is queued; the filter processes one after update_min_distance or "
       "update_min_angle of motion"},
      {"base_frame", "base_frame", C::kSame, 1, 0, "the same"},
      {"map_frame", "map_frame", C::kSame, 1, 0, "the same"},
      {"odom_frame", "odom_frame", C::kSame, 1, 0, "the same"},
      {"map_update_interval", "map_update_interval", C::kSame, 1, 0, "the same"},
      {"maxUrange", "usable_range", C::kLinear, 1, 0,
       "the same meaning: longer beams only clear space up to it"},
      {"sigma", "", C::kNone, 0, 0,
       "gmapping's endpoint-matching kernel; ours (matcher_score_sigma) has another form and "
       "refines an ICP match"},
      {"kernelSize", "", C::kNone, 0, 0,
       "gmapping's correspondence window in cells; ours is matcher_search_radius, in m"},
      {"lstep", "matcher_linear_step", C::kLinear, 1, 0,
       "the same meaning: the hill climb's first translation step, halved at each refinement"},
      {"astep", "matcher_angular_step", C::kLinear, 1, 0, "... its first rotation step"},
      {"iterations", "matcher_refinements", C::kLinear, 1, 0, "... its number of step halvings"},
      {"lsigma", "", C::kNone, 0, 0,
       "gmapping's beam likelihood; our weights come from the evidential forward model "
       "(forward_sigma)"},
      {"ogain", "", C::kNone, 0, 0,
       "gmapping divides log-likelihoods by ogain x particles; likelihood_temperature plays that "
       "role on another scale"},
      {"lskip", "weight_beam_stride", C::kLinear, 1, 1,
       "gmapping skips lskip beams between two it uses: every (lskip + 1)-th beam, for the "
       "weights (matching: matcher_beam_spacing)"},
      {"minimumScore", "", C::kNone, 0, 0,
       "a score on gmapping's matcher's scale; ours keeps the odometry's pose below "
       "matcher_min_match_fraction of matched endpoints"},
      {"srr", "alpha_trans_trans", C::kSquare, 1, 0,
       "translation noise from translation; alpha = srr^2"},
      {"srt", "alpha_rot_trans", C::kSquare, 0.5, 0,
       "rotation noise from translation (in gmapping's code; its wiki swaps srt and str); ours "
       "adds it to both turns of a step: alpha = srt^2 / 2"},
      {"str", "alpha_trans_rot", C::kSquare, 1, 0,
       "translation noise from rotation; alpha = str^2"},
      {"stt", "alpha_rot_rot", C::kSquare, 1, 0, "rotation noise from rotation; alpha = stt^2"},
      {"linearUpdate", "update_min_distance", C::kLinear, 1, 0, "the same meaning"},
      {"angularUpdate", "update_min_angle", C::kLinear, 1, 0, "the same meaning"},
      {"temporalUpdate", "", C::kNone, 0, 0, "a scan is processed after motion only"},
      {"resampleThreshold", "resample_threshold", C::kLinear, 1, 0,
       "the same meaning: resample when N_eff < threshold x particles"},
      {"particles", "particles", C::kSame, 1, 0, "the same"},
      {"xmin", "", C::kNone, 0, 0, "the map grows as needed"},
      {"ymin", "", C::kNone, 0, 0, "the map grows as needed"},
      {"xmax", "", C::kNone, 0, 0, "the map grows as needed"},
      {"ymax", "", C::kNone, 0, 0, "the map grows as needed"},
      {"delta", "resolution", C::kLinear, 1, 0, "the same meaning: the cell size"},
      {"llsamplerange", "", C::kNone, 0, 0, "gmapping's likelihood sampling around the match"},
      {"llsamplestep", "", C::kNone, 0, 0, "gmapping's likelihood sampling around the match"},
      {"lasamplerange", "", C::kNone, 0, 0, "gmapping's likelihood sampling around the match"},
      {"lasamplestep", "", C::kNone, 0, 0, "gmapping's likelihood sampling around the match"},
      {"transform_publish_period", "transform_publish_period", C::kSame, 1, 0, "the same"},
      {"tf_delay", "transform_tolerance", C::kLinear, 1, 0,
       "the same meaning: map->odom is post-dated by it"},
      {"occ_thresh", "", C::kNone, 0, 0,
       "gmapping's /map calls every seen cell below it free; ours keeps unknown cells (BetP 0.5) "
       "between free_thresh and occupied_thresh, so 0.25 would mark them occupied"},
      {"maxRange", "", C::kNone, 0, 0, "the scan's range_max is the sensor's limit"},
  };
  return table;
}

const GmappingName* findGmappingName(const std::string& theirs) {
  for (const GmappingName& row : gmappingNames()) {
    if (theirs == row.theirs) return &row;
  }
  return nullptr;
}

double convertGmappingValue(const GmappingName& row, double value) {
  switch (row.conversion) {
    case C::kLinear:
      return row.factor * value + row.offset;
    case C::kSquare:
      return row.factor * value * value;
    default:
      return value;
  }
}

}  // namespace ros_adapter
}  // namespace evidential_slam
