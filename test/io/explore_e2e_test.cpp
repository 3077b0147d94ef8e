// End to end: the built evidential_slam_explore runs a short exploration of the two-room fixture
// map and writes exploration.json; bad usage gets exit code 2 and a one-line message.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

// Runs the binary with `args` (already quoted where needed); the exit code, stderr in `err`.
int runExplore(const std::string& args, const fs::path& scratch, std::string* err) {
  const fs::path err_path = scratch / "stderr.txt";
  const std::string cmd = std::string("'") + ES_EXPLORE_BIN + "' " + args + " > /dev/null 2> '" +
                          err_path.string() + "' < /dev/null";
  const int status = std::system(cmd.c_str());
  *err = test::readText(err_path);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ExploreE2e, ShortRunWritesExplorationJson) {
  const fs::path dir = test::scratchDir();
  std::string err;
  const std::string args = "--map '" + test::dataPath("sim_map.png") +
                           "' --start -6,-4,0 --strategy frontier --max-time 8 --param "
                           "particles=10 --out '" + (dir / "run").string() + "'";
  ASSERT_EQ(runExplore(args, dir, &err), 0) << err;
  const nlohmann::json j = nlohmann::json::parse(test::readText(dir / "run" / "exploration.json"));
  EXPECT_EQ(j["stop_reason"].get<std::string>(), "max_time reached");
  EXPECT_GT(j["final_coverage"].get<double>(), 0.05);  // 8 s of a 30 m laser in a 16 m room
  EXPECT_GE(j["sim_time_s"].get<double>(), 8.0);
  EXPECT_EQ(j["collisions"].get<int>(), 0);
  EXPECT_NEAR(j["gap_band_m"].get<double>(), 0.125, 1e-12);
}

TEST(ExploreE2e, BadUsageGetsOneLine) {
  const fs::path dir = test::scratchDir();
  std::string err;
  EXPECT_EQ(runExplore("--map x.png", dir, &err), 2);
  EXPECT_EQ(err, "error: --map and --out are required (see --help)\n");
  EXPECT_EQ(runExplore("--map x.png --out y --frobnicate 1", dir, &err), 2);
  EXPECT_EQ(err, "error: unknown option --frobnicate (see --help)\n");
  EXPECT_EQ(runExplore("--map x.png --out y --param gain_rays=2", dir, &err), 2);
  EXPECT_EQ(err, "error: unknown or bad parameter gain_rays=2\n");
  EXPECT_EQ(runExplore("--map x.png --out y --start 1,2", dir, &err), 2);
  EXPECT_EQ(err, "error: bad value '1,2' for --start (see --help)\n");
}

}  // namespace
}  // namespace evidential_slam
