// Strict reading of small YAML files from outside (a layer folder's map.yaml): bounded size, one
// document, no duplicate keys, numbers written as plain numbers (a quoted "5" is text).
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

namespace evidential_slam {
namespace io {

// Largest YAML file read this way.
constexpr size_t kStrictYamlMaxBytes = size_t{1} << 20;

// Parses `text` as exactly one YAML document without duplicate keys in any map (yaml-cpp bounds
// the nesting). False and a one-line `error` ("<source>: why") otherwise.
bool loadStrictYaml(const std::string& text, const std::string& source, YAML::Node* root,
                    std::string* error);
// The same for the file at `path` (at most kStrictYamlMaxBytes).
bool loadStrictYamlFile(const std::string& path, YAML::Node* root, std::string* error);

// `node` as a finite number written plainly (not quoted, the whole scalar). False and a `why`
// naming `field` otherwise.
bool strictYamlNumber(const YAML::Node& node, const std::string& field, double* value,
                      std::string* why);

}  // namespace io
}  // namespace evidential_slam
