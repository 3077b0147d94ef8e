// Command line of evidential_slam_offline.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "evidential_slam/io/parameter_file.h"
#include "evidential_slam/session/offline_runner.h"

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
                     "--octomap-z-max=1.5",
                     "--first-scan",
                     "12",
                     "--load-map",
                     "saved/",
                     "--initial-pose=1.5,-2,0.25"},
                    &o, &error))
      << error;
  EXPECT_EQ(o.rawlog, "a.rawlog");
  EXPECT_EQ(o.out_dir, "outdir");
  EXPECT_EQ(o.ground_truth, "gt.txt");
  EXPECT_EQ(o.params.slam.particles, 30);
  EXPECT_EQ(o.params.slam.seed, 7);
  EXPECT_DOUBLE_EQ(o.params.slam.resolution, 0.1);
  EXPECT_EQ(o.params.slam.threads, 2);
  EXPECT_EQ(o.max_scans, 50u);
  EXPECT_EQ(o.laser_label, "LASER");
  EXPECT_TRUE(o.quiet);
  EXPECT_TRUE(o.params.session.export_octomap);
  EXPECT_DOUBLE_EQ(o.params.session.octomap_z_min, -0.5);
  EXPECT_DOUBLE_EQ(o.params.session.octomap_z_max, 1.5);
  EXPECT_EQ(o.first_scan, 12u);
  EXPECT_EQ(o.load_map, "saved/");
  EXPECT_TRUE(o.has_initial_pose);
  EXPECT_DOUBLE_EQ(o.initial_pose.x, 1.5);
  EXPECT_DOUBLE_EQ(o.initial_pose.y, -2.0);
  EXPECT_DOUBLE_EQ(o.initial_pose.theta, 0.25);
}

TEST(OfflineArgs, LocalizeOnlyOptions) {
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m",
                     "--initial-pose", "1,2,0.5", "--initial-cov=0.5,0.25,0.1", "--param",
                     "max_particles=800"},
                    &o, &error))
      << error;
  EXPECT_TRUE(o.localize_only);
  EXPECT_FALSE(o.global_localization);
  EXPECT_TRUE(o.has_initial_covariance);
  EXPECT_DOUBLE_EQ(o.initial_covariance[0], 0.5);
  EXPECT_DOUBLE_EQ(o.initial_covariance[1], 0.25);
  EXPECT_DOUBLE_EQ(o.initial_covariance[2], 0.1);
  EXPECT_EQ(o.params.localization.max_particles, 800);
  EXPECT_FALSE(o.all_layers);
  OfflineOptions a;
  ASSERT_TRUE(
      parse({"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m", "--all-layers"},
            &a, &error))
      << error;
  EXPECT_TRUE(a.all_layers);
  OfflineOptions g;
  ASSERT_TRUE(parse({"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m",
                     "--global"},
                    &g, &error))
      << error;
  EXPECT_TRUE(g.global_localization);
  EXPECT_FALSE(g.has_initial_pose);
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(OfflineArgs, DefaultsAreTheCoreDefaults) {
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--rawlog", "a", "--out", "b"}, &o, &error)) << error;
  const SlamConfig defaults;
  EXPECT_EQ(o.params.slam.particles, defaults.particles);
  EXPECT_EQ(o.params.slam.resolution, defaults.resolution);
  EXPECT_EQ(o.params.slam.matcher.heading_window, defaults.matcher.heading_window);
  EXPECT_EQ(o.max_scans, 0u);
  EXPECT_TRUE(o.params.isValid(&error)) << error;
  EXPECT_FALSE(o.params.session.export_octomap);
  EXPECT_TRUE(o.config_files.empty());
}

// A file written for this test (TempFile removes it).
struct TempFile {
  explicit TempFile(const std::string& text) {
    char name[] = "/tmp/es_params_XXXXXX";
    const int fd = mkstemp(name);
    path = name;
    std::FILE* f = fdopen(fd, "w");
    std::fputs(text.c_str(), f);
    std::fclose(f);
  }
  ~TempFile() { std::remove(path.c_str()); }
  std::string path;
};

