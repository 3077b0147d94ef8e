// Shared bits of the io/ tests: fixture paths (compile definitions set in CMakeLists.txt) and a
// fresh scratch directory per test.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

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

}  // namespace test
}  // namespace evidential_slam
