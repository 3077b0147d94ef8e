// The command line of `evidential_slam_simulate` (src/apps/simulate_main.cpp): every
// GridmapSimulatorConfig field is an option (--name, '_' written '-'), plus --out and the two
// fault shorthands --kidnap and --moving-object. Kept out of main() so it can be tested.
#pragma once

#include <string>
#include <vector>

#include "evidential_slam/io/gridmap_simulator.h"

namespace evidential_slam {
namespace io {

struct SimulateOptions {
  GridmapSimulatorConfig config;
  std::string out;     // the rawlog to write; the ground truth goes to <out>.GT.txt
  bool quiet = false;  // no summary on stdout
  std::string truth_scans;  // --truth-scans: per-scan truth file (simulateToRawlog); "" = none
};

// Process exit codes of evidential_slam_simulate.
enum SimulateExitCode : int {
  kSimulateOk = 0,
  kSimulateUsage = 1,     // bad command line or parameter values
  kSimulateBadInput = 2,  // unreadable map or waypoints, or an output that cannot be written
};

std::string simulateUsage(const std::string& program);

// Parses the arguments after the program name. False with a one-line `error` on bad usage
// (unknown option, missing value, malformed number, missing --map/--waypoints/--out, or values
// GridmapSimulatorConfig::isValid refuses); `help` is set (and true returned) for -h/--help.
bool parseSimulateArgs(const std::vector<std::string>& args, SimulateOptions* options, bool* help,
                       std::string* error);

}  // namespace io
}  // namespace evidential_slam
