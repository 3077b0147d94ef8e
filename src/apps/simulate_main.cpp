// evidential_slam_simulate: simulates a robot on a grid map along a waypoint route and writes an
// MRPT rawlog plus its ground truth (<out>.GT.txt) for the offline runner. Thin: the options are
// parsed by io::parseSimulateArgs and the run is io::simulateToRawlog (gridmap_simulator.h).
#include <cstdio>
#include <string>
#include <vector>

#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/io/simulate_args.h"

int main(int argc, char** argv) {
  namespace io = evidential_slam::io;
  const std::string program = argc > 0 ? argv[0] : "evidential_slam_simulate";
  const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
  io::SimulateOptions options;
  bool help = false;
  std::string error;
  if (!io::parseSimulateArgs(args, &options, &help, &error)) {
    std::fprintf(stderr, "error: %s (see --help)\n", error.c_str());
    return io::kSimulateUsage;
  }
  if (help) {
    std::fputs(io::simulateUsage(program).c_str(), stdout);
    return io::kSimulateOk;
  }
  io::SimulationSummary summary;
  if (!io::simulateToRawlog(options.config, options.out, &summary, &error, options.truth_scans)) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return io::kSimulateBadInput;
  }
  const auto& c = options.config;
  if (c.hasKidnap() && !summary.kidnapped) {
    std::fprintf(stderr, "warning: the run ended at %.2f s, before the kidnap at %.2f s\n",
                 summary.last_stamp, c.kidnap_time);
  }
  if (c.hasMovingObject() && summary.moving_object_scans == 0) {
    std::fprintf(stderr, "warning: no scan saw the moving object (the run spans %.2f-%.2f s)\n",
                 summary.first_stamp, summary.last_stamp);
  }
  if (summary.collisions > 0) {
    std::fprintf(stderr,
                 "warning: the robot (radius %.2f m) ran into a wall %llu time(s)%s; the route "
                 "must keep clear of walls\n",
                 c.robot_radius, static_cast<unsigned long long>(summary.collisions),
                 summary.stuck ? " and the route ended early, held by a wall for 5 s" : "");
  }
  if (!options.quiet) {
    std::printf(
        "wrote %llu scans (%.2f-%.2f s, %.1f m driven) to %s and %s\n"
        "odometry is %.2f m off the truth at the end\n",
        static_cast<unsigned long long>(summary.scans), summary.first_stamp, summary.last_stamp,
        summary.path_length, options.out.c_str(), io::groundTruthPathFor(options.out).c_str(),
        summary.odometry_error);
  }
  return io::kSimulateOk;
}
