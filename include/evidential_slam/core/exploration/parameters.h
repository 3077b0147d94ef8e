// The explorer's rows of the parameter table (core/parameters.def) as data: a visitor over the
// fields of an ExplorerConfig, one parameter set by name from text (the node's ROS parameters and
// the offline tools' --param go through it), and every value as text.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/exploration/explorer.h"
#include "evidential_slam/core/parameters.h"

namespace evidential_slam {
namespace exploration {

// Visits every row of the explorer's lists: visit(spec, field).
template <typename Config, typename Visitor>
void forEachExplorerParameter(Config& c, Visitor&& visit) {
  ES_EXPLORER_CELL_PARAMETERS(ES_VISIT_PARAMETER, c.cells)
  ES_EXPLORER_GOAL_PARAMETERS(ES_VISIT_PARAMETER, c.frontiers)
  ES_EXPLORER_PLANNER_PARAMETERS(ES_VISIT_PARAMETER, c.planner)
  ES_EXPLORER_PURSUIT_PARAMETERS(ES_VISIT_PARAMETER, c.pursuit)
  ES_EXPLORER_PARAMETERS(ES_VISIT_PARAMETER, c)
}

// The rows of the explorer's parameters, in table order.
std::vector<ParameterSpec> explorerParameterSpecs();

// Sets one explorer parameter by name from text. False with a one-line reason for an unknown name
// or a bad value (the config is unchanged then).
bool setExplorerParameter(const std::string& name, const std::string& value,
                          ExplorerConfig* config, std::string* why);

// Every explorer parameter's value as text, in table order.
std::vector<std::pair<std::string, std::string>> explorerParameterValues(
    const ExplorerConfig& config);

}  // namespace exploration
}  // namespace evidential_slam
