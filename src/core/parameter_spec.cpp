// What the table's rows need one at a time: range checks, parsing and printing a value. Apart
// from parameters.cpp (the structs' lists) so that code checking one row links without them.
#include "evidential_slam/core/parameters.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <system_error>

namespace evidential_slam {
namespace {

std::string rangeText(const ParameterSpec& spec) {
  char text[96];
  std::snprintf(text, sizeof(text), "[%.9g, %.9g]%s%s", spec.min, spec.max,
                spec.unit[0] != '\0' ? " " : "", spec.unit);
  return text;
}

bool refuse(std::string* why, const std::string& what) {
  if (why != nullptr) *why = what;
  return false;
}

// Whole-string decimal parses.
bool parseNumber(const std::string& text, double* out) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *out);
  return r.ec == std::errc() && r.ptr == text.data() + text.size() && std::isfinite(*out);
}
bool parseNumber(const std::string& text, int* out) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *out);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

}  // namespace

std::string valueText(int v) { return std::to_string(v); }
std::string valueText(bool v) { return v ? "true" : "false"; }
std::string valueText(const std::string& v) { return v; }
std::string valueText(double v) {
  char text[40];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(text, sizeof(text), "%.*g", precision, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

bool inRange(const ParameterSpec& spec, double value, std::string* why) {
  if (std::isfinite(value) && value >= spec.min && value <= spec.max) return true;
  return refuse(why, std::string(spec.name) + " must be in " + rangeText(spec));
}
bool inRange(const ParameterSpec& spec, int value, std::string* why) {
  return inRange(spec, static_cast<double>(value), why);
}
bool inRange(const ParameterSpec&, bool, std::string*) { return true; }
bool inRange(const ParameterSpec&, const std::string&, std::string*) { return true; }

bool parseParameter(const ParameterSpec& spec, const std::string& text, int* field,
                    std::string* why) {
  int v = 0;
  if (!parseNumber(text, &v)) {
    return refuse(why, std::string(spec.name) + " wants an integer, not '" + text + "'");
  }
  if (!inRange(spec, v, why)) return false;
  *field = v;
  return true;
}

bool parseParameter(const ParameterSpec& spec, const std::string& text, double* field,
                    std::string* why) {
  double v = 0.0;
  if (!parseNumber(text, &v)) {
    return refuse(why, std::string(spec.name) + " wants a number, not '" + text + "'");
  }
  if (!inRange(spec, v, why)) return false;
  *field = v;
  return true;
}

bool parseParameter(const ParameterSpec& spec, const std::string& text, bool* field,
                    std::string* why) {
  if (text == "true" || text == "1") {
    *field = true;
  } else if (text == "false" || text == "0") {
    *field = false;
  } else {
    return refuse(why, std::string(spec.name) + " wants true or false, not '" + text + "'");
  }
  return true;
}

bool parseParameter(const ParameterSpec& spec, const std::string& text, std::string* field,
                    std::string* why) {
  if (text.empty()) return refuse(why, std::string(spec.name) + " must not be empty");
  *field = text;
  return true;
}

}  // namespace evidential_slam