// --config files apply in order (later wins), --param and the shorthand options after them in
// command-line order, whatever their place on the command line; --preset NAME is config/NAME.yaml.
TEST(OfflineArgs, ConfigFilesThenParametersInOrder) {
  const TempFile first("particles: 30\nresample_threshold: 0.3\nalong_track_prior: no\n");
  const TempFile second("resample_threshold: 0.35\nmap_frame: world  # the node's only\n");
  OfflineOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--param", "matcher_heading_window=0.2", "--config", first.path, "--rawlog",
                     "a", "--out", "b", "--config", second.path, "--particles", "12",
                     "--param=likelihood_temperature=25", "--param", "likelihood_temperature=30"},
                    &o, &error))
      << error;
  EXPECT_EQ(o.config_files, (std::vector<std::string>{first.path, second.path}));
  EXPECT_EQ(o.params.slam.particles, 12);                  // --particles over the file
  EXPECT_DOUBLE_EQ(o.params.slam.resample_threshold, 0.35);  // the later file
  EXPECT_FALSE(o.params.slam.along_track_prior);           // YAML 1.1's `no`
  EXPECT_DOUBLE_EQ(o.params.slam.matcher.heading_window, 0.2);
  EXPECT_DOUBLE_EQ(o.params.slam.likelihood_temperature, 30.0);
  EXPECT_EQ(o.ignored, (std::vector<std::string>{"map_frame"}));
  ASSERT_EQ(o.parameters.size(), 4u);
  EXPECT_EQ(o.parameters[1].first, "particles");
  EXPECT_EQ(o.parameters[2].second, "25");

  OfflineOptions sim;
  ASSERT_TRUE(parse({"--preset", "sim", "--rawlog", "a", "--out", "b"}, &sim, &error)) << error;
  EXPECT_EQ(sim.config_files, (std::vector<std::string>{presetFile("sim")}));
  EXPECT_EQ(sim.params.slam.matcher.heading_window, 0.0);
  EXPECT_FALSE(sim.params.slam.sensor.forward_conflict_as_unknown);
}

