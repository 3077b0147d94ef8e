// Every ROS parameter of the explorer node (the core Explorer's and the node's own) and of
// exploration_monitor, read by the rows of the parameter table (core/parameters.def).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <xmlrpcpp/XmlRpcValue.h>

#include "evidential_slam/core/exploration/parameters.h"
#include "evidential_slam/core/parameter_fields/exploration_monitor.h"
#include "evidential_slam/core/parameter_fields/explorer_node.h"

namespace evidential_slam {
namespace ros_adapter {

struct ExplorerNodeParams {
  ExplorerNodeParams();  // the table's defaults
  ES_EXPLORER_NODE_FIELDS
  exploration::ExplorerConfig explorer;

  bool isValid(std::string* why) const;
};

// Looks a private parameter up by name: false when it is not set.
using ParameterLookup = std::function<bool(const std::string& name, XmlRpc::XmlRpcValue* value)>;

// Reads every parameter through `lookup`; unset ones keep their defaults. False with a one-line
// `why` for a value of the wrong type or out of range (range only: call isValid after).
bool readExplorerParams(const ParameterLookup& lookup, ExplorerNodeParams* params,
                        std::string* why);

// The names among `names` (private parameter names) that are no parameter of the explorer.
std::vector<std::string> unknownExplorerParams(const std::vector<std::string>& names);

// exploration_monitor's parameters (the harness of explore.launch).
struct ExplorationMonitorParams {
  ExplorationMonitorParams();  // the table's defaults
  ES_EXPLORATION_MONITOR_FIELDS

  bool isValid(std::string* why) const;
};

// As readExplorerParams, for exploration_monitor.
bool readExplorationMonitorParams(const ParameterLookup& lookup, ExplorationMonitorParams* params,
                                  std::string* why);

}  // namespace ros_adapter
}  // namespace evidential_slam
