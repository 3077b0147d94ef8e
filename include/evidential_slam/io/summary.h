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

// Where a run started when not from nothing (--load-map, --initial-pose; summary.json: "start").
struct StartSummary {
  std::string map_file;  // the map file loaded; empty: an empty map
  uint64_t map_tiles = 0;
  double x = 0.0, y = 0.0, theta = 0.0;  // the first scan's pose, map frame (m, m, rad)
  std::string pose_from;                 // "map file" or "--initial-pose"
  // The map file's odometry pose was used: the first scan is placed by the odometry since then.
  bool odometry_anchored = false;
};

// The lossless map file written (summary.json: "map_file").
struct MapFileSummary {
  std::string path;  // relative to the output directory
  uint64_t bytes = 0;
  uint64_t tiles = 0;
};

// A --localize-only run (summary.json: "localization").
struct LocalizationSummary {
  bool global = false;   // started from particles spread over the free space
  uint64_t updates = 0;  // scans that passed the motion gate
  uint64_t resamplings = 0;
  uint64_t particles_min = 0;   // after an update, over the updates
  double particles_mean = 0.0;  // weighed per update
  uint64_t particles_max = 0;
  double cpu_time_s = 0.0;            // process CPU (user + system, all threads) while localizing
  double log_duration_s = 0.0;        // the last scan's stamp minus the first's
  double real_time_factor = 0.0;      // log_duration_s / the wall time of the localization
  double real_time_factor_cpu = 0.0;  // log_duration_s / cpu_time_s
  double anomaly_bits = 0.0;          // Σ of the anomaly layer against the stored map
  uint64_t anomaly_cells = 0;         // cells with an anomaly
  uint64_t lookup_bytes = 0;          // laser_model_type beam: the lookup's memory (0: not built)
  double lookup_build_s = 0.0;        // ... and its build time (CPU s)
  uint64_t recoveries = 0;            // kidnap_recovery's spreads over the free space
  uint64_t global_searches = 0;       // correlative searches of a scan over the map
  double global_search_s = 0.0;       // ... their CPU s (score grids built included)
  uint64_t proposal_matches = 0;      // updates at which the mixture proposal matched the scan
};

struct RunSummary {
  std::string mode = "slam";  // "slam" or "localization" (--localize-only)
  std::string rawlog;
  std::string rawlog_format;            // "actions/sensory-frames" or "observations"
  std::string ground_truth;             // empty when none was given
  uint64_t first_scan = 0;              // scans of the log passed over first (--first-scan)
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
  std::optional<StartSummary> start;
  std::optional<MapFileSummary> map_file;
  std::vector<std::string> outputs;         // files written, relative to the output directory
  std::optional<MapExportSummary> octomap;  // with --export-octomap
  std::optional<LocalizationSummary> localization;
  // Conflict alarm (conflict_alarm.h): stamps of the scans that raised a new alarm.
  std::vector<double> conflict_alarm_stamps;
};

class AtomicFiles;

// Writes `summary` as pretty-printed JSON, replacing the old file only once complete
// (atomic_files.h; staged into `files` when given). False (and `error`, with the reason) when the
// file cannot be written.
bool writeSummaryJson(const std::string& path, const RunSummary& summary, std::string* error,
                      AtomicFiles* files = nullptr);

}  // namespace io
}  // namespace evidential_slam
