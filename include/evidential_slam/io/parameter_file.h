// Parameter files (config/*.yaml): a YAML map of `name: value`, the format `rosparam load` reads
// into a node's namespace, so one file configures the offline runner (--config) and the node
// (slam.launch config:=).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/parameters.h"

namespace evidential_slam {
namespace io {

// Reads the entries of a parameter file in file order, each value as text (a YAML 1.1 switch
// such as `yes` or `On` as true/false). False with a one-line `error` for a file that cannot be
// read, is not YAML, is not a map (an empty file is an empty map), or holds a value that is not
// a single scalar.
bool readParameterFile(const std::string& path,
                       std::vector<std::pair<std::string, std::string>>* entries,
                       std::string* error);
// The same for the text of a file; `source` names it in the error.
bool readParameterText(const std::string& text, const std::string& source,
                       std::vector<std::pair<std::string, std::string>>* entries,
                       std::string* error);

// Sets the shared parameters of `entries` (read from `source`) in `params` (setParameter); the
// names of node parameters go to `ignored` instead. False at the first bad entry with a one-line
// `error` naming `source`, printable whatever bytes the file held.
bool applyParameterEntries(const std::vector<std::pair<std::string, std::string>>& entries,
                           const std::string& source, Parameters* params,
                           std::vector<std::string>* ignored, std::string* error);

}  // namespace io
}  // namespace evidential_slam
