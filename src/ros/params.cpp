#include "evidential_slam/ros/params.h"
#include "evidential_slam/ros/parameter_text.h"

#include <cstdio>

#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace evidential_slam {
namespace ros_adapter {
namespace {

// The run-time rows bound to their field of the generated dynamic_reconfigure struct:
// visit(field, cfg_field). Start-up rows have no cfg field.
#define ES_BIND_RECONFIGURE(ctx, name, member, type, def, min, max, unit, scope, meaning) \
  ES_BIND_RECONFIGURE_##scope(ctx, name, member)
#define ES_BIND_RECONFIGURE_runtime(ctx, name, member) visit((ctx).member, cfg.name);
#define ES_BIND_RECONFIGURE_startup(ctx, name, member)

template <typename Params, typename Cfg, typename Visitor>
void forEachReconfigurable(Params& p, Cfg& cfg, Visitor&& visit) {
  ES_SLAM_CONFIG_PARAMETERS(ES_BIND_RECONFIGURE, p.slam)
  ES_CONFLICT_ALARM_PARAMETERS(ES_BIND_RECONFIGURE, p.conflict_alarm)
  ES_SESSION_PARAMETERS(ES_BIND_RECONFIGURE, p.session)
  ES_LOCALIZATION_PARAMETERS(ES_BIND_RECONFIGURE, p.localization)
  ES_NODE_PARAMETERS(ES_BIND_RECONFIGURE, p)
}

}  // namespace

bool parameterText(XmlRpc::XmlRpcValue& value, std::string* text) {
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

bool NodeParams::isValid(std::string* why) const {
  auto fail = [why](const std::string& what) {
    if (why != nullptr) *why = what;
    return false;
  };
  if (!Parameters::isValid(why)) return false;
  bool ok = true;
  ES_NODE_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (!ok) return false;
  if (map_frame.empty() || odom_frame.empty() || base_frame.empty()) {
    return fail("map_frame, odom_frame and base_frame must not be empty");
  }
  if (map_frame == odom_frame) return fail("map_frame and odom_frame must differ");
  return true;
}

bool readParams(const ros::NodeHandle& nh, NodeParams* params, std::string* why,
                std::vector<std::string>* unknown) {
  bool ok = true;
  std::vector<std::string> known;
  forEachNodeParameter(*params, [&](const ParameterSpec& spec, auto& field) {
    known.push_back(spec.name);
    XmlRpc::XmlRpcValue value;
    if (!ok || !nh.getParam(spec.name, value)) return;
    std::string text;
    if (!parameterText(value, &text)) {
      ok = false;
      if (why != nullptr) *why = std::string(spec.name) + " must be a single value";
      return;
    }
    ok = parseParameter(spec, text, &field, why);
  });
  if (unknown != nullptr) {
    std::vector<std::string> names;
    const std::string prefix = nh.getNamespace() + "/";
    if (ros::param::getParamNames(names)) {
      for (const std::string& n : names) {
        if (n.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string name = n.substr(prefix.size());
        bool is_known = false;
        for (const std::string& k : known) is_known = is_known || name == k;
        if (!is_known) unknown->push_back(name);
      }
    }
  }
  return ok;
}

EvidentialSlamConfig toReconfigure(const NodeParams& params) {
  NodeParams p = params;
  EvidentialSlamConfig cfg = EvidentialSlamConfig::__getDefault__();
  forEachReconfigurable(p, cfg, [](auto& field, auto& cfg_field) { cfg_field = field; });
  return cfg;
}

void applyReconfigure(const EvidentialSlamConfig& config, NodeParams* params) {
  EvidentialSlamConfig cfg = config;
  forEachReconfigurable(*params, cfg, [](auto& field, auto& cfg_field) { field = cfg_field; });
}

}  // namespace ros_adapter
}  // namespace evidential_slam
