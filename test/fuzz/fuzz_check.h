// What every fuzz target checks besides "no crash, no leak, no undefined behaviour": an error is
// one non-empty line of printable ASCII (no bytes of the input reach a terminal).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace evidential_slam {
namespace fuzz {

[[noreturn]] inline void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz invariant broken: %s %s\n", what, detail.c_str());
  std::abort();
}

inline void checkErrorLine(const std::string& error) {
  if (error.empty()) die("empty error message", "");
  for (unsigned char c : error) {
    if (c < 0x20 || c >= 0x7f) die("unprintable byte in the error message:", error);
  }
}

}  // namespace fuzz
}  // namespace evidential_slam
