// Command line of evidential_slam_offline.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <set>
#include <string>

#include "evidential_slam/io/offline_runner.h"

namespace evidential_slam {
namespace io {
namespace {

bool parse(const std::vector<std::string>& args, OfflineOptions* o, std::string* error,
           bool* help = nullptr) {
  bool h = false;
  const bool ok = parseOfflineArgs(args, o, &h, error);
  if (help) *help = h;
  return ok;
}

TEST(OfflineArgs, ParsesEveryOption) {
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--rawlog",
                     "a.rawlog",
                     "--out=outdir",
                     "--ground-truth",
                     "gt.txt",
                     "--particles",
                     "30",
                     "--seed",
                     "7",
                     "--resolution",
                     "0.1",
                     "--threads",
                     "2",
                     "--max-scans",
                     "50",
                     "--laser-label",
                     "LASER",
                     "--quiet",
                     "--export-octomap",
                     "--octomap-z-min",
                     "-0.5",
                     "--octomap-z-max=1.5"},
                    &o, &error))
      << error;
  EXPECT_EQ(o.rawlog, "a.rawlog");
  EXPECT_EQ(o.out_dir, "outdir");
  EXPECT_EQ(o.ground_truth, "gt.txt");
  EXPECT_EQ(o.slam.particles, 30);
  EXPECT_EQ(o.slam.seed, 7u);
  EXPECT_DOUBLE_EQ(o.slam.resolution, 0.1);
  EXPECT_EQ(o.slam.threads, 2);
  EXPECT_EQ(o.max_scans, 50u);
  EXPECT_EQ(o.laser_label, "LASER");
  EXPECT_TRUE(o.quiet);
  EXPECT_TRUE(o.export_octomap);
  EXPECT_DOUBLE_EQ(o.octomap_z_min, -0.5);
  EXPECT_DOUBLE_EQ(o.octomap_z_max, 1.5);
}

TEST(OfflineArgs, DefaultsAreTheCoreDefaults) {
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--rawlog", "a", "--out", "b"}, &o, &error)) << error;
  const SlamConfig defaults;
  EXPECT_EQ(o.slam.particles, defaults.particles);
  EXPECT_EQ(o.slam.resolution, defaults.resolution);
  EXPECT_EQ(o.max_scans, 0u);
  EXPECT_TRUE(o.slam.isValid(&error)) << error;
  EXPECT_FALSE(o.export_octomap);
  EXPECT_EQ(o.octomap_z_min, 0.0);
  EXPECT_EQ(o.octomap_z_max, 0.0);
}

// --preset real applies the core's real-robot preset (the wide-basin match); sim is the default.
TEST(OfflineArgs, Preset) {
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--rawlog", "a", "--out", "b"}, &o, &error)) << error;
  EXPECT_EQ(o.preset, "sim");
  EXPECT_EQ(o.slam.matcher.heading_window, 0.0);
  OfflineOptions real;
  ASSERT_TRUE(parse({"--preset", "real", "--rawlog", "a", "--out", "b", "--particles", "30"}, &real,
                    &error))
      << error;
  SlamConfig expected;
  expected.particles = 30;
  applyRealRobotPreset(&expected);
  EXPECT_EQ(real.preset, "real");
  EXPECT_EQ(real.slam.particles, 30);
  EXPECT_EQ(real.slam.matcher.heading_window, expected.matcher.heading_window);
  EXPECT_GT(real.slam.matcher.heading_window, 0.0);
  EXPECT_TRUE(real.slam.isValid(&error)) << error;
}

// config/real.yaml (the node's preset) sets what --preset real sets: each of its `name: value`
// lines, applied by ROS name to the defaults, gives applyRealRobotPreset's value, and it names
// each of the seven fields the preset changes; the dynamic_reconfigure file mentions it.
TEST(OfflineArgs, NodePresetFileMatchesThePreset) {
  std::ifstream in(std::string(ES_TEST_DATA_DIR) + "/../../config/real.yaml");
  ASSERT_TRUE(in.good());
  SlamConfig from_file;
  std::set<std::string> names;
  std::string line, why;
  const auto trim = [](std::string t) {
    t.erase(0, t.find_first_not_of(" \t"));
    t.erase(t.find_last_not_of(" \t") + 1);
    return t;
  };
  while (std::getline(in, line)) {
    line = line.substr(0, line.find('#'));
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string name = trim(line.substr(0, colon)), value = trim(line.substr(colon + 1));
    EXPECT_TRUE(setSlamParameter(name, value, &from_file, &why)) << why;
    names.insert(name);
  }
  EXPECT_EQ(names, (std::set<std::string>{"matcher_heading_window", "forward_conflict_as_unknown",
                                          "along_track_prior", "matcher_icp_iterations",
                                          "matcher_long_step_beam_spacing", "alpha_rot_rot",
                                          "long_step_forward_sigma"}));
  SlamConfig preset;
  applyRealRobotPreset(&preset);
  EXPECT_EQ(from_file.matcher.heading_window, preset.matcher.heading_window);
  EXPECT_EQ(from_file.sensor.forward_conflict_as_unknown,
            preset.sensor.forward_conflict_as_unknown);
  EXPECT_EQ(from_file.along_track_prior, preset.along_track_prior);
  EXPECT_EQ(from_file.matcher.icp_iterations, preset.matcher.icp_iterations);
  EXPECT_EQ(from_file.matcher.long_step_beam_spacing, preset.matcher.long_step_beam_spacing);
  EXPECT_EQ(from_file.motion.alpha_rot_rot, preset.motion.alpha_rot_rot);
  EXPECT_EQ(from_file.sensor.long_step_forward_sigma, preset.sensor.long_step_forward_sigma);

  // dynamic_reconfigure's description of each of them names the preset's value.
  std::ifstream cfg(std::string(ES_TEST_DATA_DIR) + "/../../cfg/EvidentialSlam.cfg");
  ASSERT_TRUE(cfg.good());
  std::set<std::string> described;
  while (std::getline(cfg, line)) {
    for (const std::string& name : names) {
      if (line.find(".add(\"" + name + "\"") == std::string::npos) continue;
      EXPECT_NE(line.find("config/real.yaml: "), std::string::npos) << line;
      described.insert(name);
    }
  }
  EXPECT_EQ(described, names);
}

