#include "evidential_slam/ros/explorer_params.h"

#include <cstdio>

namespace evidential_slam {
namespace ros_adapter {
namespace {

// A parameter server value as the text the table's parsers read; false for arrays and structs.
bool asText(XmlRpc::XmlRpcValue& value, std::string* text) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeInt:
      *text = std::to_string(static_cast<int>(value));
      return true;
    case XmlRpc::XmlRpcValue::TypeDouble: {
      char buffer[40];
      std::snprintf(buffer, sizeof(buffer), "%.17g", static_cast<double>(value));
      *text = buffer;
      return true;
    }
    case XmlRpc::XmlRpcValue::TypeBoolean:
      *text = static_cast<bool>(value) ? "true" : "false";
      return true;
    case XmlRpc::XmlRpcValue::TypeString:
      *text = static_cast<std::string>(value);
      return true;
    default:
      return false;
  }
}

}  // namespace

bool ExplorerNodeParams::isValid(std::string* why) const {
  if (!explorer.isValid(why)) return false;
  bool ok = true;
  ES_EXPLORER_NODE_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

bool readExplorerParams(const ParameterLookup& lookup, ExplorerNodeParams* params,
                        std::string* why) {
  bool ok = true;
  forEachExplorerNodeParameter(*params, [&](const ParameterSpec& spec, auto& field) {
    XmlRpc::XmlRpcValue value;
    if (!ok || !lookup(spec.name, &value)) return;
    std::string text;
    if (!asText(value, &text)) {
      ok = false;
      if (why != nullptr) *why = std::string(spec.name) + " must be a single value";
      return;
    }
    ok = parseParameter(spec, text, &field, why);
  });
  return ok;
}

std::vector<std::string> unknownExplorerParams(const std::vector<std::string>& names) {
  std::vector<std::string> known;
  ExplorerNodeParams scratch;
  forEachExplorerNodeParameter(scratch,
                               [&known](const ParameterSpec& spec, auto&) { known.push_back(spec.name); });
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
