// libFuzzer target for the simulator's text inputs: the bytes as a waypoint file (readWaypoints)
// and, split at newlines, as its command line (parseSimulateArgs). Accepted waypoints are finite
// and at least two; refusals leave no waypoints and give a one-line error.
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/io/simulate_args.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace io = evidential_slam::io;
  using evidential_slam::fuzz::checkErrorLine;
  using evidential_slam::fuzz::die;
  const std::string text(reinterpret_cast<const char*>(data), size);

  std::istringstream in(text);
  std::vector<Eigen::Vector2d> waypoints;
  std::string error;
  if (io::readWaypoints(in, "fuzz input", &waypoints, &error)) {
    if (waypoints.size() < 2) die("fewer than two waypoints accepted", "");
    for (const auto& w : waypoints) {
      if (!w.allFinite()) die("non-finite waypoint accepted", "");
    }
  } else {
    if (!waypoints.empty()) die("waypoints left after an error", "");
    checkErrorLine(error);
  }

  std::vector<std::string> args;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) args.push_back(line);
  io::SimulateOptions options;
  bool help = false;
  error.clear();
  if (io::parseSimulateArgs(args, &options, &help, &error)) {
    std::string why;
    if (!help && !options.config.isValid(&why)) die("invalid options accepted:", why);
  } else {
    if (error.empty()) die("no reason for refused arguments", "");
  }
  return 0;
}