// --param NAME=VALUE sets a SLAM parameter by its ROS name, over the preset, in order.
TEST(OfflineArgs, ParamOverridesThePreset) {
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(
      parse({"--param", "matcher_heading_window=0.2", "--preset", "real", "--rawlog", "a", "--out",
             "b", "--param=resample_threshold=0.3", "--param", "resample_threshold=0.25"},
            &o, &error))
      << error;
  EXPECT_DOUBLE_EQ(o.slam.matcher.heading_window, 0.2);
  EXPECT_DOUBLE_EQ(o.slam.resample_threshold, 0.25);
  ASSERT_EQ(o.parameters.size(), 3u);
  EXPECT_EQ(o.parameters[1].first, "resample_threshold");
  EXPECT_EQ(o.parameters[1].second, "0.3");
  EXPECT_NE(offlineUsage("prog").find("likelihood_temperature"), std::string::npos);
}

TEST(OfflineArgs, BadUsageHasOneLineErrors) {
  const std::vector<std::vector<std::string>> bad = {
      {},
      {"--rawlog", "a"},
      {"--out", "b"},
      {"--rawlog", "a", "--out", "b", "--particles", "0"},
      {"--rawlog", "a", "--out", "b", "--particles", "many"},
      {"--rawlog", "a", "--out", "b", "--resolution", "-1"},
      {"--rawlog", "a", "--out", "b", "--threads", "-2"},
      {"--rawlog", "a", "--out", "b", "--max-scans", "0"},
      {"--rawlog", "a", "--out", "b", "--seed", "-3"},
      {"--rawlog", "a", "--out", "b", "--bogus"},
      {"--rawlog", "a", "--out", "b", "--preset", "fast"},
      {"--rawlog", "a", "--out"},
      {"--rawlog", "a", "--out", "b", "--quiet=1"},
      {"--rawlog", "a", "--out", "b", "--export-octomap=yes"},
      {"--rawlog", "a", "--out", "b", "--octomap-z-min", "0.5"},  // without --export-octomap
      {"--rawlog", "a", "--out", "b", "--export-octomap", "--octomap-z-min", "low"},
      {"--rawlog", "a", "--out", "b", "--export-octomap", "--octomap-z-max", "nan"},
      {"--rawlog", "a", "--out", "b", "--export-octomap", "--octomap-z-max", "1e9"},
      {"--rawlog", "a", "--out", "b", "--export-octomap", "--octomap-z-min", "1", "--octomap-z-max",
       "0.5"},
      {"--rawlog", "a", "--out", "b", "--export-octomap", "--octomap-z-min"},
      {"--rawlog", "a", "--out", "b", "--param", "resample_threshold"},
      {"--rawlog", "a", "--out", "b", "--param", "=0.3"},
      {"--rawlog", "a", "--out", "b", "--param", "no_such_parameter=1"},
      {"--rawlog", "a", "--out", "b", "--param", "likelihood_temperature=warm"},
      {"--rawlog", "a", "--out", "b", "--param"},
  };
  for (const auto& args : bad) {
    OfflineOptions o;
    std::string error;
    EXPECT_FALSE(parse(args, &o, &error)) << ::testing::PrintToString(args);
    EXPECT_FALSE(error.empty());
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

TEST(OfflineArgs, Help) {
  OfflineOptions o;
  std::string error;
  bool help = false;
  EXPECT_TRUE(parse({"--help"}, &o, &error, &help));
  EXPECT_TRUE(help);
  EXPECT_NE(offlineUsage("prog").find("--rawlog FILE"), std::string::npos);
  EXPECT_NE(offlineUsage("prog").find("--export-octomap"), std::string::npos);
}

TEST(OfflineArgs, ExportOctomapNeedsAnExporter) {
  // The runner lives in evidential_slam_io, which has no OctoMap: main() passes the exporter in.
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--rawlog", "missing.rawlog", "--out", "b", "--export-octomap"}, &o, &error));
  std::FILE* out = std::tmpfile();
  std::FILE* err = std::tmpfile();
  ASSERT_TRUE(out && err);
  EXPECT_EQ(runOffline(o, out, err, false), kExitUsage);
  std::rewind(err);
  char line[256] = {};
  ASSERT_NE(std::fgets(line, sizeof(line), err), nullptr);
  EXPECT_NE(std::string(line).find("--export-octomap is not available"), std::string::npos) << line;
  std::fclose(out);
  std::fclose(err);
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
