// Runs the EvidentialOcTree reader's libFuzzer target (test/io/octomap_reader_fuzzer.cpp, built
// with clang, ASan and UBSan by cmake/OctomapTargets.cmake) for a fixed number of inputs from a
// seed corpus written here: valid files of several shapes and a few broken ones. Fails when the
// fuzzer finds a crash, leak, undefined behaviour or broken invariant, when it did not run, and
// when the fuzzer was not built (unless configured with -DES_ALLOW_NO_FUZZER=ON, which makes that
// a reported skip).
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <sstream>

#include "evidential_slam/io/evidential_octree.h"
#include "evidential_slam/io/octomap_export.h"
#include "octomap_test_support.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

// Fuzzed inputs per run: a count, not a time, so a loaded machine makes the test slower, never
// failing.
constexpr long kFuzzRuns = 20000;

// Small valid trees of both layouts (the fuzzer's default max_len is 4096 bytes, the seeds stay
// below it): the exporter's (layout 2, with and without an anomaly) and the committed file of
// layout 1.
std::vector<std::string> validSeeds(const fs::path& dir) {
  std::vector<std::string> seeds;
  auto add = [&](const EvidentialGridMap& grid, const OctomapExportConfig& config,
                 const AnomalyGrid& anomaly = AnomalyGrid()) {
    OctomapExportResult result;
    std::string error;
    EXPECT_TRUE(exportOctomap(grid, anomaly, config, (dir / "seed").string(), &result, &error))
        << error;
    seeds.push_back(test::readText(dir / "seed.evidential.ot"));
  };
  EvidentialGridMap empty(0.05);
  add(empty, {});
  EvidentialGridMap few(0.05);
  updateCell(few.mutableCell(0, 0), ScanMass{0.0f, 0.8f});
  updateCell(few.mutableCell(1, 0), ScanMass{0.63f, 0.0f});
  updateCell(few.mutableCell(-3, 2), ScanMass{0.3f, 0.3f});
  add(few, {});
  OctomapExportConfig two_layers;
  two_layers.z_max = 0.06;
  add(few, two_layers);
  EvidentialGridMap block(0.1);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int k = 0; k <= (x + y) % 3; ++k)
        updateCell(block.mutableCell(x, y), ScanMass{0.2f, 0.5f});
    }
  }
  add(block, two_layers);
  AnomalyGrid anomaly;
  anomaly.add(1, 0, 2.5f);
  anomaly.add(-3, 2, 0.75f);
  add(few, two_layers, anomaly);
  seeds.push_back(test::readText(test::dataPath("octomap_masses_v1.evidential.ot")));
  return seeds;
}

TEST(OctomapFuzz, ReaderSurvivesTheFuzzer) {
  const std::string fuzzer = ES_FUZZER_BIN;
  if (fuzzer.empty()) {
    if (ES_ALLOW_NO_FUZZER) GTEST_SKIP() << "libFuzzer (clang) not available; allowed by config";
    FAIL() << "the fuzzer was not built: clang++ with -fsanitize=fuzzer was not found at "
              "configure time (install clang and libclang-rt-14-dev, see scripts/packages.txt)";
  }
  ASSERT_TRUE(fs::is_regular_file(fuzzer)) << fuzzer;
  const fs::path scratch = test::scratchDir();
  const fs::path seeds_dir = scratch / "seeds", corpus = scratch / "corpus";
  fs::create_directories(seeds_dir);
  fs::create_directories(corpus);
  const std::vector<std::string> valid = validSeeds(scratch);
  std::vector<std::string> valid_paths;
  for (size_t i = 0; i < valid.size(); ++i) {
    ASSERT_LT(valid[i].size(), 4096u);
    const fs::path p = seeds_dir / ("valid" + std::to_string(i) + ".ot");
    test::writeText(p, valid[i]);
    valid_paths.push_back(p.string());
  }
  test::writeText(seeds_dir / "garbage", "# Octomap OcTree binary file\nid OcTree\n");
  test::writeText(seeds_dir / "truncated.ot", valid[1].substr(0, valid[1].size() - 9));
  test::writeText(seeds_dir / "other_type.ot",
                  "# Octomap OcTree file\nid ColorOcTree\nsize 1\nres 0.1\ndata\n");

  // The fuzzer build reads every valid seed (it aborts on a rejected one with this variable).
  test::RunResult r =
      test::runProgram(fuzzer, valid_paths, scratch, {{"ES_FUZZ_EXPECT_VALID", "1"}});
  ASSERT_EQ(r.exit_code, 0) << r.err;

  r = test::runProgram(
      fuzzer,
      {"-runs=" + std::to_string(kFuzzRuns), "-timeout=30", "-rss_limit_mb=2048",
       "-print_final_stats=1", "-artifact_prefix=" + scratch.string() + "/", corpus.string(),
       seeds_dir.string()},
      scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err.substr(r.err.size() > 4000 ? r.err.size() - 4000 : 0);
  EXPECT_EQ(r.err.find("ERROR: AddressSanitizer"), std::string::npos);
  EXPECT_EQ(r.err.find("runtime error"), std::string::npos);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("stat::number_of_executed_units: (\\d+)")))
      << r.err.substr(r.err.size() > 2000 ? r.err.size() - 2000 : 0);
  const long runs = std::stol(m[1]);
  EXPECT_GE(runs, kFuzzRuns) << "the fuzzer stopped early";
  std::printf("fuzzer: %ld inputs\n", runs);
  for (const auto& entry : fs::directory_iterator(scratch)) {
    const std::string name = entry.path().filename().string();
    for (const char* kind : {"crash-", "leak-", "timeout-", "oom-", "slow-unit-"}) {
      EXPECT_NE(name.rfind(kind, 0), 0u) << "fuzzer artifact " << entry.path();
    }
  }
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
