// Small pieces shared by the command lines of the io tools (evidential_slam_offline,
// evidential_slam_simulate): whole-string number parsing and `--flag=value` splitting.
#pragma once

#include <charconv>
#include <string>
#include <system_error>

namespace evidential_slam {
namespace io {

// Parses all of `text` as a number (no leading/trailing junk); false otherwise.
template <typename T>
bool parseNumber(const std::string& text, T* value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto r = std::from_chars(begin, end, *value);
  return r.ec == std::errc() && r.ptr == end && !text.empty();
}

// One command-line argument: `--flag=value` splits into flag and value (`has_value` set);
// anything else is just the flag.
struct CommandLineArg {
  std::string flag;
  std::string value;
  bool has_value = false;
};
inline CommandLineArg splitArg(const std::string& arg) {
  CommandLineArg a{arg, "", false};
  if (arg.rfind("--", 0) == 0) {
    const size_t eq = arg.find('=');
    if (eq != std::string::npos) {
      a.flag = arg.substr(0, eq);
      a.value = arg.substr(eq + 1);
      a.has_value = true;
    }
  }
  return a;
}

}  // namespace io
}  // namespace evidential_slam
