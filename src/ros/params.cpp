#include "evidential_slam/ros/params.h"
#include "evidential_slam/EvidentialSlamConfig.h"
#include "evidential_slam/ros/gmapping_names.h"
#include "evidential_slam/ros/parameter_rows.h"
#include "evidential_slam/ros/parameter_text.h"

#include <cstdio>

#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace evidential_slam {
namespace ros_adapter {
namespace {

// The run-time rows bound to their field of the generated dynamic_reconfigure struct:
// visit(field, cfg_field). Start-up rows have no cfg field.
#define ES_BIND_RECONFIGURE(ctx, name, member, type, def, min, max, unit, scope, tier, meaning) \
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

NodeParams::NodeParams() { ES_NODE_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

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
  if (mode != "slam" && mode != "localization") {
    return fail("mode must be slam or localization, not '" + mode + "'");
  }
  if (mode == "localization" && map_file.empty()) {
    return fail("mode localization needs map_file (the saved map to localize on)");
  }
  return true;
}

namespace {

// Exact (what the parser reads) or short (what the log shows).
std::string numberText(double v, bool exact = true) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), exact ? "%.17g" : "%g", v);
  return buffer;
}

// Sets `field` (the parameter `spec`) from gmapping's `row` given as `value`. A value that is not
// a number, or out of our range once converted, is reported and leaves the field as it was.
template <typename Field>
void readGmappingName(const GmappingName& row, const ParameterSpec& spec,
                      XmlRpc::XmlRpcValue& value, Field* field, GmappingReport* report) {
  double theirs = 0.0;
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    theirs = static_cast<int>(value);
  } else if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    theirs = static_cast<double>(value);
  } else {
    report->refused.push_back(std::string("gmapping's ") + row.theirs + " must be a number; " +
                              spec.name + " keeps its value");
    return;
  }
  const double ours = convertGmappingValue(row, theirs);
  const std::string text = numberText(ours);
  Field converted = *field;
  std::string why;
  if (!parseParameter(spec, text, &converted, &why)) {
    report->refused.push_back(std::string("gmapping's ") + row.theirs + " = " +
                              numberText(theirs, false) + " refused (" + why + "); " + spec.name +
                              " keeps its value");
    return;
  }
  *field = converted;
  report->used.push_back(std::string(row.theirs) + " -> " + spec.name + " = " +
                         numberText(ours, false));
}

}  // namespace

bool readParams(const ros::NodeHandle& nh, NodeParams* params, std::string* why,
                std::vector<std::string>* unknown, GmappingReport* gmapping) {
  bool ok = true;
  GmappingReport report;
  std::vector<std::string> known;
  forEachNodeParameter(*params, [&](const ParameterSpec& spec, auto& field) {
    known.push_back(spec.name);
    XmlRpc::XmlRpcValue value;
    if (!ok) return;
    if (!nh.getParam(spec.name, value)) {
      // slam_gmapping's name for it, when ours is not given.
      for (const GmappingName& row : gmappingNames()) {
        const bool converts = row.conversion == GmappingName::Conversion::kLinear ||
                              row.conversion == GmappingName::Conversion::kSquare;
        if (converts && spec.name == std::string(row.ours) && nh.getParam(row.theirs, value)) {
          readGmappingName(row, spec, value, &field, &report);
        }
      }
      return;
    }
    ok = parseServerValue(spec, value, &field, why);
  });
  for (const GmappingName& row : gmappingNames()) {
    if (!nh.hasParam(row.theirs)) continue;
    if (row.conversion == GmappingName::Conversion::kNone) {
      report.ignored.push_back(row.theirs);
    } else if (row.conversion != GmappingName::Conversion::kSame && nh.hasParam(row.ours)) {
      report.shadowed.push_back(std::string(row.theirs) + " (" + row.ours + " is given)");
    }
  }
  if (gmapping != nullptr) *gmapping = report;
  if (unknown != nullptr) {
    std::vector<std::string> names;
    const std::string prefix = nh.getNamespace() + "/";
    if (ros::param::getParamNames(names)) {
      for (const std::string& n : names) {
        if (n.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string name = n.substr(prefix.size());
        bool is_known = findGmappingName(name) != nullptr;
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
