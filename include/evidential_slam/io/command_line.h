// Small pieces shared by the command lines of the io tools (evidential_slam_offline,
// evidential_slam_simulate): whole-string number parsing and `--flag=value` splitting.
#pragma once

#include <charconv>
#include <cmath>
#include <string>
#include <system_error>
#include <vector>

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

// Parses all of `text` as comma-separated finite numbers ("1.5,-2,0.3"); false on an empty
// item, junk, a non-finite number, or a count outside [min_count, max_count].
inline bool parseNumberList(const std::string& text, size_t min_count, size_t max_count,
                            std::vector<double>* values) {
  values->clear();
  size_t start = 0;
  for (;;) {
    const size_t comma = text.find(',', start);
    double v = 0.0;
    const std::string item = text.substr(start, comma == std::string::npos ? comma : comma - start);
    if (!parseNumber(item, &v) || !std::isfinite(v)) return false;
    values->push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return values->size() >= min_count && values->size() <= max_count;
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
