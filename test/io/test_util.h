// Shared bits of the io/ tests: fixture paths (compile definitions set in CMakeLists.txt), a
// fresh scratch directory per test, and running a program.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace evidential_slam {
namespace test {

inline std::string dataPath(const std::string& name) {
  return std::string(ES_TEST_DATA_DIR) + "/" + name;
}

// An empty directory named after the running test, under the build tree.
inline std::filesystem::path scratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::filesystem::path dir = std::filesystem::path(ES_TEST_TMP_DIR) /
                              (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `program args...` with stdin from /dev/null; stdout and stderr are captured in files in
// `scratch`, `cwd` (if set) is the working directory.
inline RunResult runProgram(const std::string& program, const std::vector<std::string>& args,
                            const std::filesystem::path& scratch,
                            const std::map<std::string, std::string>& env = {},
                            const std::string& cwd = "") {
  std::string cmd;
  if (!cwd.empty()) cmd += "cd " + shellQuote(cwd) + " && ";
  for (const auto& [k, v] : env) cmd += k + "=" + shellQuote(v) + " ";
  cmd += shellQuote(program);
  for (const auto& a : args) cmd += " " + shellQuote(a);
  const std::filesystem::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  cmd += " > " + shellQuote(out.string()) + " 2> " + shellQuote(err.string()) + " < /dev/null";
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readText(out);
  r.err = readText(err);
  return r;
}

}  // namespace test
}  // namespace evidential_slam
