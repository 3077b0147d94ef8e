// The offline runner behind `evidential_slam_offline`: streams a rawlog into
// SlamEngine::processScan (the same entry point the ROS node uses), then writes the trajectory, the
// layers and summary.json. Kept out of main() so the command line and the run can be tested without
// a process.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/conflict_alarm.h"

namespace evidential_slam {
class EvidentialGridMap;
namespace io {

// Process exit codes of the runner.
enum ExitCode : int {
  kExitOk = 0,        // success, also for a truncated log (with a warning)
  kExitUsage = 1,     // bad command line or parameter values
  kExitBadInput = 2,  // unusable input (missing, not a rawlog, no scans, no odometry, bad GT)
                      // or an output that cannot be written
  kExitInternal = 3,  // unexpected failure inside the run (a bug)
};

struct OfflineOptions {
  std::string rawlog;
  std::string out_dir;
  std::string ground_truth;  // optional `t x y phi` file
  std::string laser_label;   // optional: only scans with this sensor label
  SlamConfig slam;           // core defaults; --particles/--seed/--resolution/--threads override
  ConflictAlarmConfig conflict_alarm;  // per-scan alarm written to conflict.csv
  std::string preset = "sim";  // --preset: "sim" (the defaults) or "real" (applyRealRobotPreset)
  // --param NAME=VALUE, in the order given, applied over the preset (setSlamParameter).
  std::vector<std::pair<std::string, std::string>> parameters;
  uint64_t max_scans = 0;    // 0 = all
  bool quiet = false;        // no progress line, no per-scan warnings
  double ate_max_dt = 0.05;  // s, timestamp association window for the ATE
  // --export-octomap: <out>/octomap/map.{evidential.ot,bt,color.ot} (octomap_export.h), a slab
  // of voxel layers from the one containing octomap_z_min to the one containing octomap_z_max.
  bool export_octomap = false;
  double octomap_z_min = 0.0;  // m
  double octomap_z_max = 0.0;  // m
};

// What a map exporter wrote, for summary.json and the printed summary.
struct MapExportReport {
  std::vector<std::string> files;  // full paths
  std::vector<uint64_t> bytes;     // size of each file
  double seconds = 0.0;            // whole export
  int z_layers = 0;
  uint64_t voxels = 0;
};

// Writes the final map in further formats after the layers. The OctoMap export lives in its own
// library (evidential_slam_octomap, which depends on this one), so main() passes it in
// (exportOctomapForOfflineRun, octomap_export.h).
using MapExporter = std::function<bool(const EvidentialGridMap& map, const OfflineOptions& options,
                                       MapExportReport* report, std::string* error)>;

// Usage text for --help and usage errors.
std::string offlineUsage(const std::string& program);

// Parses the arguments after the program name. False with a one-line `error` on bad usage;
// `help` is set (and true returned) for -h/--help.
bool parseOfflineArgs(const std::vector<std::string>& args, OfflineOptions* options, bool* help,
                      std::string* error);

// Runs everything; returns the exit code. The short summary goes to `out`; progress, warnings and
// `error: ...` lines go to `err` (progress redraws in place when `err_is_tty`). With
// options.export_octomap, `octomap_exporter` must be set (else kExitUsage before any work).
int runOffline(const OfflineOptions& options, std::FILE* out, std::FILE* err, bool err_is_tty,
               const MapExporter& octomap_exporter = nullptr);

// Peak resident set size of this process so far, MB (getrusage).
double peakRssMb();

}  // namespace io
}  // namespace evidential_slam
