// Command line of evidential_slam_offline.
#include <gtest/gtest.h>

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
  ASSERT_TRUE(parse({"--rawlog", "a.rawlog", "--out=outdir", "--ground-truth", "gt.txt",
                     "--particles", "30", "--seed", "7", "--resolution", "0.1", "--threads", "2",
                     "--max-scans", "50", "--laser-label", "LASER", "--quiet"},
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
      {"--rawlog", "a", "--out"},
      {"--rawlog", "a", "--out", "b", "--quiet=1"},
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
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
