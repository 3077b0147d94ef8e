// evidential_slam_ate: scores a TUM trajectory (e.g. trajectory.tum from the node's save_map or
// the offline runner) against a GridmapNavSimul ground truth, as the offline runner does.
//   evidential_slam_ate TRAJECTORY.tum GROUND_TRUTH.txt [max_dt=0.05]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/trajectory_io.h"

int main(int argc, char** argv) {
  namespace es = evidential_slam;
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s TRAJECTORY.tum GROUND_TRUTH.txt [max_dt_s]\n", argv[0]);
    return 1;
  }
  const double max_dt = argc == 4 ? std::atof(argv[3]) : 0.05;
  std::vector<es::StampedPose> estimate, truth;
  std::string error;
  if (!es::io::readTumTrajectory(argv[1], &estimate, &error) ||
      !es::io::readGroundTruth(argv[2], &truth, &error)) {
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
