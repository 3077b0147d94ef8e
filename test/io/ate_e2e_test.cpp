// evidential_slam_ate as a process: a trajectory scored against its own truth, and bad usage
// (an unknown option, a bad max_dt, a missing file argument) as one line with exit code 1.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

TEST(AteE2e, ScoresATrajectoryAndRefusesBadUsage) {
  const fs::path dir = test::scratchDir();
  const std::string tum = (dir / "est.tum").string(), gt = (dir / "gt.txt").string();
  {
    std::ofstream est(tum), truth(gt);
    for (int i = 0; i < 5; ++i) {
      est << i << " " << 0.5 * i << " 1 0 0 0 0 1\n";
      truth << i << " " << 0.5 * i << " 1 0\n";
    }
  }
  test::RunResult r = test::runProgram(ES_ATE_BIN, {tum, gt}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "ATE RMSE 0.0000 m, max 0.0000 m, 5 of 5 poses matched\n");
  r = test::runProgram(ES_ATE_BIN, {tum, gt, "0.01"}, dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;

  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{tum, gt, "--bogus"}, "error: unknown option '--bogus' (see --help)\n"},
      {{tum, gt, "soon"}, "error: max_dt_s wants a number > 0 (s), not 'soon' (see --help)\n"},
      {{tum, gt, "0"}, "error: max_dt_s wants a number > 0 (s), not '0' (see --help)\n"},
      {{tum}, "error: GROUND_TRUTH is required (see --help)\n"},
      {{tum, gt, "0.1", "extra"}, "error: unexpected argument 'extra' (see --help)\n"},
  };
  for (const auto& [args, message] : bad) {
    r = test::runProgram(ES_ATE_BIN, args, dir);
    EXPECT_EQ(r.exit_code, 1) << ::testing::PrintToString(args);
    EXPECT_EQ(r.err, message) << ::testing::PrintToString(args);
  }
  r = test::runProgram(ES_ATE_BIN, {"--help"}, dir);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("TRAJECTORY.tum GROUND_TRUTH.txt [max_dt_s]"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace evidential_slam
