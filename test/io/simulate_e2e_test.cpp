// End to end: the built evidential_slam_simulate binary writes a rawlog + ground truth that the
// built evidential_slam_offline maps and scores; exit codes and messages on bad usage and input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

ProcessResult runBinary(const std::string& binary, const std::vector<std::string>& args,
                        const fs::path& scratch) {
  auto quote = [](const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  std::string cmd = quote(binary);
  for (const auto& a : args) cmd += " " + quote(a);
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  cmd += " > " + quote(out.string()) + " 2> " + quote(err.string()) + " < /dev/null";
  const int status = std::system(cmd.c_str());
  ProcessResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = test::readText(out);
  r.err = test::readText(err);
  return r;
}

size_t lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }

// The route through the two-room fixture map with noisy odometry (seed 3: ~0.75 m off at the end).
std::vector<std::string> simulateArgs(const fs::path& out) {
  return {"--map",
          test::dataPath("sim_map.png"),
          "--waypoints",
          test::dataPath("sim_map_waypoints.txt"),
          "--seed",
          "3",
          "--odometry-noise-xy",
          "0.05",
          "--odometry-noise-theta",
          "0.05",
          "--odometry-noise-theta-per-m",
          "0.05",
          "--out",
          out.string()};
}

// A simulation whose output cannot be written (no file may grow past 100 kB, as on a full disk)
// exits 2 with the reason and leaves the previous rawlog and ground truth as they were, with no
// temporary file beside them.
TEST(SimulateE2e, AFailedRecordingKeepsThePreviousFiles) {
  const fs::path dir = test::scratchDir();
  const fs::path rawlog = dir / "sim.rawlog";
  ASSERT_EQ(runBinary(ES_SIMULATE_BIN, simulateArgs(rawlog), dir).exit_code, 0);
  const std::string old_rawlog = test::readText(rawlog);
  const std::string old_truth = test::readText(dir / "sim.rawlog.GT.txt");
  ASSERT_GT(old_rawlog.size(), 100000u);

  std::vector<std::string> args = {
      "-c", "trap '' XFSZ; exec prlimit --fsize=100000 -- \"$0\" \"$@\"", ES_SIMULATE_BIN};
  for (const std::string& a : simulateArgs(rawlog)) args.push_back(a);
  args.insert(args.end(), {"--seed", "4"});  // another run: other bytes
  const ProcessResult r = runBinary("/bin/sh", args, dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
  EXPECT_TRUE(test::readText(rawlog) == old_rawlog);
  EXPECT_TRUE(test::readText(dir / "sim.rawlog.GT.txt") == old_truth);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"sim.rawlog", "sim.rawlog.GT.txt", "stderr.txt",
                                             "stdout.txt"}));
}

TEST(SimulateE2e, SimulatedRunFeedsTheOfflineRunner) {
  const fs::path dir = test::scratchDir();
  const fs::path rawlog = dir / "sim.rawlog";
  const ProcessResult sim = runBinary(ES_SIMULATE_BIN, simulateArgs(rawlog), dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_EQ(sim.err, "");
  EXPECT_NE(sim.out.find("wrote "), std::string::npos) << sim.out;
  const fs::path truth = dir / "sim.rawlog.GT.txt";
  ASSERT_TRUE(fs::is_regular_file(truth));
  const size_t scans = lines(test::readText(truth));
  EXPECT_GT(scans, 300u);
  EXPECT_NE(sim.out.find("wrote " + std::to_string(scans) + " scans"), std::string::npos);

  // Deterministic for a seed.
  const fs::path again = dir / "again.rawlog";
  ASSERT_EQ(runBinary(ES_SIMULATE_BIN, simulateArgs(again), dir).exit_code, 0);
  EXPECT_EQ(test::readText(again), test::readText(rawlog));
  EXPECT_EQ(test::readText(dir / "again.rawlog.GT.txt"), test::readText(truth));

  const fs::path out = dir / "slam";
  const ProcessResult slam =
      runBinary(ES_OFFLINE_BIN,
                {"--rawlog", rawlog.string(), "--ground-truth", truth.string(), "--out",
                 out.string(), "--preset", "sim", "--particles", "20", "--seed", "3", "--threads",
                 "2", "--quiet"},
                dir);
  ASSERT_EQ(slam.exit_code, 0) << slam.err;
  const auto j = nlohmann::json::parse(test::readText(out / "summary.json"));
  EXPECT_EQ(j["scans_total"].get<size_t>(), scans);
  EXPECT_EQ(j["ate_matched"].get<size_t>(), scans);
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.1);
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.7 * j["odometry_ate_rmse_m"].get<double>());
  RecordProperty("ate_rmse_m", std::to_string(j["ate_rmse_m"].get<double>()));
}

TEST(SimulateE2e, ExitCodesAndOneLineMessages) {
  const fs::path dir = test::scratchDir();
  ProcessResult r = runBinary(ES_SIMULATE_BIN, {"--help"}, dir);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--moving-object T0,T1,BEARING_MIN,BEARING_MAX,DISTANCE"),
            std::string::npos);

  r = runBinary(ES_SIMULATE_BIN, {}, dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "error: --map is required (see --help)\n");

  std::vector<std::string> args = simulateArgs(dir / "x.rawlog");
  args[1] = (dir / "missing.png").string();
  r = runBinary(ES_SIMULATE_BIN, args, dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("missing.png' does not exist"), std::string::npos) << r.err;

  args = simulateArgs(dir / "x.rawlog");
  args.insert(args.end(), {"--kidnap", "1000,1,0,0"});
  r = runBinary(ES_SIMULATE_BIN, args, dir);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.err.find("warning: the run ended at"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace evidential_slam
