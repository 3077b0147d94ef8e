#include "evidential_slam/ros/params.h"

#include <cmath>

namespace evidential_slam {
namespace ros_adapter {
namespace {

// The run-time parameters: each name once, bound to its NodeParams field and to the field of the
// generated dynamic_reconfigure struct. Reading, and both conversions, walk this one list.
template <typename Visitor>
void forEachRuntimeParam(NodeParams& p, EvidentialSlamConfig& c, Visitor&& visit) {
  SensorModelConfig& s = p.slam.sensor;
  MotionModelConfig& m = p.slam.motion;
  visit("hit_sigma", s.hit_sigma, c.hit_sigma);
  visit("forward_sigma", s.forward_sigma, c.forward_sigma);
  visit("long_step_forward_sigma", s.long_step_forward_sigma, c.long_step_forward_sigma);
  visit("forward_window", s.forward_window, c.forward_window);
  visit("free_gap", s.free_gap, c.free_gap);
  visit("random_weight", s.random_weight, c.random_weight);
  visit("forward_unknown_weight", s.forward_unknown_weight, c.forward_unknown_weight);
  visit("forward_conflict_as_unknown", s.forward_conflict_as_unknown,
        c.forward_conflict_as_unknown);
  visit("prior_occupied", s.prior_occupied, c.prior_occupied);
  visit("usable_range", s.usable_range, c.usable_range);
  visit("min_range", s.min_range, c.min_range);
  visit("clear_no_return", s.clear_no_return, c.clear_no_return);
  visit("weight_beam_stride", s.weight_beam_stride, c.weight_beam_stride);
  visit("laser_range_sigma", p.laser_range_sigma, c.laser_range_sigma);
  visit("alpha_rot_rot", m.alpha_rot_rot, c.alpha_rot_rot);
  visit("alpha_rot_trans", m.alpha_rot_trans, c.alpha_rot_trans);
  visit("alpha_trans_trans", m.alpha_trans_trans, c.alpha_trans_trans);
  visit("alpha_trans_rot", m.alpha_trans_rot, c.alpha_trans_rot);
  visit("update_min_distance", p.slam.update_min_distance, c.update_min_distance);
  visit("update_min_angle", p.slam.update_min_angle, c.update_min_angle);
  visit("likelihood_temperature", p.slam.likelihood_temperature, c.likelihood_temperature);
  visit("resample_threshold", p.slam.resample_threshold, c.resample_threshold);
  visit("along_track_prior", p.slam.along_track_prior, c.along_track_prior);
  visit("constrained_merge_ratio", p.slam.constrained_merge_ratio, c.constrained_merge_ratio);
  visit("constrained_merge_distance", p.slam.constrained_merge_distance,
        c.constrained_merge_distance);
  visit("constrained_merge_angle", p.slam.constrained_merge_angle, c.constrained_merge_angle);
  visit("scan_matching", p.slam.matcher.enabled, c.scan_matching);
  visit("matcher_search_radius", p.slam.matcher.search_radius, c.matcher_search_radius);
  visit("matcher_point_to_line", p.slam.matcher.point_to_line, c.matcher_point_to_line);
  visit("matcher_interleave_subsets", p.slam.matcher.interleave_subsets,
        c.matcher_interleave_subsets);
  visit("matcher_heading_window", p.slam.matcher.heading_window, c.matcher_heading_window);
  visit("matcher_heading_step", p.slam.matcher.heading_step, c.matcher_heading_step);
  visit("matcher_icp_iterations", p.slam.matcher.icp_iterations, c.matcher_icp_iterations);
  visit("matcher_beam_spacing", p.slam.matcher.beam_spacing, c.matcher_beam_spacing);
  visit("matcher_long_step_beam_spacing", p.slam.matcher.long_step_beam_spacing,
        c.matcher_long_step_beam_spacing);
  visit("matcher_long_step_distance", p.slam.matcher.long_step_distance,
        c.matcher_long_step_distance);
  visit("matcher_long_step_angle", p.slam.matcher.long_step_angle, c.matcher_long_step_angle);
  visit("conflict_alarm_enabled", p.conflict_alarm.enabled, c.conflict_alarm_enabled);
  visit("conflict_alarm_factor", p.conflict_alarm.threshold_factor, c.conflict_alarm_factor);
  visit("conflict_alarm_min_added", p.conflict_alarm.min_added, c.conflict_alarm_min_added);
  visit("conflict_alarm_baseline_scans", p.conflict_alarm.baseline_scans,
        c.conflict_alarm_baseline_scans);
  visit("map_update_interval", p.map_update_interval, c.map_update_interval);
  visit("external_conflict_display_max", p.external_conflict_display_max,
        c.external_conflict_display_max);
}

}  // namespace

bool NodeParams::isValid(std::string* why) const {
  auto fail = [why](const std::string& what) {
    if (why != nullptr) *why = what;
    return false;
  };
  if (!slam.isValid(why)) return false;
  if (!conflict_alarm.isValid(why)) return false;
  if (!(laser_range_sigma >= 0.0) || !std::isfinite(laser_range_sigma)) {
    return fail("laser_range_sigma must be >= 0");
  }
  if (map_frame.empty() || odom_frame.empty() || base_frame.empty()) {
    return fail("map_frame, odom_frame and base_frame must not be empty");
  }
  if (map_frame == odom_frame) return fail("map_frame and odom_frame must differ");
  if (!(map_update_interval > 0.0)) return fail("map_update_interval must be > 0");
  if (!(external_conflict_display_max > 0.0)) {
    return fail("external_conflict_display_max must be > 0");
  }
  if (!(transform_publish_period >= 0.0)) return fail("transform_publish_period must be >= 0");
  if (!(transform_tolerance >= 0.0)) return fail("transform_tolerance must be >= 0");
  if (!(time_jump_tolerance > 0.0)) return fail("time_jump_tolerance must be > 0");
  if (scan_queue_size < 1) return fail("scan_queue_size must be >= 1");
  return true;
}

NodeParams readParams(const ros::NodeHandle& nh) {
  NodeParams p;
  EvidentialSlamConfig unused;
  forEachRuntimeParam(
      p, unused, [&nh](const char* name, auto& field, auto&) { nh.param(name, field, field); });
  // Start-up only: they shape the particles and the maps.
  nh.param("particles", p.slam.particles, p.slam.particles);
  nh.param("resolution", p.slam.resolution, p.slam.resolution);
  int seed = static_cast<int>(p.slam.seed);
  nh.param("seed", seed, seed);
  p.slam.seed = static_cast<uint64_t>(seed < 0 ? 0 : seed);
  nh.param("threads", p.slam.threads, p.slam.threads);
  nh.param("map_frame", p.map_frame, p.map_frame);
  nh.param("odom_frame", p.odom_frame, p.odom_frame);
  nh.param("base_frame", p.base_frame, p.base_frame);
  nh.param("transform_publish_period", p.transform_publish_period, p.transform_publish_period);
  nh.param("transform_tolerance", p.transform_tolerance, p.transform_tolerance);
  nh.param("time_jump_tolerance", p.time_jump_tolerance, p.time_jump_tolerance);
  nh.param("scan_queue_size", p.scan_queue_size, p.scan_queue_size);
  return p;
}

EvidentialSlamConfig toReconfigure(const NodeParams& params) {
  NodeParams p = params;
  EvidentialSlamConfig c = EvidentialSlamConfig::__getDefault__();
  forEachRuntimeParam(p, c, [](const char*, auto& field, auto& cfg_field) { cfg_field = field; });
  return c;
}

void applyReconfigure(const EvidentialSlamConfig& config, NodeParams* params) {
  EvidentialSlamConfig c = config;
  forEachRuntimeParam(*params, c,
                      [](const char*, auto& field, auto& cfg_field) { field = cfg_field; });
}

}  // namespace ros_adapter
}  // namespace evidential_slam
