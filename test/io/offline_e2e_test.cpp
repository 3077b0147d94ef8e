// End to end: runs the built evidential_slam_offline binary on the committed simul-gridmap fixture
// (both rawlog formats) and on broken variants made here, then checks exit codes, messages,
// outputs and the value ranges of every layer.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include <mrpt/io/CFileGZInputStream.h>
#include <nlohmann/json.hpp>

#include "evidential_slam/core/measures.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/io/npy.h"
#include "evidential_slam/io/trajectory_io.h"
#include "rawlog_fixtures.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;
using test::dataPath;

constexpr int kFixtureScans = 159;
// Few particles keep the suite fast; the fixture's odometry drifts ~0.7 m RMSE, SLAM gets ~0.02 m.
// The fixtures are simulated: config/sim.yaml.
const std::vector<std::string> kFast = {"--preset", "sim", "--particles", "20",
                                        "--seed",   "3",   "--threads",   "2"};

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// `prefix` goes before the command (a shell command ending in `exec` or a launcher such as
// prlimit).
Result runOffline(const std::vector<std::string>& args, const fs::path& scratch,
                  const std::string& prefix = "") {
  std::string cmd = prefix + quote(ES_OFFLINE_BIN);
  for (const auto& a : args) cmd += " " + quote(a);
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  cmd += " > " + quote(out.string()) + " 2> " + quote(err.string()) + " < /dev/null";
  const int status = std::system(cmd.c_str());
  Result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = test::readText(out);
  r.err = test::readText(err);
  return r;
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

int lineCount(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

nlohmann::json summaryOf(const fs::path& out_dir) {
  return nlohmann::json::parse(test::readText(out_dir / "summary.json"));
}

// Every output file (the set ~save_map writes too: session/map_files.h), the trajectory and the
// value ranges of the layers.
void checkOutputs(const fs::path& out, int scans) {
  const fs::path layers = out / "layers";
  for (const std::string& name : layerNames()) {
    for (const char* ext : {".png", ".npy", ".pgm", ".yaml"}) {
      EXPECT_TRUE(fs::is_regular_file(layers / (name + ext))) << name << ext;
    }
  }
  EXPECT_TRUE(fs::is_regular_file(out / "conflict.csv"));
  EXPECT_TRUE(fs::is_regular_file(out / "map.evmap"));
  EXPECT_TRUE(fs::is_regular_file(out / "trajectory.png"));
  EXPECT_TRUE(fs::is_regular_file(layers / "composite.png"));
  EXPECT_TRUE(fs::is_regular_file(layers / "observed.npy"));
  EXPECT_TRUE(fs::is_regular_file(layers / "map.yaml"));

  std::vector<StampedPose> path;
  std::string error;
  ASSERT_TRUE(io::readTumTrajectory((out / "trajectory.tum").string(), &path, &error)) << error;
  EXPECT_EQ(static_cast<int>(path.size()), scans);

  std::map<std::string, std::vector<float>> v;
  size_t cells = 0;
  for (const std::string& name : layerNames()) {
    io::NpyArray a;
    ASSERT_TRUE(io::readNpy((layers / (name + ".npy")).string(), &a, &error)) << error;
    ASSERT_EQ(a.shape.size(), 2u);
    v[name] = a.asFloat32();
    ASSERT_EQ(v[name].size(), a.shape[0] * a.shape[1]) << name;
    cells = v[name].size();
  }
  ASSERT_GT(cells, 0u);
  // Masses and BetP in [0, 1] up to float rounding (m(Θ) = 1 - m(o) - m(e) can come out -1e-8).
  constexpr float kTol = 1e-6f;
  size_t bad_sum = 0, out_of_range = 0, negative_ec = 0, not_finite = 0, bits_out_of_range = 0;
  for (size_t i = 0; i < cells; ++i) {
    const float o = v["occupied"][i], e = v["free"][i], u = v["unknown"][i], c = v["conflict"][i];
    for (float m : {o, e, u, c, v["pignistic"][i], v["nonspecificity"][i]}) {
      if (!(m >= -kTol && m <= 1.0f + kTol)) ++out_of_range;
    }
    if (std::abs(o + e + u + c - 1.0f) > 1e-4f) ++bad_sum;
    if (!(v["external_conflict"][i] >= 0.0f)) ++negative_ec;
    for (const std::string& name : layerNames()) not_finite += !std::isfinite(v[name][i]);
    // IC and H are in bits over a two-element frame: [0, 1].
    for (float b : {v["internal_conflict"][i], v["entropy"][i]}) {
      if (!(b >= -kTol && b <= 1.0f + kTol)) ++bits_out_of_range;
    }
  }
  EXPECT_EQ(out_of_range, 0u);
  EXPECT_EQ(bad_sum, 0u);
  EXPECT_EQ(negative_ec, 0u);
  EXPECT_EQ(not_finite, 0u) << "layer values must be finite";
  EXPECT_EQ(bits_out_of_range, 0u) << "internal conflict / entropy outside [0, 1] bit";
}

class OfflineE2E : public ::testing::Test {
 protected:
  fs::path scratch_ = test::scratchDir();
};

TEST_F(OfflineE2E, ActionsSensoryFrameFixture) {
  const fs::path out = scratch_ / "out";
  const Result r = runOffline(concat({"--rawlog", dataPath("sim.rawlog"), "--out", out.string(),
                                      "--ground-truth", dataPath("sim.GT.txt")},
                                     kFast),
                              scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("error"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("ATE:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("summary.json"), std::string::npos) << r.out;
  checkOutputs(out, kFixtureScans);

  const auto j = summaryOf(out);
  for (const char* key :
       {"rawlog", "scans_total", "scans_processed", "scans_rejected", "rays_total", "rays_bad",
        "rays_no_return", "long_steps", "wall_time_s", "peak_rss_mb", "particles", "resolution",
        "seed", "threads", "truncated", "warnings", "ate_rmse_m", "ate_max_m", "ate_matched"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["scans_total"], kFixtureScans);
  EXPECT_EQ(j["long_steps"], 0);  // off in the default (simulation) configuration
  EXPECT_GT(j["scans_processed"].get<int>(), 20);
  // Every update weighs and updates between 1 group and one per particle (K = 20).
  EXPECT_GE(j["groups_per_update"].get<double>(), 1.0);
  EXPECT_LE(j["groups_per_update"].get<double>(), 20.0);
  EXPECT_EQ(j["scans_rejected"], 0);
  EXPECT_EQ(j["rays_total"], kFixtureScans * 181);
  EXPECT_EQ(j["rays_bad"], 0);
  EXPECT_EQ(j["truncated"], false);
  EXPECT_EQ(j["particles"], 20);
  EXPECT_EQ(j["seed"], 3);
  EXPECT_EQ(j["ate_matched"], kFixtureScans);
  EXPECT_GT(j["peak_rss_mb"].get<double>(), 1.0);
  // conflict.csv: a header, then one row per processed scan; no alarm on a clean simulated log.
  const std::string csv = test::readText(out / "conflict.csv");
  size_t rows = 0;
  for (size_t p = csv.find('\n'); p != std::string::npos; p = csv.find('\n', p + 1)) ++rows;
  EXPECT_NE(csv.find("stamp,ec_added_bits,conflict_mass_added,open_space_conflict_added,baseline,"
                     "ratio,alarm,contradiction_added\n"),
            std::string::npos);
  EXPECT_EQ(rows, 2 + j["scans_processed"].get<size_t>());  // comment, header, rows
  ASSERT_TRUE(j.contains("conflict_alarms"));
  EXPECT_TRUE(j["conflict_alarms"].empty()) << j["conflict_alarms"];
  // SLAM beats the drifting odometry by a wide margin.
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.15);
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.5 * j["odometry_ate_rmse_m"].get<double>());
}

TEST_F(OfflineE2E, ObservationOnlyFixture) {
  const fs::path out = scratch_ / "out";
  const Result r = runOffline(concat({"--rawlog", dataPath("sim_obs.rawlog"), "--out", out.string(),
                                      "--ground-truth", dataPath("sim.GT.txt"), "--quiet"},
                                     kFast),
                              scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // --quiet
  checkOutputs(out, kFixtureScans);
  const auto j = summaryOf(out);
  EXPECT_EQ(j["rawlog_format"], "observations");
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.15);
}

TEST_F(OfflineE2E, MissingFile) {
  const Result r = runOffline(
      {"--rawlog", (scratch_ / "nope.rawlog").string(), "--out", (scratch_ / "out").string()},
      scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scratch_ / "out"));
}

TEST_F(OfflineE2E, NotARawlog) {
  test::writeText(scratch_ / "notes.rawlog", "this is not a rawlog\n");
  const Result r = runOffline(
      {"--rawlog", (scratch_ / "notes.rawlog").string(), "--out", (scratch_ / "out").string()},
      scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not an MRPT rawlog"), std::string::npos) << r.err;
}

// The fixture's decompressed bytes with `patch` applied at the payload of its `nth` scan (0-based;
// `offset` bytes after the scan's version byte).
std::string patchedFixture(int nth, size_t offset, const std::string& patch) {
  mrpt::io::CFileGZInputStream in(dataPath("sim.rawlog"));
  std::string bytes;
  char buf[65536];
  size_t n;
  while ((n = in.Read(buf, sizeof(buf))) > 0 && n <= sizeof(buf)) bytes.append(buf, n);
  const std::string name = "mrpt::obs::CObservation2DRangeScan";
  size_t at = 0;
  for (int i = 0; i <= nth; ++i) at = bytes.find(name, at + 1);
  EXPECT_NE(at, std::string::npos);
  bytes.replace(at + name.size() + 1 + offset, patch.size(), patch);
  return bytes;
}

// A corrupt entry in the middle of the log (here scan 40's beam count: 2^30, which made MRPT
// write through a null pointer) and an impossible value are bad input: exit 2 with one line that
// names the entry, before any SLAM work.
TEST_F(OfflineE2E, CorruptLogIsBadInput) {
  // Aperture (4), direction (1) and maximum range (4), then the CPose3D (header, version 3:
  // twelve doubles, end flag), then the beam count.
  const size_t beam_count = 9 + 1 + 20 + 1 + 96 + 1;
  const std::string huge("\x00\x00\x00\x40", 4);
  const float nan = std::nanf("");
  const std::string nan_bytes(reinterpret_cast<const char*>(&nan), 4);
  struct Case {
    std::string bytes, expect;
  };
  for (const Case& c : {Case{patchedFixture(40, beam_count, huge), "1073741824 beams in a scan"},
                        Case{patchedFixture(40, 0, nan_bytes), "a scan aperture of nan rad"}}) {
    const fs::path log = scratch_ / "corrupt.rawlog", out = scratch_ / "out";
    test::writeText(log, c.bytes);
    const auto t0 = std::chrono::steady_clock::now();
    const Result r =
        runOffline(concat({"--rawlog", log.string(), "--out", out.string()}, kFast), scratch_);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("error: '" + log.string() + "' is corrupt at rawlog entry 82"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_LT(seconds, 10.0);
    EXPECT_FALSE(fs::exists(out / "summary.json"));
  }
}

// Name -> size and hash of every file under `dir`.
std::map<std::string, std::pair<size_t, size_t>> digest(const fs::path& dir) {
  std::map<std::string, std::pair<size_t, size_t>> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string content = test::readText(e.path());
    files[e.path().lexically_relative(dir).string()] = {content.size(),
                                                        std::hash<std::string>()(content)};
  }
  return files;
}

// A run whose outputs cannot be written (a full disk: here no file may grow past 100 kB; an
// unwritable directory) exits 2 with the reason, and leaves the previous run's files as they were
// and no temporary file: every output replaces the old one only once all are written.
TEST_F(OfflineE2E, AFailedSaveKeepsThePreviousRun) {
  const fs::path out = scratch_ / "out";
  const std::vector<std::string> base = {"--rawlog",   dataPath("sim.rawlog"), "--out",
                                         out.string(), "--export-octomap",     "--quiet"};
  Result r = runOffline(concat(concat(base, kFast), {"--max-scans", "40"}), scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto before = digest(out);
  // Top level (with map.evmap and trajectory.png), layers (PNG/NPY, composite, observed,
  // map.yaml; the map_server pairs), OctoMap.
  ASSERT_EQ(before.size(), 5u + (2u * kLayerCount + 3u) + 2u * kLayerCount + 3u);

  // SIGXFSZ ignored: a write past the limit fails with EFBIG instead of killing the run.
  r = runOffline(concat(concat(base, kFast), {"--max-scans", "60"}), scratch_,
                 "trap '' XFSZ; exec prlimit --fsize=100000 -- ");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("error: cannot write '" + out.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("': File too large"), std::string::npos) << r.err;
  EXPECT_EQ(digest(out), before);

  // Unwritable directories (as user nobody when the tests run as root, who may write anyway).
  const auto read_only = fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                         fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec;
  for (const fs::path& d : {out, out / "layers", out / "octomap"}) fs::permissions(d, read_only);
  r = runOffline(concat(concat(base, kFast), {"--max-scans", "60"}), scratch_,
                 geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "");
  for (const fs::path& d : {out, out / "layers", out / "octomap"}) {
    fs::permissions(d, fs::perms::owner_all, fs::perm_options::add);
  }
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("': Permission denied"), std::string::npos) << r.err;
  EXPECT_EQ(digest(out), before);
}

TEST_F(OfflineE2E, TruncatedLogStillWritesOutputs) {
  const fs::path cut = scratch_ / "cut.rawlog";
  std::string error;
  ASSERT_TRUE(test::truncateCopy(dataPath("sim.rawlog"), cut.string(), 0.6, &error)) << error;
  const fs::path out = scratch_ / "out";
  const Result r = runOffline(concat({"--rawlog", cut.string(), "--out", out.string(),
                                      "--ground-truth", dataPath("sim.GT.txt")},
                                     kFast),
                              scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
  const auto j = summaryOf(out);
  EXPECT_EQ(j["truncated"], true);
  const int scans = j["scans_total"].get<int>();
  EXPECT_GT(scans, 20);
  EXPECT_LT(scans, kFixtureScans);
  EXPECT_LT(j["scans_processed"].get<int>(), scans + 1);
  EXPECT_FALSE(j["warnings"].empty());
  checkOutputs(out, scans);
}

TEST_F(OfflineE2E, LogWithoutLaser) {
  const fs::path log = scratch_ / "no_laser.rawlog";
  std::string error;
  ASSERT_TRUE(
      test::makeVariant(dataPath("sim.rawlog"), log.string(), test::Variant::kNoLaser, &error))
      << error;
  const Result r =
      runOffline({"--rawlog", log.string(), "--out", (scratch_ / "out").string()}, scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("error: no 2-D laser scans"), std::string::npos) << r.err;
}

TEST_F(OfflineE2E, LogWithoutOdometry) {
  for (const char* fixture : {"sim.rawlog", "sim_obs.rawlog"}) {
    const fs::path log = scratch_ / "no_odometry.rawlog";
    std::string error;
    ASSERT_TRUE(
        test::makeVariant(dataPath(fixture), log.string(), test::Variant::kNoOdometry, &error))
        << error;
    const Result r =
        runOffline({"--rawlog", log.string(), "--out", (scratch_ / "out").string()}, scratch_);
    EXPECT_EQ(r.exit_code, 2) << fixture;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("error: no odometry"), std::string::npos) << r.err;
  }
}

// Odometry that is there but unusable (NaN) is reported as such, naming the reading, in one line,
// not as missing.
TEST_F(OfflineE2E, LogWithUnusableOdometry) {
  for (const char* fixture : {"sim.rawlog", "sim_obs.rawlog"}) {
    const fs::path log = scratch_ / "nan_odometry.rawlog";
    std::string error;
    ASSERT_TRUE(
        test::makeVariant(dataPath(fixture), log.string(), test::Variant::kNanOdometry, &error))
        << error;
    const Result r =
        runOffline({"--rawlog", log.string(), "--out", (scratch_ / "out").string()}, scratch_);
    EXPECT_EQ(r.exit_code, 2) << fixture;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_EQ(r.err.find("no odometry"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("an odometry"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(nan, 0, 0)"), std::string::npos) << r.err;
  }
}

TEST_F(OfflineE2E, BadRangesAreSkippedAndCounted) {
  const fs::path log = scratch_ / "bad_ranges.rawlog";
  std::string error;
  ASSERT_TRUE(
      test::makeVariant(dataPath("sim.rawlog"), log.string(), test::Variant::kBadRanges, &error))
      << error;
  const fs::path out = scratch_ / "out";
  const Result r = runOffline(concat({"--rawlog", log.string(), "--out", out.string(),
                                      "--ground-truth", dataPath("sim.GT.txt")},
                                     kFast),
                              scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = summaryOf(out);
  EXPECT_EQ(j["rays_bad"], 3 * kFixtureScans);  // NaN, +inf and -1 in every scan
  EXPECT_EQ(j["scans_rejected"], 0);
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.15);
  EXPECT_NE(r.err.find("NaN, infinite or negative"), std::string::npos) << r.err;
  checkOutputs(out, kFixtureScans);
}

// A start pose beyond max_map_extent is refused where it enters, with one line and exit 2 (once an
// uncaught std::length_error from the scan matcher: exit 3 "unexpected failure").
TEST_F(OfflineE2E, AStartPoseBeyondTheMapExtentIsOneLine) {
  const fs::path out = scratch_ / "out";
  for (const char* pose : {"1e9,0,0", "0,1e12,0", "1001,0,0"}) {
    const Result r = runOffline(
        concat({"--rawlog", dataPath("sim.rawlog"), "--out", out.string(), "--initial-pose", pose},
               kFast),
        scratch_);
    EXPECT_EQ(r.exit_code, 2) << pose << ": " << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("max_map_extent (1000 m)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// A log whose every range is unusable makes no map: one line (no MRPT exception with its call
// stack from writing an empty image) and no output folder left behind, neither a new --out
// directory nor a layers/ in an existing one.
TEST_F(OfflineE2E, NoUsableRangeIsOneLineAndLeavesNoFolder) {
  const fs::path log = scratch_ / "all_unusable.rawlog";
  std::string error;
  ASSERT_TRUE(test::makeVariant(dataPath("sim_obs.rawlog"), log.string(),
                                test::Variant::kAllUnusable, &error))
      << error;
  const fs::path out = scratch_ / "out";
  Result r = runOffline(concat({"--rawlog", log.string(), "--out", out.string()}, kFast), scratch_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const size_t at = r.err.find("error: ");
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err.substr(at)), 1) << r.err;
  EXPECT_NE(r.err.find("had a usable range"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "a failed run left " << out;

  const fs::path existing = scratch_ / "existing";
  fs::create_directories(existing);
  test::writeText(existing / "keep.txt", "mine");
  r = runOffline(concat({"--rawlog", log.string(), "--out", existing.string()}, kFast), scratch_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(fs::exists(existing / "keep.txt"));
  EXPECT_FALSE(fs::exists(existing / "layers"));
  EXPECT_FALSE(fs::exists(existing / "map.evmap"));
}

TEST_F(OfflineE2E, RejectedScansAreCountedAndWarnedAboutSparingly) {
  const fs::path log = scratch_ / "unusable.rawlog";
  std::string error;
  ASSERT_TRUE(test::makeVariant(dataPath("sim_obs.rawlog"), log.string(),
                                test::Variant::kUnusableScans, &error))
      << error;
  const fs::path out = scratch_ / "out";
  const Result r = runOffline(concat({"--rawlog", log.string(), "--out", out.string(),
                                      "--ground-truth", dataPath("sim.GT.txt")},
                                     kFast),
                              scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = summaryOf(out);
  const int rejected = kFixtureScans / 10;
  EXPECT_EQ(j["scans_rejected"], rejected);
  EXPECT_EQ(j["rays_bad"], rejected * 181);
  // Three rejections are reported one by one, then a single note; the total comes at the end.
  size_t shown = 0;
  for (size_t at = r.err.find("rejected:"); at != std::string::npos;
       at = r.err.find("rejected:", at + 1)) {
    ++shown;
  }
  EXPECT_EQ(shown, 3u) << r.err;
  EXPECT_NE(r.err.find("further rejected scans are only counted"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::to_string(rejected) + " of 159 scans were rejected"), std::string::npos)
      << r.err;
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.15);
  checkOutputs(out, kFixtureScans);
}

TEST_F(OfflineE2E, BadUsageAndUnwritableOutput) {
  Result r = runOffline({}, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  r = runOffline({"--rawlog", dataPath("sim.rawlog"), "--out", "x", "--particles", "0"}, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  r = runOffline({"--help"}, scratch_);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("usage:"), std::string::npos);
  // The output directory is a file.
  test::writeText(scratch_ / "file", "x");
  r = runOffline({"--rawlog", dataPath("sim.rawlog"), "--out", (scratch_ / "file").string()},
                 scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("cannot create output directory"), std::string::npos) << r.err;
  // A malformed ground truth is reported before any work.
  test::writeText(scratch_ / "gt.txt", "1 2 3\n");
  r = runOffline({"--rawlog", dataPath("sim.rawlog"), "--out", (scratch_ / "o").string(),
                  "--ground-truth", (scratch_ / "gt.txt").string()},
                 scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("gt.txt:1:"), std::string::npos) << r.err;
}

TEST_F(OfflineE2E, MaxScans) {
  const fs::path out = scratch_ / "out";
  const Result r = runOffline(
      concat({"--rawlog", dataPath("sim.rawlog"), "--out", out.string(), "--max-scans", "40"},
             kFast),
      scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(summaryOf(out)["scans_total"], 40);
  // Not a TTY: progress comes as whole lines, about one per 10 %.
  EXPECT_EQ(r.err.find('\r'), std::string::npos);
  EXPECT_GE(lineCount(r.err), 5);
  checkOutputs(out, 40);
}

double ateOf(const std::vector<StampedPose>& path) {
  std::vector<StampedPose> truth;
  std::string error;
  EXPECT_TRUE(io::readGroundTruth(dataPath("sim.GT.txt"), &truth, &error)) << error;
  AteResult ate;
  EXPECT_TRUE(computeAte(path, truth, 0.05, &ate, &error)) << error;
  EXPECT_EQ(ate.matched, path.size());
  return ate.rmse;
}

std::vector<StampedPose> trajectoryOf(const fs::path& out) {
  std::vector<StampedPose> path;
  std::string error;
  EXPECT_TRUE(io::readTumTrajectory((out / "trajectory.tum").string(), &path, &error)) << error;
  return path;
}

// The fixture in two slices: scans 0-79 saved with --out, then --first-scan 80 --load-map on that
// directory (the same log: the saved odometry pose places scan 80). The map file lists the run's
// parameters and where it came from; the second run starts on its tiles.
TEST_F(OfflineE2E, ContinuesMappingOnASavedMap) {
  const fs::path first = scratch_ / "first", second = scratch_ / "second";
  Result r = runOffline(
      concat({"--rawlog", dataPath("sim.rawlog"), "--out", first.string(), "--max-scans", "80"},
             kFast),
      scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("map.evmap"), std::string::npos) << r.out;
  auto j = summaryOf(first);
  EXPECT_EQ(j["map_file"]["path"], "map.evmap");
  EXPECT_GT(j["map_file"]["tiles"].get<int>(), 10);
  bool listed = false;
  for (const auto& f : j["outputs"]) listed |= f == "map.evmap";
  EXPECT_TRUE(listed);
  EvidentialGridMap saved;
  io::MapFileInfo info;
  std::string error;
  ASSERT_TRUE(io::readMapFile((first / "map.evmap").string(), &saved, &info, &error)) << error;
  EXPECT_EQ(info.parameters.at("particles"), "20");
  EXPECT_EQ(info.parameters.at("seed"), "3");
  EXPECT_EQ(info.parameters.count("likelihood_temperature"), 1u);
  EXPECT_EQ(info.metadata.at("next_scan"), "80");
  EXPECT_EQ(info.metadata.at("source"), fs::weakly_canonical(dataPath("sim.rawlog")).string());
  EXPECT_TRUE(info.has_odometry_pose);
  const std::vector<StampedPose> first_path = trajectoryOf(first);
  ASSERT_EQ(first_path.size(), 80u);
  EXPECT_NEAR(info.robot_pose.x, first_path.back().pose.x, 1e-6);  // trajectory.tum has 6 decimals
  EXPECT_NEAR(info.robot_pose.y, first_path.back().pose.y, 1e-6);

  r = runOffline(concat({"--rawlog", dataPath("sim.rawlog"), "--out", second.string(),
                         "--first-scan", "80", "--load-map", first.string()},
                        kFast),
                 scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = summaryOf(second);
  EXPECT_EQ(j["first_scan"], 80);
  EXPECT_EQ(j["scans_total"], kFixtureScans - 80);
  EXPECT_EQ(j["start"]["map_file"], (first / "map.evmap").string());
  EXPECT_EQ(j["start"]["pose_from"], "map file");
  EXPECT_EQ(j["start"]["odometry_anchored"], true);
  EXPECT_EQ(j["start"]["map_tiles"].get<size_t>(), saved.allocatedTiles());
  checkOutputs(second, kFixtureScans - 80);
  std::vector<StampedPose> halves = first_path;
  for (const StampedPose& p : trajectoryOf(second)) halves.push_back(p);
  EXPECT_LT(ateOf(halves), 0.15);

  // The whole log again on that map, from its first scan at the map frame's origin: no saved
  // odometry pose then.
  const fs::path again = scratch_ / "again";
  r = runOffline(concat({"--rawlog", dataPath("sim.rawlog"), "--out", again.string(), "--load-map",
                         (first / "map.evmap").string(), "--initial-pose", "0,0,0"},
                        kFast),
                 scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = summaryOf(again);
  EXPECT_EQ(j["start"]["pose_from"], "--initial-pose");
  EXPECT_EQ(j["start"]["odometry_anchored"], false);
  EXPECT_LT(ateOf(trajectoryOf(again)), 0.15);
}

// A missing or damaged map, a first scan beyond the log: exit 2 with one line naming the problem.
TEST_F(OfflineE2E, BadMapsAndSlices) {
  const std::vector<std::string> base = {"--rawlog", dataPath("sim.rawlog"), "--out",
                                         (scratch_ / "o").string()};
  Result r = runOffline(concat(base, {"--load-map", (scratch_ / "nowhere").string()}), scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
  test::writeText(scratch_ / "map.evmap", "not a map");
  r = runOffline(concat(base, {"--load-map", scratch_.string()}), scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("map.evmap"), std::string::npos) << r.err;
  r = runOffline(concat(base, {"--first-scan", "159"}), scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("159 usable scans"), std::string::npos) << r.err;
}

// The position error of `path` against `reference` at the same stamps: RMSE and worst, m.
std::pair<double, double> positionError(const std::vector<StampedPose>& path,
                                        const std::vector<StampedPose>& reference) {
  EXPECT_EQ(path.size(), reference.size());
  double sum = 0.0, worst = 0.0;
  const size_t n = std::min(path.size(), reference.size());
  for (size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(path[i].stamp, reference[i].stamp, 1e-6);
    const double d =
        std::hypot(path[i].pose.x - reference[i].pose.x, path[i].pose.y - reference[i].pose.y);
    sum += d * d;
    worst = std::max(worst, d);
  }
  return {n > 0 ? std::sqrt(sum / n) : 0.0, worst};
}

// The names of the files in `dir`, sorted.
std::vector<std::string> fileNames(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// --localize-only: the fixture mapped, then its observation-only twin localized on that map from
// the map frame's origin: the pose follows the SLAM's path, every output is written (layers/: the
// anomaly layer only; with --all-layers every layer, the same anomaly files among them), the map
// file is the stored map unchanged, and localization.csv holds one row per update.
TEST_F(OfflineE2E, LocalizesOnAMapOfTheFixture) {
  const fs::path map = scratch_ / "map", out = scratch_ / "loc", all = scratch_ / "loc_all";
  Result r = runOffline(concat({"--rawlog", dataPath("sim.rawlog"), "--out", map.string()}, kFast),
                        scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> localize = {"--rawlog",
                                             dataPath("sim_obs.rawlog"),
                                             "--preset",
                                             "sim",
                                             "--threads",
                                             "2",
                                             "--localize-only",
                                             "--load-map",
                                             map.string(),
                                             "--initial-cov",
                                             "0.01,0.01,0.003",
                                             "--ground-truth",
                                             dataPath("sim.GT.txt")};
  r = runOffline(concat(localize, {"--out", out.string()}), scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("localized:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the anomaly layer"), std::string::npos) << r.out;
  const std::vector<std::string> anomaly_only = {"anomaly.npy", "anomaly.pgm", "anomaly.png",
                                                 "anomaly.yaml"};
  EXPECT_EQ(fileNames(out / "layers"), anomaly_only);
  EXPECT_TRUE(fs::is_regular_file(out / "trajectory.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "map.evmap"));
  EXPECT_TRUE(fs::is_regular_file(out / "trajectory.tum"));
  r = runOffline(concat(localize, {"--out", all.string(), "--all-layers"}), scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  checkOutputs(all, kFixtureScans);
  for (const std::string& name : anomaly_only) {
    EXPECT_EQ(test::readText(out / "layers" / name), test::readText(all / "layers" / name)) << name;
  }
  EXPECT_EQ(test::readText(out / "trajectory.tum"), test::readText(all / "trajectory.tum"));

  const auto [rmse, worst] = positionError(trajectoryOf(out), trajectoryOf(map));
  EXPECT_LT(rmse, 0.05);   // measured 0.033 m
  EXPECT_LT(worst, 0.12);  // measured 0.081 m
  const auto j = summaryOf(out);
  EXPECT_EQ(j["mode"], "localization");
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.1);  // measured 0.021 m
  EXPECT_EQ(j["start"]["pose_from"], "default (0, 0, 0)");
  const auto& loc = j["localization"];
  const uint64_t updates = loc["updates"].get<uint64_t>();
  EXPECT_GT(updates, 20u);
  EXPECT_EQ(j["scans_processed"].get<uint64_t>(), updates);
  EXPECT_GE(loc["particles_min"].get<int>(), 100);   // min_particles
  EXPECT_LE(loc["particles_max"].get<int>(), 5000);  // max_particles
  EXPECT_LE(loc["particles_min"].get<double>(), loc["particles_mean"].get<double>());
  EXPECT_LE(loc["particles_mean"].get<double>(), loc["particles_max"].get<double>());
  EXPECT_GT(loc["real_time_factor"].get<double>(), 0.0);
  EXPECT_GT(loc["cpu_time_s"].get<double>(), 0.0);
  EXPECT_GT(loc["log_duration_s"].get<double>(), 10.0);
  ASSERT_TRUE(loc.contains("proposal_matches"));
  EXPECT_LE(loc["proposal_matches"].get<uint64_t>(), updates);

  const std::string csv = test::readText(out / "localization.csv");
  EXPECT_EQ(lineCount(csv), static_cast<int>(updates) + 2);  // a comment and the header
  EXPECT_NE(csv.find("stamp,x,y,theta,cov_xx,"), std::string::npos);

  EvidentialGridMap stored, written;
  io::MapFileInfo info;
  std::string error;
  ASSERT_TRUE(io::readMapFile((map / "map.evmap").string(), &stored, &info, &error)) << error;
  ASSERT_TRUE(io::readMapFile((out / "map.evmap").string(), &written, &info, &error)) << error;
  EXPECT_EQ(info.metadata.at("mode"), "localization");
  EXPECT_EQ(written.allocatedTiles(), stored.allocatedTiles());
  const CellBox box = stored.observedBox();
  size_t differ = 0;
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& a = stored.cell(x, y);
      const Cell& b = written.cell(x, y);
      differ += a.occupiedSteps() != b.occupiedSteps() || a.freeSteps() != b.freeSteps() ||
                a.lambdaBits() != b.lambdaBits();
    }
  }
  EXPECT_EQ(differ, 0u) << "localization must not change the map";
}

// --global: the particles start spread over the map's free space (max_particles of them).
TEST_F(OfflineE2E, GlobalLocalizationStartsSpread) {
  const fs::path out = scratch_ / "global";
  const Result r = runOffline(
      {"--rawlog", dataPath("sim_obs.rawlog"), "--out", out.string(), "--preset", "sim",
       "--threads", "2", "--localize-only", "--load-map", dataPath("sim_first_half.evmap"),
       "--global", "--param", "max_particles=300", "--max-scans", "10"},
      scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = summaryOf(out);
  EXPECT_EQ(j["start"]["pose_from"], "--global");
  EXPECT_EQ(j["localization"]["global"], true);
  EXPECT_EQ(j["localization"]["particles_max"], 300);
}

// --localize-only without a map, with an unreadable map, with a bad option: one line each.
TEST_F(OfflineE2E, LocalizeOnlyBadInput) {
  const std::vector<std::string> base = {"--rawlog", dataPath("sim.rawlog"), "--out",
                                         (scratch_ / "o").string(), "--localize-only"};
  Result r = runOffline(base, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--localize-only needs --load-map"), std::string::npos) << r.err;
  test::writeText(scratch_ / "bad.evmap", "not a map");
  r = runOffline(concat(base, {"--load-map", (scratch_ / "bad.evmap").string()}), scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("bad.evmap"), std::string::npos) << r.err;
  r = runOffline(
      concat(base, {"--load-map", dataPath("sim_first_half.evmap"), "--initial-cov", "1,1"}),
      scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--initial-cov"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scratch_ / "o" / "summary.json"));
}

// --profile writes profile.txt with the update's sections, the ns per visited cell and the compute
// floor, and leaves the results as they are without it (the same trajectory, byte for byte).
TEST_F(OfflineE2E, ProfileReportsSectionsAndLeavesResultsAlone) {
  const fs::path plain = scratch_ / "plain", profiled = scratch_ / "profiled";
  const std::vector<std::string> args = {"--rawlog", dataPath("sim.rawlog"), "--max-scans", "40"};
  Result r = runOffline(concat(concat(args, {"--out", plain.string()}), kFast), scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = runOffline(concat(concat(args, {"--out", profiled.string(), "--profile"}), kFast), scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string report = test::readText(profiled / "profile.txt");
  for (const char* line : {"traversal: forward model + evidence", "applying the scan to the map",
                           "hill climb (scan matcher score)", "ns per visited cell",
                           "floor:", "visited_cells", "process CPU"}) {
    EXPECT_NE(report.find(line), std::string::npos) << line << "\n" << report;
  }
  EXPECT_NE(r.out.find("ns per visited cell"), std::string::npos) << r.out;
  EXPECT_EQ(test::readText(plain / "trajectory.tum"), test::readText(profiled / "trajectory.tum"));
  EXPECT_FALSE(fs::exists(plain / "profile.txt"));
}

// Regression on a real robot: Radish's ACES log (440 scans, 22 minutes) with its raw wheel odometry
// (benchmark data outside the package: shared/ beside the clone, or $ES_RADISH_DIR), mapped with
// the defaults (which are for real robots) at issue 6's K = 100 (about 40 s on 2 cores). Odometry
// alone is off by 5.4 m RMSE; SLAM must stay within issue 6's target, 0.5 m (seeds 1-10 gave
// 0.11-0.22 m; seed 1, run here, 0.148 m: docs/benchmarks.md#real-robot-logs). At K = 30 an earlier
// preset ran it in 10 s but was not robust there: seeds 1-3 gave 0.19, 0.45, 0.63 m. Skipped,
// saying why, where the logs are absent.
TEST_F(OfflineE2E, RealRobotLogWithRawOdometry) {
  const char* env_dir = std::getenv("ES_RADISH_DIR");
  const fs::path dir = env_dir != nullptr ? env_dir : ES_RADISH_DIR;
  const fs::path log = dir / "aces.rawlog", truth = dir / "aces.GT.txt";
  if (!fs::exists(log) || !fs::exists(truth)) GTEST_SKIP() << "no Radish logs in " << dir;
  const fs::path out = scratch_ / "out";
  const Result r =
      runOffline({"--rawlog", log.string(), "--out", out.string(), "--ground-truth", truth.string(),
                  "--particles", "100", "--seed", "1", "--threads", "2"},
                 scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = summaryOf(out);
  EXPECT_EQ(j["scans_total"], 440);
  EXPECT_GT(j["scans_processed"].get<int>(), 400);
  EXPECT_GT(j["odometry_ate_rmse_m"].get<double>(), 5.0);
  EXPECT_LT(j["ate_rmse_m"].get<double>(), 0.5);
  // The defaults match every beam after long steps, which are nearly all of ACES' (scans ~1 m
  // apart): 429 of 437 processed with seed 1. The first processed scan starts the filter, no step.
  const int processed = j["scans_processed"].get<int>();
  EXPECT_GT(j["long_steps"].get<int>(), processed * 9 / 10);
  EXPECT_LT(j["long_steps"].get<int>(), processed);
}

}  // namespace
}  // namespace evidential_slam
