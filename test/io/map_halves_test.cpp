// Continue mapping through the offline runner's command line, on a whole log: MRPT's simul.rawlog
// (1732 scans) mapped in one go, and in two halves (--max-scans 866 with --out, then
// --first-scan 866 --load-map on that directory). The halves' joined path must end within 0.1 m
// ATE of the one go's, and the two final maps must agree on >= 98 % of the observed cells' BetP
// class. K = 30 keeps the three runs (two whole logs' worth) short; ES_MAP_HALVES_PARTICLES sets
// another K (docs/decisions.md, "Starting on a loaded map", has K = 100 figures).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/io/trajectory_io.h"
#include "map_compare.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

const fs::path kLogDir = "/usr/share/mrpt/datasets/graphslam-engine-demos/action_observations_map";
constexpr int kHalf = 866;

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs the offline runner; returns its wall time (s), or a negative value when it failed.
double run(const std::vector<std::string>& args, const fs::path& scratch) {
  std::string cmd = quote(ES_OFFLINE_BIN);
  for (const auto& a : args) cmd += " " + quote(a);
  cmd += " > " + quote((scratch / "stdout.txt").string()) + " 2> " +
         quote((scratch / "stderr.txt").string()) + " < /dev/null";
  const auto t0 = std::chrono::steady_clock::now();
  const int status = std::system(cmd.c_str());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  EXPECT_TRUE(ok) << cmd << "\n" << test::readText(scratch / "stderr.txt");
  return ok ? seconds : -1.0;
}

std::vector<StampedPose> trajectoryOf(const fs::path& out) {
  std::vector<StampedPose> path;
  std::string error;
  EXPECT_TRUE(io::readTumTrajectory((out / "trajectory.tum").string(), &path, &error)) << error;
  return path;
}

EvidentialGridMap mapOf(const fs::path& out) {
  EvidentialGridMap map;
  io::MapFileInfo info;
  std::string error;
  EXPECT_TRUE(io::readMapFile((out / io::kMapFileName).string(), &map, &info, &error)) << error;
  return map;
}

TEST(MapHalves, SimulInTwoHalvesEndsLikeOneGo) {
  const fs::path log = kLogDir / "simul.rawlog", gt = kLogDir / "simul.rawlog.GT.txt";
  if (!fs::exists(log) || !fs::exists(gt)) GTEST_SKIP() << "no " << log << " (mrpt-common)";
  const char* env_particles = std::getenv("ES_MAP_HALVES_PARTICLES");
  const std::string particles = env_particles != nullptr ? env_particles : "30";
  const std::vector<std::string> settings = {"--preset", "sim", "--particles", particles,
                                             "--seed",   "1",   "--threads",   "2",
                                             "--quiet"};
  auto with = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"--rawlog", log.string()});
    args.insert(args.end(), settings.begin(), settings.end());
    return args;
  };
  const fs::path scratch = test::scratchDir();
  const fs::path whole = scratch / "whole", first = scratch / "first", second = scratch / "second";
  const double t_whole = run(with({"--out", whole.string()}), scratch);
  const double t_first =
      run(with({"--out", first.string(), "--max-scans", std::to_string(kHalf)}), scratch);
  const double t_second = run(with({"--out", second.string(), "--first-scan",
                                    std::to_string(kHalf), "--load-map", first.string()}),
                              scratch);
  ASSERT_GT(t_whole, 0.0);
  ASSERT_GT(t_first, 0.0);
  ASSERT_GT(t_second, 0.0);
  const auto start = nlohmann::json::parse(test::readText(second / "summary.json"))["start"];
  EXPECT_EQ(start["odometry_anchored"], true);

  std::vector<StampedPose> truth;
  std::string error;
  ASSERT_TRUE(io::readGroundTruth(gt.string(), &truth, &error)) << error;
  std::vector<StampedPose> halves = trajectoryOf(first);
  EXPECT_EQ(halves.size(), static_cast<size_t>(kHalf));
  for (const StampedPose& p : trajectoryOf(second)) halves.push_back(p);
  const std::vector<StampedPose> one_go = trajectoryOf(whole);
  ASSERT_EQ(halves.size(), one_go.size());
  AteResult ate_whole, ate_halves;
  ASSERT_TRUE(computeAte(one_go, truth, 0.05, &ate_whole, &error)) << error;
  ASSERT_TRUE(computeAte(halves, truth, 0.05, &ate_halves, &error)) << error;
  EXPECT_EQ(ate_halves.matched, one_go.size());

  size_t compared = 0;
  const double agreement = test::classAgreement(mapOf(whole), mapOf(second), &compared);
  std::printf(
      "K = %s: ATE one go %.4f m (%.1f s), two halves %.4f m (%.1f s + %.1f s); BetP class "
      "agreement %.2f %% of %zu observed cells\n",
      particles.c_str(), ate_whole.rmse, t_whole, ate_halves.rmse, t_first, t_second,
      100.0 * agreement, compared);
  RecordProperty("ate_one_go_m", std::to_string(ate_whole.rmse));
  RecordProperty("ate_halves_m", std::to_string(ate_halves.rmse));
  RecordProperty("class_agreement", std::to_string(agreement));
  RecordProperty("wall_s", std::to_string(t_whole + t_first + t_second));
  EXPECT_LE(std::abs(ate_halves.rmse - ate_whole.rmse), 0.1);
  EXPECT_GT(compared, 500000u);
  EXPECT_GE(agreement, 0.98);
}

}  // namespace
}  // namespace evidential_slam
