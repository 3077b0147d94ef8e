// summary.json through nlohmann::json (keys keep the order below). See summary.h.
#include "evidential_slam/io/summary.h"

#include <nlohmann/json.hpp>

#include "evidential_slam/io/atomic_files.h"

namespace evidential_slam {
namespace io {

bool writeSummaryJson(const std::string& path, const RunSummary& s, std::string* error,
                      AtomicFiles* files) {
  nlohmann::ordered_json j;
  j["mode"] = s.mode;
  j["rawlog"] = s.rawlog;
  j["rawlog_format"] = s.rawlog_format;
  j["first_scan"] = s.first_scan;
  j["scans_total"] = s.scans_total;
  j["scans_processed"] = s.scans_processed;
  j["scans_rejected"] = s.scans_rejected;
  j["scans_without_odometry"] = s.scans_without_odometry;
  j["scans_dropped"] = s.scans_dropped;
  j["rays_total"] = s.rays_total;
  j["rays_bad"] = s.rays_bad;
  j["rays_no_return"] = s.rays_no_return;
  j["resamplings"] = s.resamplings;
  j["long_steps"] = s.long_steps;
  // Updates: every processed scan but the first.
  const double updates = s.scans_processed > 1 ? static_cast<double>(s.scans_processed - 1) : 1.0;
  j["group_updates"] = s.group_updates;
  j["groups_per_update"] = static_cast<double>(s.group_updates) / updates;
  j["wall_time_s"] = s.wall_time_s;
  j["slam_time_s"] = s.slam_time_s;
  j["peak_rss_mb"] = s.peak_rss_mb;
  j["config_files"] = s.config_files;
  if (!s.parameters.empty()) {
    nlohmann::ordered_json params = nlohmann::ordered_json::object();
    for (const auto& [name, value] : s.parameters) params[name] = value;
    j["parameters"] = params;
  }
  nlohmann::ordered_json values = nlohmann::ordered_json::object();
  for (const auto& [name, value] : s.parameter_values) values[name] = value;
  j["parameter_values"] = values;
  j["particles"] = s.particles;
  j["resolution"] = s.resolution;
  j["seed"] = s.seed;
  j["threads"] = s.threads;
  j["truncated"] = s.truncated;
  j["warnings"] = s.warnings;
  if (!s.ground_truth.empty()) j["ground_truth"] = s.ground_truth;
  if (s.ate) {
    j["ate_rmse_m"] = s.ate->rmse_m;
    j["ate_max_m"] = s.ate->max_m;
    j["ate_matched"] = s.ate->matched;
  } else if (!s.ground_truth.empty()) {
    j["ate_rmse_m"] = nullptr;
    j["ate_max_m"] = nullptr;
    j["ate_matched"] = 0;
  }
  if (s.odometry_ate) {
    j["odometry_ate_rmse_m"] = s.odometry_ate->rmse_m;
    j["odometry_ate_max_m"] = s.odometry_ate->max_m;
  }
  j["external_conflict_scale"] = s.external_conflict_scale;
  j["map_width"] = s.map_width;
  j["map_height"] = s.map_height;
  if (s.start) {
    nlohmann::ordered_json o;
    o["map_file"] = s.start->map_file;
    o["map_tiles"] = s.start->map_tiles;
    o["pose"] = {s.start->x, s.start->y, s.start->theta};
    o["pose_from"] = s.start->pose_from;
    o["odometry_anchored"] = s.start->odometry_anchored;
    j["start"] = o;
  }
  if (s.map_file) {
    nlohmann::ordered_json o;
    o["path"] = s.map_file->path;
    o["bytes"] = s.map_file->bytes;
    o["tiles"] = s.map_file->tiles;
    j["map_file"] = o;
  }
  j["outputs"] = s.outputs;
  j["conflict_alarms"] = s.conflict_alarm_stamps;
  if (s.octomap) {
    nlohmann::ordered_json o;
    o["files"] = s.octomap->files;
    o["bytes"] = s.octomap->bytes;
    o["export_time_s"] = s.octomap->seconds;
    o["z_min"] = s.octomap->z_min;
    o["z_max"] = s.octomap->z_max;
    o["z_layers"] = s.octomap->z_layers;
    o["voxels"] = s.octomap->voxels;
    j["octomap"] = o;
  }
  if (s.localization) {
    const LocalizationSummary& l = *s.localization;
    nlohmann::ordered_json o;
    o["global"] = l.global;
    o["updates"] = l.updates;
    o["resamplings"] = l.resamplings;
    o["particles_min"] = l.particles_min;
    o["particles_mean"] = l.particles_mean;
    o["particles_max"] = l.particles_max;
    o["cpu_time_s"] = l.cpu_time_s;
    o["log_duration_s"] = l.log_duration_s;
    o["real_time_factor"] = l.real_time_factor;
    o["real_time_factor_cpu"] = l.real_time_factor_cpu;
    o["anomaly_bits"] = l.anomaly_bits;
    o["anomaly_cells"] = l.anomaly_cells;
    o["lookup_bytes"] = l.lookup_bytes;
    o["lookup_build_s"] = l.lookup_build_s;
    o["recoveries"] = l.recoveries;
    o["global_searches"] = l.global_searches;
    o["global_search_s"] = l.global_search_s;
    o["proposal_matches"] = l.proposal_matches;
    j["localization"] = o;
  }

  // Invalid UTF-8 in a path or message is replaced rather than thrown.
  const std::string text =
      j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
  auto write = [&](std::ostream& out) { return static_cast<bool>(out << text); };
  if (files) return files->add(path, write, error);
  return writeFileAtomically(path, write, error);
}

}  // namespace io
}  // namespace evidential_slam
