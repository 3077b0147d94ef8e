// The explorer's rows of the parameter table (core/parameters.def) as data: one parameter set by
// name from text (the node's ROS parameters and the offline tools' --param go through it), and
// every value as text. The visitor over an ExplorerConfig's fields is in parameter_rows.h.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/exploration/explorer.h"
#include "evidential_slam/core/parameters.h"

namespace evidential_slam {
namespace exploration {

// The rows of the explorer's parameters, in table order.
std::vector<ParameterSpec> explorerParameterSpecs();

// Sets one explorer parameter by name from text. False with a one-line reason for an unknown name
// or a bad value (the config is unchanged then).
bool setExplorerParameter(const std::string& name, const std::string& value, ExplorerConfig* config,
                          std::string* why);

// Every explorer parameter's value as text, in table order.
std::vector<std::pair<std::string, std::string>> explorerParameterValues(
    const ExplorerConfig& config);

}  // namespace exploration
}  // namespace evidential_slam