// A bad parameter file: a one-line error naming the file (and the parameter).
TEST(OfflineArgs, BadConfigFiles) {
  const TempFile unknown("particles: 30\nparticels: 40\n");
  const TempFile range("usable_range: 1e9\n");
  const TempFile nested("filter:\n  particles: 30\n");
  const TempFile not_yaml("particles: [30\n");
  const TempFile list("- particles\n");
  for (const std::string& path : {unknown.path, range.path, nested.path, not_yaml.path,
                                  list.path, std::string("/nonexistent/config.yaml")}) {
    OfflineOptions o;
    std::string error;
    EXPECT_FALSE(parse({"--rawlog", "a", "--out", "b", "--config", path}, &o, &error)) << path;
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
  OfflineOptions o;
  std::string error;
  EXPECT_FALSE(parse({"--rawlog", "a", "--out", "b", "--config", unknown.path}, &o, &error));
  EXPECT_NE(error.find("particels"), std::string::npos) << error;
}

// What YAML readers accept silently and a user did not mean: a key given twice (the last won), a
// second document (ignored) and a quoted number (text, which ROS would not read as a number). Each
// is one line naming the file; a quoted string parameter stays fine.
TEST(OfflineArgs, AmbiguousConfigFilesAreRefused) {
  const TempFile twice("particles: 30\nparticles: 40\n");
  const TempFile documents("particles: 30\n---\nparticles: 40\n");
  const TempFile quoted("particles: \"5\"\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {twice.path, "duplicate key 'particles'"},
      {documents.path, "2 YAML documents"},
      {quoted.path, "'particles': '5' is quoted text"}};
  for (const auto& [path, what] : cases) {
    OfflineOptions o;
    std::string error;
    EXPECT_FALSE(parse({"--rawlog", "a", "--out", "b", "--config", path}, &o, &error)) << path;
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find(what), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
  const TempFile text("map_frame: \"5\"\nparticles: 5\n");
  OfflineOptions o;
  std::string error;
  EXPECT_TRUE(parse({"--rawlog", "a", "--out", "b", "--config", text.path}, &o, &error)) << error;
  EXPECT_EQ(o.params.slam.particles, 5);
}

// Names and values are the file's bytes: the error shows them as printable text, on one line.
TEST(OfflineArgs, ConfigFileErrorsArePrintable) {
  const TempFile unknown("par\x1b[2J\xffticles: 3\n");
  const TempFile not_single("\x07" "bell: [1, 2]\n");
  const TempFile bad_value("particles: \"3\\r\\n0\\x01\"\n");
  for (const std::string& path : {unknown.path, not_single.path, bad_value.path}) {
    OfflineOptions o;
    std::string error;
    EXPECT_FALSE(parse({"--rawlog", "a", "--out", "b", "--config", path}, &o, &error)) << path;
    EXPECT_NE(error.find(path), std::string::npos) << error;
    for (unsigned char c : error) {
      EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "byte " << int(c) << " in: " << error;
    }
  }
}

// Every file in config/ that holds parameters reads, sets only known parameters and validates.
TEST(OfflineArgs, EveryShippedConfigFileLoads) {
  const std::string dir = std::string(ES_TEST_DATA_DIR) + "/../../config";
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    OfflineOptions o;
    std::string error;
    EXPECT_TRUE(parse({"--rawlog", "a", "--out", "b", "--config", entry.path().string()}, &o,
                      &error))
        << error;
    EXPECT_TRUE(o.params.isValid(&error)) << entry.path() << ": " << error;
    std::vector<std::pair<std::string, std::string>> entries;
    ASSERT_TRUE(readParameterFile(entry.path().string(), &entries, &error)) << error;
    EXPECT_FALSE(entries.empty()) << entry.path();
  }
  EXPECT_GE(files, 1);
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
      {"--rawlog", "a", "--out", "b", "--preset", "fast"},  // no config/fast.yaml
      {"--rawlog", "a", "--out", "b", "--preset", "../sim"},
      {"--rawlog", "a", "--out"},
      {"--rawlog", "a", "--out", "b", "--quiet=1"},
      {"--rawlog", "a", "--out", "b", "--export-octomap=yes"},
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
      {"--rawlog", "a", "--out", "b", "--param", "map_frame=world"},  // the node's only
      {"--rawlog", "a", "--out", "b", "--param", "free_thresh=0.9"},  // above occupied_thresh
      {"--rawlog", "a", "--out", "b", "--param"},
      {"--rawlog", "a", "--out", "b", "--first-scan", "-1"},
      {"--rawlog", "a", "--out", "b", "--first-scan", "x"},
      {"--rawlog", "a", "--out", "b", "--load-map", ""},
      {"--rawlog", "a", "--out", "b", "--initial-pose", "1,2"},
      {"--rawlog", "a", "--out", "b", "--initial-pose", "1,2,3,4"},
      {"--rawlog", "a", "--out", "b", "--initial-pose", "1,nan,0"},
      {"--rawlog", "a", "--out", "b", "--initial-pose", "1, 2, 0"},
      {"--rawlog", "a", "--out", "b", "--localize-only"},  // no --load-map
      {"--rawlog", "a", "--out", "b", "--localize-only=1", "--load-map", "m"},
      {"--rawlog", "a", "--out", "b", "--load-map", "m", "--global"},  // not --localize-only
      {"--rawlog", "a", "--out", "b", "--load-map", "m", "--initial-cov", "1,1,1"},
      {"--rawlog", "a", "--out", "b", "--load-map", "m", "--all-layers"},  // not --localize-only
      {"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m", "--global",
       "--initial-pose", "1,2,0"},
      {"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m", "--initial-cov", "1,1"},
      {"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m", "--initial-cov",
       "1,-1,1"},
      {"--rawlog", "a", "--out", "b", "--localize-only", "--load-map", "m", "--param",
       "max_particles=50"},  // below min_particles
  };
  for (const auto& args : bad) {
    OfflineOptions o;
    std::string error;
    EXPECT_FALSE(parse(args, &o, &error)) << ::testing::PrintToString(args);
    EXPECT_FALSE(error.empty());
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

// An unknown option and bad values: one line naming the option.
TEST(OfflineArgs, UnknownOptionAndBadValueNameTheOption) {
  const std::vector<std::string> base = {"--rawlog", "a", "--out", "b"};
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--bogus"}, "unknown option '--bogus'"},
      {{"--bogus=3"}, "unknown option '--bogus=3'"},
      {{"--max-scans", "0"}, "--max-scans wants an integer >= 1"},
      {{"--first-scan", "x"}, "--first-scan wants an integer >= 0"},
      {{"--initial-pose", "1,2"}, "--initial-pose wants X,Y,YAW (three finite numbers: m, m, rad)"},
      {{"--preset", "../sim"}, "--preset wants the name of a file in config/ (e.g. sim)"},
      {{"--quiet=1"}, "--quiet takes no value"},
      {{"--param", "=0.3"}, "--param wants NAME=VALUE"},
      {{"--seed"}, "--seed needs a value"},
  };
  for (const auto& [extra, message] : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    OfflineOptions o;
    std::string error;
    EXPECT_FALSE(parse(args, &o, &error)) << ::testing::PrintToString(args);
    EXPECT_EQ(error, message);
  }
  OfflineOptions o;
  std::string error;
  EXPECT_FALSE(parse({"--out", "b"}, &o, &error));
  EXPECT_EQ(error, "--rawlog is required");
}

// --help lists every parameter --param and --config take, once.
TEST(OfflineArgs, HelpListsEveryParameter) {
  const std::string usage = offlineUsage("prog");
  for (const auto& [name, value] : parameterValues(Parameters())) {
    const size_t at = usage.find("\n  " + name + " = ");
    EXPECT_NE(at, std::string::npos) << name;
    EXPECT_EQ(usage.find("\n  " + name + " = ", at + 1), std::string::npos) << name;
  }
}

// The README's option table lists every option of the usage text.
TEST(OfflineArgs, ReadmeListsEveryOption) {
  std::ifstream in(std::string(ES_TEST_DATA_DIR) + "/../../README.md");
  ASSERT_TRUE(in.good());
  const std::string readme((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string usage = offlineUsage("prog");
  int options = 0;
  for (size_t p = usage.find("\n  --"); p != std::string::npos; p = usage.find("\n  --", p + 1)) {
    const size_t end = usage.find_first_of(" \n", p + 3);
    const std::string option = usage.substr(p + 3, end - p - 3);
    ++options;
    EXPECT_NE(readme.find("`" + option + "`"), std::string::npos) << option;
  }
  EXPECT_GE(options, 14);
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

}  // namespace
}  // namespace io
}  // namespace evidential_slam
