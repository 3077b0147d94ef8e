#include "evidential_slam/io/parameter_file.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

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

}  // namespace

bool readParameterFile(const std::string& path,
                       std::vector<std::pair<std::string, std::string>>* entries,
                       std::string* error) {
  entries->clear();
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = path + ": " + why;
    return false;
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail("cannot read the file");
  try {
    const YAML::Node root = YAML::Load(text.str());
    if (root.IsNull()) return true;
    if (!root.IsMap()) return fail("not a map of `name: value` lines");
    for (const auto& item : root) {
      if (!item.first.IsScalar()) return fail("a key is not a name");
      const std::string name = item.first.Scalar();
      if (!item.second.IsScalar()) return fail(name + ": the value is not a single value");
      entries->emplace_back(name, normaliseSwitch(item.second.Scalar()));
    }
  } catch (const YAML::Exception& e) {
    entries->clear();
    return fail("not YAML (line " + std::to_string(e.mark.line + 1) + ": " + e.msg + ")");
  }
  return true;
}

}  // namespace io
}  // namespace evidential_slam
