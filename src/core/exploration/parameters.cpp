#include "evidential_slam/core/exploration/parameters.h"

#include "evidential_slam/core/exploration/parameter_rows.h"

namespace evidential_slam {
namespace exploration {

std::vector<ParameterSpec> explorerParameterSpecs() {
  std::vector<ParameterSpec> specs;
  ExplorerConfig scratch;
  forEachExplorerParameter(scratch,
                           [&specs](const ParameterSpec& spec, auto&) { specs.push_back(spec); });
  return specs;
}

bool setExplorerParameter(const std::string& name, const std::string& value, ExplorerConfig* config,
                          std::string* why) {
  bool found = false, ok = false;
  forEachExplorerParameter(*config, [&](const ParameterSpec& spec, auto& field) {
    if (found || name != spec.name) return;
    found = true;
    ok = parseParameter(spec, value, &field, why);
  });
  if (!found && why != nullptr) *why = "unknown explorer parameter '" + name + "'";
  return found && ok;
}

std::vector<std::pair<std::string, std::string>> explorerParameterValues(
    const ExplorerConfig& config) {
  std::vector<std::pair<std::string, std::string>> values;
  forEachExplorerParameter(config, [&values](const ParameterSpec& spec, const auto& field) {
    values.emplace_back(spec.name, valueText(field));
  });
  return values;
}

}  // namespace exploration
}  // namespace evidential_slam
