// Parameter files (config/*.yaml): a YAML map of `name: value`, the format `rosparam load` reads
// into a node's namespace, so one file configures the offline runner (--config) and the node
// (slam.launch config:=).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace evidential_slam {
namespace io {

// Reads the entries of a parameter file in file order, each value as text (a YAML 1.1 switch
// such as `yes` or `On` as true/false). False with a one-line `error` for a file that cannot be
// read, is not YAML, is not a map (an empty file is an empty map), or holds a value that is not
// a single scalar.
bool readParameterFile(const std::string& path,
                       std::vector<std::pair<std::string, std::string>>* entries,
                       std::string* error);

}  // namespace io
}  // namespace evidential_slam
