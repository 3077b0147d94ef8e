// Runs each libFuzzer target of test/fuzz/ (built with clang, ASan and UBSan by
// cmake/FuzzTargets.cmake): first over its committed corpus (seeds and the regression inputs of
// crashes once found, each must pass), then for a fixed number of fuzzed inputs from it (a count,
// not a time: a loaded machine makes it slower, never failing). Fails on a crash, leak, undefined
// behaviour, broken invariant, time-out or allocation over the limit, when a target ran fewer
// inputs than asked, and when the targets were not built (unless configured with
// -DES_ALLOW_NO_FUZZER=ON, which makes that a reported skip).
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

// Inputs per target: the rawlog target goes through MRPT's deserialisation (about 100 inputs/s
// unloaded), the text readers are fast.
long fuzzRuns(const std::string& name) { return name == "rawlog" ? 1000 : 10000; }

std::string tail(const std::string& s, size_t n = 3000) {
  return s.size() > n ? s.substr(s.size() - n) : s;
}

class FuzzSmoke : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzSmoke, SurvivesItsCorpusAndAFixedNumberOfFuzzedInputs) {
  const std::string dir = ES_FUZZ_DIR;
  if (dir.empty()) {
    if (ES_ALLOW_NO_FUZZER) GTEST_SKIP() << "libFuzzer (clang) not available; allowed by config";
    FAIL() << "the fuzz targets were not built: clang++ with -fsanitize=fuzzer was not found at "
              "configure time (install clang and libclang-rt-14-dev, see scripts/packages.txt)";
  }
  const std::string name = GetParam();
  const fs::path fuzzer = fs::path(dir) / (name + "_fuzzer");
  const fs::path corpus = fs::path(ES_FUZZ_CORPUS_DIR) / name;
  ASSERT_TRUE(fs::is_regular_file(fuzzer)) << fuzzer;
  ASSERT_TRUE(fs::is_directory(corpus)) << corpus;
  const fs::path scratch = test::scratchDir();
  const fs::path grown = scratch / "corpus";
  fs::create_directories(grown);
  // Per input at most 30 s (a hang, even on a loaded machine) and 2 GB in all; a single
  // allocation over 256 MB is a failure (the readers' limits keep every allocation far below it).
  const std::vector<std::string> limits = {"-timeout=30", "-rss_limit_mb=2048",
                                           "-malloc_limit_mb=256", "-print_final_stats=1",
                                           "-artifact_prefix=" + scratch.string() + "/"};

  std::vector<std::string> args = limits;
  args.push_back("-runs=0");  // every committed input once
  args.push_back(corpus.string());
  test::RunResult r = test::runProgram(fuzzer.string(), args, scratch);
  ASSERT_EQ(r.exit_code, 0) << tail(r.err);

  args = limits;
  const long want = fuzzRuns(name);
  args.push_back("-runs=" + std::to_string(want));
  args.push_back(grown.string());
  args.push_back(corpus.string());
  r = test::runProgram(fuzzer.string(), args, scratch);
  EXPECT_EQ(r.exit_code, 0) << tail(r.err);
  EXPECT_EQ(r.err.find("ERROR: AddressSanitizer"), std::string::npos) << tail(r.err);
  EXPECT_EQ(r.err.find("runtime error"), std::string::npos) << tail(r.err);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("stat::number_of_executed_units: (\\d+)")))
      << tail(r.err);
  const long runs = std::stol(m[1]);
  EXPECT_GE(runs, want) << "the fuzzer stopped early";
  std::printf("%s: %ld inputs\n", name.c_str(), runs);
  for (const auto& entry : fs::directory_iterator(scratch)) {
    const std::string file = entry.path().filename().string();
    for (const char* kind : {"crash-", "leak-", "timeout-", "oom-", "slow-unit-"}) {
      EXPECT_NE(file.rfind(kind, 0), 0u) << "fuzzer artifact " << entry.path();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Readers, FuzzSmoke,
                         ::testing::Values("rawlog", "ground_truth", "waypoints", "yaml_config",
                                           "layers"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace evidential_slam
