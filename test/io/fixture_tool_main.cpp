// evidential_slam_fixture_tool: the MRPT steps of test/data/make_fixtures.py that no MRPT CLI
// offers (simul-gridmap writes zero odometry increments; nothing converts to observation-only).
//   add-odometry IN OUT GT [SEED]   noisy odometry increments from the true poses, label LASER
//   to-observations IN OUT          Actions/SensoryFrame -> observation-only
//   fuzz-seeds DATA_DIR MRPT_DATASETS_DIR OUT_DIR
//                                   the rawlog fuzzer's seed corpus (test/fuzz/corpus/rawlog)
#include <cstdio>
#include <cstdlib>
#include <string>

#include "rawlog_fixtures.h"

int main(int argc, char** argv) {
  namespace t = evidential_slam::test;
  const std::string cmd = argc > 1 ? argv[1] : "";
  std::string error;
  bool ok = false;
  if (cmd == "add-odometry" && (argc == 5 || argc == 6)) {
    t::OdometryNoise noise;
    if (argc == 6) noise.seed = std::strtoull(argv[5], nullptr, 10);
    ok = t::addNoisyOdometry(argv[2], argv[3], argv[4], noise, "LASER", &error);
  } else if (cmd == "to-observations" && argc == 4) {
    ok = t::convertToObservations(argv[2], argv[3], &error);
  } else if (cmd == "fuzz-seeds" && argc == 5) {
    ok = t::writeRawlogFuzzSeeds(argv[2], argv[3], argv[4], &error);
  } else {
    std::fprintf(stderr,
                 "usage: %s add-odometry IN OUT GT [SEED] | to-observations IN OUT | "
                 "fuzz-seeds DATA_DIR MRPT_DATASETS_DIR OUT_DIR\n",
                 argc > 0 ? argv[0] : "evidential_slam_fixture_tool");
    return 1;
  }
  if (!ok) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return 2;
  }
  return 0;
}
