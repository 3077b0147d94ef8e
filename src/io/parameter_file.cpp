#include "evidential_slam/io/parameter_file.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/strict_yaml.h"

namespace evidential_slam {
namespace io {
namespace {

// YAML 1.1's switch spellings (what rosparam's PyYAML reads as booleans) as true / false.
std::string normaliseSwitch(const std::string& text) {
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "true" || lower == "yes" || lower == "on") return "true";
  if (lower == "false" || lower == "no" || lower == "off") return "false";
  return text;
}

// A shared parameter whose value is a number or a switch.
bool numericParameter(const std::string& name) {
  static const std::vector<ParameterSpec> specs = sharedParameterSpecs();
  for (const ParameterSpec& spec : specs) {
    if (name == spec.name) return std::string(spec.type) != "std::string";
  }
  return false;
}

}  // namespace

bool readParameterFile(const std::string& path,
                       std::vector<std::pair<std::string, std::string>>* entries,
                       std::string* error) {
  entries->clear();
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();
  if (!in || in.bad()) {
    if (error != nullptr) *error = path + ": cannot read the file";
    return false;
  }
  return readParameterText(text.str(), path, entries, error);
}

bool readParameterText(const std::string& text, const std::string& source,
                       std::vector<std::pair<std::string, std::string>>* entries,
                       std::string* error) {
  entries->clear();
  auto fail = [&](const std::string& why) {
    entries->clear();
    if (error != nullptr) *error = source + ": " + why;
    return false;
  };
  try {
    // One document, no key twice (strict_yaml.h): the last of two `particles:` lines or a
    // second document must not win or vanish silently.
    YAML::Node root;
    std::string why;
    if (!loadStrictYaml(text, "", &root, &why)) return fail(why.substr(2));  // drops ": "
    if (root.IsNull()) return true;
    if (!root.IsMap()) return fail("not a map of `name: value` lines");
    for (const auto& item : root) {
      if (!item.first.IsScalar()) return fail("a key is not a name");
      const std::string name = item.first.Scalar();
      if (!item.second.IsScalar()) {
        return fail(quotedForMessage(name) + ": the value is not a single value");
      }
      // A quoted value is text: "5" for a number or a switch is refused, as ROS would read it.
      if (item.second.Tag() == "!" && numericParameter(name)) {
        return fail(quotedForMessage(name) + ": " + quotedForMessage(item.second.Scalar()) +
                    " is quoted text; a number or switch is written without quotes");
      }
      entries->emplace_back(name, normaliseSwitch(item.second.Scalar()));
    }
  } catch (const YAML::Exception& e) {
    return fail("not YAML (line " + std::to_string(e.mark.line + 1) + ": " +
                oneLineMessage(e.msg) + ")");
  }
  return true;
}

bool applyParameterEntries(const std::vector<std::pair<std::string, std::string>>& entries,
                           const std::string& source, Parameters* params,
                           std::vector<std::string>* ignored, std::string* error) {
  for (const auto& [name, text] : entries) {
    std::string why;
    if (isNodeParameter(name)) {
      if (ignored != nullptr) ignored->push_back(name);
    } else if (!setParameter(name, text, params, &why)) {
      if (error != nullptr) *error = source + ": " + oneLineMessage(why);
      return false;
    }
  }
  return true;
}

}  // namespace io
}  // namespace evidential_slam
