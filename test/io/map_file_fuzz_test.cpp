// Runs the map file reader's libFuzzer target (test/io/map_file_fuzzer.cpp, built with clang, ASan
// and UBSan by cmake/MapFileTargets.cmake) for a fixed number of inputs from the committed seeds
// (test/data/map_file_seeds: valid files, the raw form of one, and the inputs of past findings).
// Fails when the fuzzer finds a crash, leak, undefined behaviour or broken invariant, when it did
// not run, and when it was not built (unless configured with -DES_ALLOW_NO_FUZZER=ON, which makes
// that a reported skip).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

// Fuzzed inputs per run: a count, not a time, so a loaded machine makes the test slower, never
// failing.
constexpr long kFuzzRuns = 5000;
const char* const kSeedDir = ES_TEST_DATA_DIR "/map_file_seeds";

struct RunResult {
  int exit_code = -1;
  std::string err;
};

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

RunResult run(const std::string& env, const std::vector<std::string>& args,
              const fs::path& scratch) {
  std::string cmd = env + " " + quote(ES_FUZZER_BIN);
  for (const std::string& a : args) cmd += " " + quote(a);
  const fs::path err = scratch / "stderr.txt";
  cmd += " > /dev/null 2> " + quote(err.string()) + " < /dev/null";
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = test::readText(err);
  return r;
}

std::string tail(const std::string& s, size_t n) {
  return s.substr(s.size() > n ? s.size() - n : 0);
}

TEST(MapFileFuzz, ReaderSurvivesTheFuzzer) {
  if (std::string(ES_FUZZER_BIN).empty()) {
    if (ES_ALLOW_NO_FUZZER) GTEST_SKIP() << "libFuzzer (clang) not available; allowed by config";
    FAIL() << "the fuzzer was not built: clang++ with -fsanitize=fuzzer was not found at "
              "configure time (install clang and libclang-rt-14-dev, see scripts/packages.txt)";
  }
  ASSERT_TRUE(fs::is_regular_file(ES_FUZZER_BIN)) << ES_FUZZER_BIN;
  const fs::path scratch = test::scratchDir();
  const fs::path corpus = scratch / "corpus";  // new inputs go here, not into the source tree
  fs::create_directories(corpus);

  // The fuzzer build reads every valid seed (it aborts on a rejected one with this variable).
  std::vector<std::string> valid;
  for (const auto& entry : fs::directory_iterator(kSeedDir)) {
    if (entry.path().filename().string().rfind("valid_", 0) == 0) valid.push_back(entry.path());
  }
  ASSERT_GE(valid.size(), 3u);
  RunResult r = run("ES_FUZZ_EXPECT_VALID=1", valid, scratch);
  ASSERT_EQ(r.exit_code, 0) << tail(r.err, 4000);

  r = run("",
          {"-runs=" + std::to_string(kFuzzRuns), "-max_len=16384", "-timeout=30",
           "-rss_limit_mb=2048", "-print_final_stats=1",
           "-artifact_prefix=" + scratch.string() + "/", corpus.string(), kSeedDir},
          scratch);
  EXPECT_EQ(r.exit_code, 0) << tail(r.err, 4000);
  EXPECT_EQ(r.err.find("ERROR: AddressSanitizer"), std::string::npos);
  EXPECT_EQ(r.err.find("runtime error"), std::string::npos);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("stat::number_of_executed_units: (\\d+)")))
      << tail(r.err, 2000);
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
}  // namespace evidential_slam
