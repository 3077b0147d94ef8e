#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/parameter_rows.h"

#include <algorithm>

namespace evidential_slam {
namespace {

bool refuse(std::string* why, const std::string& what) {
  if (why != nullptr) *why = what;
  return false;
}

#define ES_NODE_PARAMETER_NAME(ctx, name, ...) #name,
const char* const kNodeParameterNames[] = {ES_NODE_PARAMETERS(ES_NODE_PARAMETER_NAME, )};
#undef ES_NODE_PARAMETER_NAME

}  // namespace

SessionConfig::SessionConfig() { ES_SESSION_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool SessionConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_SESSION_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (ok && !(free_thresh < occupied_thresh)) {
    return refuse(why, "free_thresh must be below occupied_thresh");
  }
  if (ok && octomap_z_min > octomap_z_max) {
    return refuse(why, "octomap_z_min must not be above octomap_z_max");
  }
  return ok;
}

bool Parameters::isValid(std::string* why) const {
  return slam.isValid(why) && conflict_alarm.isValid(why) && session.isValid(why) &&
         localization.isValid(why);
}

std::vector<ParameterSpec> sharedParameterSpecs() {
  std::vector<ParameterSpec> specs;
  Parameters scratch;
  forEachSharedParameter(scratch,
                         [&specs](const ParameterSpec& spec, auto&) { specs.push_back(spec); });
  return specs;
}

#define ES_NODE_PARAMETER_MAX(ctx, name, member, type, def, min, max, unit, scope, tier, meaning) \
  if (std::string(#name) == (ctx)) return static_cast<double>(max);
double maxDeclaredRangeSigma() {
  static const double limit = []() -> double {
    ES_NODE_PARAMETERS(ES_NODE_PARAMETER_MAX, "laser_range_sigma")
    return 0.0;
  }();
  return limit;
}
#undef ES_NODE_PARAMETER_MAX

float clampDeclaredRangeSigma(double sigma) {
  if (!(sigma > 0.0)) return 0.0f;  // NaN, negative, zero: unknown
  return static_cast<float>(std::min(sigma, maxDeclaredRangeSigma()));
}

bool isNodeParameter(const std::string& name) {
  for (const char* n : kNodeParameterNames) {
    if (name == n) return true;
  }
  return false;
}

bool setParameter(const std::string& name, const std::string& value, Parameters* params,
                  std::string* why) {
  bool found = false, ok = false;
  forEachSharedParameter(*params, [&](const ParameterSpec& spec, auto& field) {
    if (found || name != spec.name) return;
    found = true;
    ok = parseParameter(spec, value, &field, why);
  });
  if (found) return ok;
  if (isNodeParameter(name)) {
    return refuse(why, "'" + name + "' is a parameter of the ROS node only");
  }
  return refuse(why, "unknown parameter '" + name + "'");
}

std::vector<std::pair<std::string, std::string>> parameterValues(const Parameters& p) {
  std::vector<std::pair<std::string, std::string>> values;
  forEachSharedParameter(p, [&values](const ParameterSpec& spec, const auto& field) {
    values.emplace_back(spec.name, valueText(field));
  });
  return values;
}

}  // namespace evidential_slam
