// The explorer's rows of the parameter table, expanded (see core/parameter_rows.h).
#pragma once

#include "evidential_slam/core/exploration/parameters.h"
#include "evidential_slam/core/parameter_rows.h"

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

}  // namespace exploration
}  // namespace evidential_slam
