#include "evidential_slam/io/strict_yaml.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace {

// The first duplicate key of any map under `root` (iterative: the depth is yaml-cpp's bound).
bool findDuplicateKey(const YAML::Node& root, std::string* key) {
  std::vector<YAML::Node> stack{root};
  while (!stack.empty()) {
    const YAML::Node node = stack.back();
    stack.pop_back();
    if (node.IsMap()) {
      std::set<std::string> seen;
      for (const auto& item : node) {
        const std::string text =
            item.first.IsScalar() ? item.first.Scalar() : YAML::Dump(item.first);
        if (!seen.insert(text).second) {
          *key = text;
          return true;
        }
        stack.push_back(item.first);
        stack.push_back(item.second);
      }
    } else if (node.IsSequence()) {
      for (const auto& item : node) stack.push_back(item);
    }
  }
  return false;
}

// Documents in `text`: a "---" or "..." line after content starts another (a "---" before any
// content only opens the first).
int documentCount(const std::string& text) {
  int documents = 0;
  bool content = false;
  size_t begin = 0;
  while (begin <= text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(begin, end - begin);
    begin = end + 1;
    const bool marker = (line.rfind("---", 0) == 0 || line.rfind("...", 0) == 0) &&
                        (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
    if (marker) {
      if (content) ++documents;
      content = false;
      continue;
    }
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#' && line[first] != '%') content = true;
  }
  return documents + (content ? 1 : 0);
}

}  // namespace

bool loadStrictYaml(const std::string& text, const std::string& source, YAML::Node* root,
                    std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = source + ": " + why;
    return false;
  };
  if (text.size() > kStrictYamlMaxBytes) {
    return fail(std::to_string(text.size()) + " bytes, more than a YAML file of " +
                std::to_string(kStrictYamlMaxBytes) + " read here");
  }
  try {
    // Not YAML::LoadAll: yaml-cpp 0.7's loops for ever on a text such as "," (its parser
    // reports a document without consuming anything).
    const int documents = documentCount(text);
    if (documents > 1) return fail(std::to_string(documents) + " YAML documents, one expected");
    *root = YAML::Load(text);
    std::string key;
    if (findDuplicateKey(*root, &key)) return fail("duplicate key " + quotedForMessage(key));
  } catch (const YAML::Exception& e) {
    return fail("not YAML (line " + std::to_string(e.mark.line + 1) + ": " + oneLineMessage(e.msg) +
                ")");
  } catch (const std::exception& e) {
    return fail("not YAML (" + oneLineMessage(e.what()) + ")");
  }
  return true;
}

bool loadStrictYamlFile(const std::string& path, YAML::Node* root, std::string* error) {
  const std::string source = quotedPath(path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (error != nullptr) *error = source + ": not a regular file";
    return false;
  }
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > kStrictYamlMaxBytes) {
    if (error != nullptr) {
      *error = source + ": " +
               (ec ? std::string("cannot read its size")
                   : std::to_string(size) + " bytes, more than a YAML file of " +
                         std::to_string(kStrictYamlMaxBytes) + " read here");
    }
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();
  if (!in || in.bad()) {
    if (error != nullptr) *error = source + ": cannot read the file";
    return false;
  }
  return loadStrictYaml(text.str(), source, root, error);
}

bool strictYamlNumber(const YAML::Node& node, const std::string& field, double* value,
                      std::string* why) {
  if (!node.IsDefined() || node.IsNull()) {
    *why = "'" + field + "' is missing";
    return false;
  }
  if (!node.IsScalar()) {
    *why = "'" + field + "' is not a number";
    return false;
  }
  const std::string& text = node.Scalar();
  if (node.Tag() != "?") {
    *why = "'" + field + "' is " + quotedForMessage(text) + ", quoted text, not a number";
    return false;
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v)) {
    *why = "'" + field + "' is " + quotedForMessage(text) + ", not a finite number";
    return false;
  }
  *value = v;
  return true;
}

}  // namespace io
}  // namespace evidential_slam
