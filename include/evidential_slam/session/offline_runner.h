// The offline runner behind `evidential_slam_offline`: streams a rawlog through a MappingSession
// (the same scan order, engine and conflict alarm as the ROS node; or, with --localize-only, its
// Localizer on a saved map), then writes the map files (writeMapFiles, as ~save_map does) and
// summary.json. Kept out of main() so the command line
// and the run can be tested without a process.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace io {

// Process exit codes of the runner.
enum ExitCode : int {
  kExitOk = 0,        // success, also for a truncated log (with a warning)
  kExitUsage = 1,     // bad command line, parameter values or parameter files
  kExitBadInput = 2,  // unusable input (missing, not a rawlog, no scans, no odometry, bad GT)
                      // or an output that cannot be written
  kExitInternal = 3,  // unexpected failure inside the run (a bug)
};

struct OfflineOptions {
  std::string rawlog;
  std::string out_dir;
  std::string ground_truth;  // optional `t x y phi` file
  std::string laser_label;   // optional: only scans with this sensor label
  // The defaults, then each of config_files in order, then `parameters` in order.
  Parameters params;
  std::vector<std::string> config_files;  // --config FILE / --preset NAME, as applied
  // --param NAME=VALUE and the shorthand options (--particles, --seed, ...), in the order given.
  std::vector<std::pair<std::string, std::string>> parameters;
  std::vector<std::string> ignored;  // node-only names met in config files
  uint64_t first_scan = 0;           // scans of the log passed over before the first one used
  uint64_t max_scans = 0;            // 0 = all
  // Continue mapping on a saved map (a map file, or a directory holding map.evmap), at the pose
  // saved in it or at `initial_pose`.
  std::string load_map;
  bool has_initial_pose = false;  // --initial-pose x,y,yaw (map frame); without --load-map: the
  Pose2 initial_pose;             // first scan's pose on an empty map
  // --localize-only: localize on the --load-map map (never changed) instead of mapping, from
  // `initial_pose` (default 0,0,0) with `initial_covariance` (default: the initial_cov_*
  // parameters), or, with --global, from particles spread over the map's free space.
  bool localize_only = false;
  bool global_localization = false;
  bool has_initial_covariance = false;  // --initial-cov XX,YY,AA (variances: m², m², rad²)
  double initial_covariance[3] = {0.0, 0.0, 0.0};
  // --all-layers: a localization's layers/ holds the stored map's layers too, not only the anomaly.
  bool all_layers = false;
  bool quiet = false;        // no progress line, no per-scan warnings
  bool profile = false;      // --profile: time the update's sections (profile.h)
  double ate_max_dt = 0.05;  // s, timestamp association window for the ATE
};

// Usage text for --help and usage errors.
std::string offlineUsage(const std::string& program);

// The file `--preset NAME` stands for: NAME.yaml in the package's config/ directory.
std::string presetFile(const std::string& name);

// Parses the arguments after the program name, reading the parameter files they name. False with
// a one-line `error` on bad usage; `help` is set (and true returned) for -h/--help.
bool parseOfflineArgs(const std::vector<std::string>& args, OfflineOptions* options, bool* help,
                      std::string* error);

// Runs everything; returns the exit code. The short summary goes to `out`; progress, warnings and
// `error: ...` lines go to `err` (progress redraws in place when `err_is_tty`).
int runOffline(const OfflineOptions& options, std::FILE* out, std::FILE* err, bool err_is_tty);

// Peak resident set size of this process so far, MB (getrusage).
double peakRssMb();
// CPU time (user + system) of this process so far, s (getrusage).
double processCpuSeconds();

}  // namespace io
}  // namespace evidential_slam
