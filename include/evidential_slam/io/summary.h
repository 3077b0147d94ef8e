// The machine-readable record of one offline run (summary.json): input, counts, time, memory,
// parameters and, with ground truth, the trajectory error. Benchmarks and tests read it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace evidential_slam {
namespace io {

struct AteSummary {
  double rmse_m = 0.0;
  double max_m = 0.0;
  uint64_t matched = 0;
};

// What --export-octomap wrote (summary.json: "octomap").
struct MapExportSummary {
  std::vector<std::string> files;  // relative to the output directory
  std::vector<uint64_t> bytes;     // size of each file
  double seconds = 0.0;            // export time, all files
  double z_min = 0.0;
  double z_max = 0.0;
  int z_layers = 0;
  uint64_t voxels = 0;  // observed cells * z_layers
};

struct RunSummary {
  std::string rawlog;
  std::string rawlog_format;            // "actions/sensory-frames" or "observations"
  std::string ground_truth;             // empty when none was given
  uint64_t scans_total = 0;             // scans given to the SLAM
  uint64_t scans_processed = 0;         // integrated (passed the motion gate)
  uint64_t scans_rejected = 0;          // refused by the core (ScanUpdate::rejected)
  uint64_t scans_without_odometry = 0;  // in the log but dropped by the reader
  uint64_t scans_dropped = 0;           // older than the scan before them (session)
  uint64_t rays_total = 0;
  uint64_t rays_bad = 0;  // NaN / inf / negative, skipped
  uint64_t rays_no_return = 0;
  uint64_t resamplings = 0;
  uint64_t long_steps = 0;  // processed scans after a long step (SlamConfig::isLongStep)
  // Groups of particles (one map, one pose) weighed and updated, summed over the filter's updates
  // (written as the total and per update).
  uint64_t group_updates = 0;
  double wall_time_s = 0.0;
  double slam_time_s = 0.0;  // inside processScan only
  double peak_rss_mb = 0.0;
  std::vector<std::string> config_files;  // --config / --preset files, in the order applied
  std::vector<std::pair<std::string, std::string>> parameters;  // --param NAME=VALUE, as given
  // Every parameter's value the run used (the table's names, in its order).
  std::vector<std::pair<std::string, std::string>> parameter_values;
  int particles = 0;
  double resolution = 0.0;
  uint64_t seed = 0;
  int threads = 0;
  bool truncated = false;
  std::vector<std::string> warnings;
  std::optional<AteSummary> ate;           // SLAM path vs ground truth
  std::optional<AteSummary> odometry_ate;  // raw odometry vs ground truth, for reference
  double external_conflict_scale = 0.0;    // EC drawn black in external_conflict.png
  int map_width = 0;
  int map_height = 0;
  std::vector<std::string> outputs;         // files written, relative to the output directory
  std::optional<MapExportSummary> octomap;  // with --export-octomap
  // Conflict alarm (conflict_alarm.h): stamps of the scans that raised a new alarm.
  std::vector<double> conflict_alarm_stamps;
};

// Writes `summary` as pretty-printed JSON. False (and `error`) when the file cannot be written.
bool writeSummaryJson(const std::string& path, const RunSummary& summary, std::string* error);

}  // namespace io
}  // namespace evidential_slam
