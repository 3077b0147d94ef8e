// evidential_slam_ate: scores a TUM trajectory (e.g. trajectory.tum from the node's save_map or
// the offline runner) against a GridmapNavSimul ground truth, as the offline runner does.
//   evidential_slam_ate TRAJECTORY.tum GROUND_TRUTH.txt [max_dt=0.05]
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/command_line.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/trajectory_io.h"

int main(int argc, char** argv) {
  namespace es = evidential_slam;
  const std::string program = argc > 0 ? argv[0] : "evidential_slam_ate";
  std::string trajectory_path, truth_path, max_dt_text;
  es::io::CommandLine cl(
      "usage: " + program +
          " TRAJECTORY.tum GROUND_TRUTH.txt [max_dt_s]\n"
          "Scores a TUM trajectory against a `t x y phi` ground truth as the offline runner does:\n"
          "prints the ATE's RMSE and maximum.",
      "Exit codes: 0 success, 1 bad usage, 2 unreadable files or no poses matched.");
  cl.positional("TRAJECTORY", "the estimate (TUM: `t x y z qx qy qz qw` per line)",
                &trajectory_path, true);
  cl.positional("GROUND_TRUTH", "the truth (`t x y phi` per line)", &truth_path, true);
  cl.positional("max_dt_s", "the largest time gap (s) of a matched pair (default 0.05)",
                &max_dt_text, false);
  if (const int code = cl.parseMain(argc, argv, 1); code >= 0) return code;
  double max_dt = 0.05;
  if (!max_dt_text.empty() &&
      (!es::io::parseNumber(max_dt_text, &max_dt) || !(max_dt > 0.0 && std::isfinite(max_dt)))) {
    std::fprintf(stderr, "error: max_dt_s wants a number > 0 (s), not '%s' (see --help)\n",
                 max_dt_text.c_str());
    return 1;
  }
  std::vector<es::StampedPose> estimate, truth;
  std::string error;
  if (!es::io::readTumTrajectory(trajectory_path, &estimate, &error) ||
      !es::io::readGroundTruth(truth_path, &truth, &error)) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return 2;
  }
  es::AteResult ate;
  if (!es::computeAte(estimate, truth, max_dt, &ate, &error)) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return 2;
  }
  std::printf("ATE RMSE %.4f m, max %.4f m, %zu of %zu poses matched\n", ate.rmse, ate.max_error,
              ate.matched, estimate.size());
  return 0;
}
