#include "evidential_slam/ros/explorer_params.h"

#include "evidential_slam/ros/parameter_rows.h"
#include "evidential_slam/ros/parameter_text.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

// Reads every parameter forEach visits through `lookup`; unset ones keep their defaults.
template <typename ForEach>
bool readThroughTable(const ParameterLookup& lookup, ForEach&& for_each, std::string* why) {
  bool ok = true;
  for_each([&](const ParameterSpec& spec, auto& field) {
    XmlRpc::XmlRpcValue value;
    if (!ok || !lookup(spec.name, &value)) return;
    ok = parseServerValue(spec, value, &field, why);
  });
  return ok;
}

}  // namespace

ExplorerNodeParams::ExplorerNodeParams() {
  ES_EXPLORER_NODE_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool ExplorerNodeParams::isValid(std::string* why) const {
  if (!explorer.isValid(why)) return false;
  bool ok = true;
  ES_EXPLORER_NODE_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

bool readExplorerParams(const ParameterLookup& lookup, ExplorerNodeParams* params,
                        std::string* why) {
  return readThroughTable(
      lookup, [params](auto&& visit) { forEachExplorerNodeParameter(*params, visit); }, why);
}

ExplorationMonitorParams::ExplorationMonitorParams() {
  ES_EXPLORATION_MONITOR_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool ExplorationMonitorParams::isValid(std::string* why) const {
  bool ok = true;
  ES_EXPLORATION_MONITOR_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

bool readExplorationMonitorParams(const ParameterLookup& lookup, ExplorationMonitorParams* params,
                                  std::string* why) {
  return readThroughTable(
      lookup,
      [params](auto&& visit) {
        auto& p = *params;
        ES_EXPLORATION_MONITOR_PARAMETERS(ES_VISIT_PARAMETER, p)
      },
      why);
}

std::vector<std::string> unknownExplorerParams(const std::vector<std::string>& names) {
  std::vector<std::string> known;
  ExplorerNodeParams scratch;
  forEachExplorerNodeParameter(
      scratch, [&known](const ParameterSpec& spec, auto&) { known.push_back(spec.name); });
  std::vector<std::string> unknown;
  for (const std::string& n : names) {
    bool is_known = false;
    for (const std::string& k : known) is_known = is_known || n == k;
    if (!is_known) unknown.push_back(n);
  }
  return unknown;
}

}  // namespace ros_adapter
}  // namespace evidential_slam
