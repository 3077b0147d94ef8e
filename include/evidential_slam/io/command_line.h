// The one command line of the programs in src/apps/: each declares its options on a CommandLine
// (CLI11 underneath: docs/decisions.md#command-lines-on-cli11) with a callback per value, and gets
// the same handling of --help, `--flag=value`, unknown options, missing values and --param, the
// same one-line errors, and a --param listing generated from the parameter table. Plus the
// whole-string number parsing the option callbacks share.
#pragma once

#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "evidential_slam/core/parameters.h"

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

// Thrown by an option's callback for a bad value: its text is the one-line error.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A NAME=VALUE pair of --param (or of a shorthand option standing for one parameter).
using ParameterAssignments = std::vector<std::pair<std::string, std::string>>;

class CommandLine {
 public:
  // `description` opens --help (the usage lines and what the program does); `footer` ends it.
  CommandLine(const std::string& description, const std::string& footer);

  // A switch taking no value (`--flag=x` is refused): `on_set` runs when it is given.
  CLI::Option* flag(const std::string& names, const std::string& help,
                    std::function<void()> on_set);
  // An option taking one value (`--name V` or `--name=V`), repeatable: `on_value` runs once per
  // occurrence, in command-line order, and throws UsageError for a bad value.
  CLI::Option* option(const std::string& names, const std::string& value_name,
                      const std::string& help, std::function<void(const std::string&)> on_value);
  // --param NAME=VALUE, repeatable: appended to `out` in command-line order (with whatever else
  // the program appends there); "--param wants NAME=VALUE" without a name and '='.
  CLI::Option* param(ParameterAssignments* out, const std::string& help);
  // A positional argument (`required`: missing is "NAME is required").
  CLI::Option* positional(const std::string& name, const std::string& help, std::string* value,
                          bool required);

  // What an unknown option and a missing value are called ("%s": the option).
  void setMessages(std::string unknown_option, std::string needs_value);
  // Text --help prints after the options (e.g. parameterHelp's listing).
  void appendHelp(const std::string& text) { extra_help_ += text; }

  // Parses the arguments after the program name. False with a one-line `error` on bad usage;
  // `help` is set (and true returned) for -h/--help, whatever else is given.
  bool parse(const std::vector<std::string>& args, bool* help, std::string* error);
  std::string help() const;
  // For main(): parses argv; on -h/--help prints the help to stdout and returns 0, on bad usage
  // prints "error: ... (see --help)" to stderr and returns `usage_exit`; -1 when the program
  // should run.
  int parseMain(int argc, char** argv, int usage_exit);

  CLI::App& app() { return app_; }

 private:
  CLI::App app_;
  std::string unknown_option_ = "unknown option '%s'";
  std::string needs_value_ = "%s needs a value";
  std::string extra_help_;
};

// One line per parameter for --help: name, default and unit, type and range, meaning.
// `defaults` are the parameters' values as text (parameterValues, ...), in `specs`' order.
std::string parameterHelp(const std::string& title, const std::vector<ParameterSpec>& specs,
                          const std::vector<std::pair<std::string, std::string>>& defaults);
// The listing of every shared parameter (the SLAM's, the conflict alarm's, the session's and
// localization's) at its default.
std::string sharedParameterHelp(const std::string& title);

// Applies the parameter files in order (config/*.yaml's format; node-only names go to `ignored`),
// then `assignments` in order, to `params`. False with a one-line `error` naming the file or the
// parameter.
bool applyParameters(const std::vector<std::string>& config_files,
                     const ParameterAssignments& assignments, Parameters* params,
                     std::vector<std::string>* ignored, std::string* error);

}  // namespace io
}  // namespace evidential_slam
