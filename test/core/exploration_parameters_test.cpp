// The explorer's rows of the parameter table: every row settable by name at its range's ends,
// defaults within range, names unique and distinct from the SLAM's, values read back as set.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "evidential_slam/core/exploration/parameters.h"

namespace evidential_slam {
namespace exploration {
namespace {

TEST(ExplorerParameters, EveryRowIsSettableWithinItsRange) {
  const std::vector<ParameterSpec> specs = explorerParameterSpecs();
  EXPECT_GT(specs.size(), 30u);
  std::map<std::string, std::string> defaults;
  for (const auto& [name, value] : explorerParameterValues(ExplorerConfig())) {
    defaults[name] = value;
  }
  EXPECT_EQ(defaults.size(), specs.size());  // unique names
  std::set<std::string> slam_names;
  for (const ParameterSpec& spec : sharedParameterSpecs()) slam_names.insert(spec.name);
  for (const ParameterSpec& spec : specs) {
    EXPECT_EQ(slam_names.count(spec.name), 0u) << spec.name << " is also a SLAM parameter";
    const std::string type = spec.type;
    std::vector<std::string> values;
    if (type == "bool") {
      values = {"true", "false"};
    } else if (type == "std::string") {
      values = {defaults[spec.name]};
    } else {
      char lo[40], hi[40];
      std::snprintf(lo, sizeof(lo), "%.17g", spec.min);
      std::snprintf(hi, sizeof(hi), "%.17g", spec.max);
      values = {lo, hi};
      const double d = std::stod(defaults[spec.name]);
      EXPECT_GE(d, spec.min) << spec.name;
      EXPECT_LE(d, spec.max) << spec.name;
    }
    for (const std::string& v : values) {
      ExplorerConfig c;
      std::string why;
      EXPECT_TRUE(setExplorerParameter(spec.name, v, &c, &why)) << spec.name << "=" << v << ": "
                                                                << why;
      for (const auto& [name, value] : explorerParameterValues(c)) {
        if (name != spec.name) continue;
        if (type == "bool" || type == "std::string") {
          EXPECT_EQ(value, v) << spec.name;
        } else {
          EXPECT_DOUBLE_EQ(std::stod(value), std::stod(v)) << spec.name;
        }
      }
    }
  }
  std::string why;
  EXPECT_TRUE(ExplorerConfig().isValid(&why)) << why;
}

TEST(ExplorerParameters, BadNamesAndValuesAreRefusedWithAReason) {
  ExplorerConfig c;
  std::string why;
  EXPECT_FALSE(setExplorerParameter("particles", "10", &c, &why));
  EXPECT_EQ(why, "unknown explorer parameter 'particles'");
  EXPECT_FALSE(setExplorerParameter("gain_rays", "2", &c, &why));
  EXPECT_EQ(why, "gain_rays must be in [4, 10000]");
  EXPECT_EQ(c.frontiers.gain_rays, ExplorerConfig().frontiers.gain_rays);
  EXPECT_FALSE(setExplorerParameter("lookahead", "far", &c, &why));
  EXPECT_EQ(why, "lookahead wants a number, not 'far'");
  EXPECT_TRUE(setExplorerParameter("strategy", "frontier", &c, &why)) << why;
  EXPECT_EQ(c.frontiers.kind(), Strategy::kFrontier);
  EXPECT_TRUE(setExplorerParameter("strategy", "nearest", &c, &why)) << why;
  EXPECT_FALSE(c.isValid(&why));  // the name is checked with the config
  EXPECT_EQ(why, "strategy must be ns, entropy or frontier, not 'nearest'");
  c = ExplorerConfig();
  EXPECT_TRUE(setExplorerParameter("unknown_ns", "0.3", &c, &why)) << why;
  EXPECT_FALSE(c.isValid(&why));
  EXPECT_EQ(why, "unknown_ns must not be below free_ns");
}

}  // namespace
}  // namespace exploration
}  // namespace evidential_slam
