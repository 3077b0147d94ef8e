// The ROS nodes' rows of the parameter table, expanded (see core/parameter_rows.h).
#pragma once

#include "evidential_slam/core/exploration/parameter_rows.h"
#include "evidential_slam/core/parameter_rows.h"
#include "evidential_slam/ros/explorer_params.h"
#include "evidential_slam/ros/map_fusion_params.h"
#include "evidential_slam/ros/params.h"

namespace evidential_slam {
namespace ros_adapter {

// Visits every parameter of the node, the shared ones first: visit(spec, field).
template <typename Params, typename Visitor>
void forEachNodeParameter(Params& p, Visitor&& visit) {
  forEachSharedParameter(p, visit);
  ES_NODE_PARAMETERS(ES_VISIT_PARAMETER, p)
}

// Visits every parameter of the explorer node, the core's first: visit(spec, field).
template <typename Params, typename Visitor>
void forEachExplorerNodeParameter(Params& p, Visitor&& visit) {
  exploration::forEachExplorerParameter(p.explorer, visit);
  ES_EXPLORER_NODE_PARAMETERS(ES_VISIT_PARAMETER, p)
}

template <typename Params, typename Visitor>
void forEachMapFusionParameter(Params& p, Visitor&& visit) {
  ES_SESSION_PARAMETERS(ES_VISIT_PARAMETER, p.session)
  ES_MAP_FUSION_PARAMETERS(ES_VISIT_PARAMETER, p)
}

}  // namespace ros_adapter
}  // namespace evidential_slam
