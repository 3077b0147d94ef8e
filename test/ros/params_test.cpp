// The dynamic_reconfigure file (generated from the parameter table) and the structs that declare
// their fields from the same table agree: every cfg default is the struct's default, every
// run-time row is a cfg field, and parameters survive the round trip through the cfg struct.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <dynamic_reconfigure/Config.h>

#include "evidential_slam/EvidentialSlamConfig.h"
#include "evidential_slam/ros/gmapping_names.h"
#include "evidential_slam/ros/parameter_rows.h"
#include "evidential_slam/ros/params.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

dynamic_reconfigure::Config asMessage(const EvidentialSlamConfig& c) {
  dynamic_reconfigure::Config m;
  c.__toMessage__(m);
  return m;
}

// cfg/EvidentialSlam.cfg's defaults equal NodeParams' (the core's) for every run-time parameter.
TEST(Params, ReconfigureDefaultsAreTheCoreDefaults) {
  const dynamic_reconfigure::Config cfg = asMessage(EvidentialSlamConfig::__getDefault__());
  const dynamic_reconfigure::Config core = asMessage(toReconfigure(NodeParams()));
  ASSERT_EQ(cfg.doubles.size(), core.doubles.size());
  for (size_t i = 0; i < cfg.doubles.size(); ++i) {
    EXPECT_EQ(cfg.doubles[i].name, core.doubles[i].name);
    EXPECT_DOUBLE_EQ(cfg.doubles[i].value, core.doubles[i].value) << cfg.doubles[i].name;
  }
  ASSERT_EQ(cfg.ints.size(), core.ints.size());
  for (size_t i = 0; i < cfg.ints.size(); ++i) {
    EXPECT_EQ(cfg.ints[i].value, core.ints[i].value) << cfg.ints[i].name;
  }
  ASSERT_EQ(cfg.bools.size(), core.bools.size());
  for (size_t i = 0; i < cfg.bools.size(); ++i) {
    EXPECT_EQ(cfg.bools[i].value, core.bools[i].value) << cfg.bools[i].name;
  }
  EXPECT_GT(cfg.doubles.size() + cfg.ints.size() + cfg.bools.size(), 20u);
}

TEST(Params, ReconfigureChangesReachTheCoreConfig) {
  EvidentialSlamConfig c = toReconfigure(NodeParams());
  c.hit_sigma = 0.07;
  c.update_min_distance = 0.2;
  c.scan_matching = false;
  c.weight_beam_stride = 3;
  c.map_update_interval = 1.5;
  c.long_step_distance = 1.2;
  c.conflict_alarm_factor = 6.0;
  c.export_octomap = true;
  NodeParams p;
  applyReconfigure(c, &p);
  EXPECT_DOUBLE_EQ(p.slam.long_step.distance, 1.2);
  EXPECT_DOUBLE_EQ(p.conflict_alarm.threshold_factor, 6.0);
  EXPECT_TRUE(p.session.export_octomap);
  EXPECT_DOUBLE_EQ(p.slam.sensor.hit_sigma, 0.07);
  EXPECT_DOUBLE_EQ(p.slam.update_min_distance, 0.2);
  EXPECT_FALSE(p.slam.matcher.enabled);
  EXPECT_EQ(p.slam.sensor.weight_beam_stride, 3);
  EXPECT_DOUBLE_EQ(p.map_update_interval, 1.5);
  EXPECT_DOUBLE_EQ(toReconfigure(p).hit_sigma, 0.07);
}

// Every run-time row of the table is a dynamic_reconfigure field of that name, and setting it by
// name (the offline runner's --param, config files) sets the same field as the cfg field does;
// the start-up rows are not in the cfg.
TEST(Params, RuntimeParametersAreTheReconfigureFields) {
  const dynamic_reconfigure::Config defaults = asMessage(toReconfigure(NodeParams()));
  std::vector<ParameterSpec> specs;
  NodeParams scratch;
  forEachNodeParameter(scratch,
                       [&specs](const ParameterSpec& spec, auto&) { specs.push_back(spec); });
  size_t runtime = 0;
  for (const ParameterSpec& spec : specs) {
    const std::string name = spec.name;
    dynamic_reconfigure::Config changed = defaults;
    std::string text;
    bool found = false;
    for (auto& d : changed.doubles) {
      if (d.name != name) continue;
      d.value = d.value + 0.125 <= spec.max ? d.value + 0.125 : spec.min;  // exact in binary
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "%.17g", d.value);
      text = buffer;
      found = true;
    }
    for (auto& i : changed.ints) {
      if (i.name != name) continue;
      i.value = i.value + 1 <= spec.max ? i.value + 1 : static_cast<int>(spec.min);
      text = std::to_string(i.value);
      found = true;
    }
    for (auto& b : changed.bools) {
      if (b.name != name) continue;
      b.value = !b.value;
      text = b.value ? "true" : "false";
      found = true;
    }
    for (auto& str : changed.strs) {
      if (str.name != name) continue;
      // Strings have no range to step through: another valid value of each (a new run-time
      // string needs one here).
      static const std::map<std::string, std::string> kOther = {
          {"laser_model_type", "likelihood_field"}};
      const auto other = kOther.find(name);
      if (other != kOther.end()) str.value = other->second;
      text = str.value;
      found = true;
    }
    if (spec.scope == ParameterScope::startup) {
      EXPECT_FALSE(found) << name << " is start-up only but in cfg/EvidentialSlam.cfg";
      continue;
    }
    ++runtime;
    ASSERT_TRUE(found) << name << " is not in cfg/EvidentialSlam.cfg";
    if (isNodeParameter(name)) continue;  // no setParameter for the node's own
    EvidentialSlamConfig cfg = EvidentialSlamConfig::__getDefault__();
    ASSERT_TRUE(cfg.__fromMessage__(changed)) << name;
    NodeParams via_reconfigure;
    applyReconfigure(cfg, &via_reconfigure);
    NodeParams via_name;
    std::string why;
    ASSERT_TRUE(setParameter(name, text, &via_name, &why)) << why;
    EXPECT_EQ(parameterValues(via_reconfigure), parameterValues(via_name)) << name;
    EXPECT_NE(parameterValues(via_name), parameterValues(NodeParams())) << name;
  }
  const size_t fields =
      defaults.doubles.size() + defaults.ints.size() + defaults.bools.size() + defaults.strs.size();
  EXPECT_EQ(fields, runtime);  // and nothing else in the cfg
  EXPECT_GT(runtime, 50u);
}

TEST(Params, Validation) {
  NodeParams p;
  std::string why;
  EXPECT_TRUE(p.isValid(&why)) << why;
  p.map_frame = "odom";
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("differ"), std::string::npos) << why;
  p = NodeParams();
  p.slam.sensor.min_range = 30.0;  // above usable_range: the core refuses it
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("min_range"), std::string::npos) << why;
  p = NodeParams();
  p.map_update_interval = 0.0;
  EXPECT_FALSE(p.isValid(&why));
}

// mode: slam or localization; localization needs map_file. One line each.
TEST(Params, ModeAndItsMap) {
  NodeParams p;
  std::string why;
  EXPECT_EQ(p.mode, "slam");
  p.mode = "amcl";
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_EQ(why, "mode must be slam or localization, not 'amcl'");
  p.mode = "localization";
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_EQ(why, "mode localization needs map_file (the saved map to localize on)");
  p.map_file = "/maps/office";
  EXPECT_TRUE(p.isValid(&why)) << why;
  p.localization.min_particles = 6000;  // above max_particles
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_EQ(why, "min_particles must not be above max_particles");
}

// Every counterpart in the gmapping table is a parameter of ours, and docs/ros.md lists each row.
TEST(Params, GmappingTableNamesOurParametersAndIsDocumented) {
  std::vector<std::string> ours;
  NodeParams p;
  forEachNodeParameter(p, [&](const ParameterSpec& spec, auto&) { ours.push_back(spec.name); });
  std::ifstream in(std::string(ES_TEST_DATA_DIR) + "/../../docs/ros.md");
  ASSERT_TRUE(in.good());
  std::stringstream doc;
  doc << in.rdbuf();
  for (const GmappingName& row : gmappingNames()) {
    const std::string counterpart = row.ours;
    if (row.conversion == GmappingName::Conversion::kNone) {
      EXPECT_TRUE(counterpart.empty()) << row.theirs;
    } else {
      EXPECT_NE(std::find(ours.begin(), ours.end(), counterpart), ours.end()) << row.theirs;
    }
    const std::string line = std::string("| `") + row.theirs + "` | " +
                             (counterpart.empty() ? "not used" : "`" + counterpart + "`") + " |";
    EXPECT_NE(doc.str().find(line), std::string::npos) << line;
  }
  EXPECT_EQ(findGmappingName("maxUrange")->ours, std::string("usable_range"));
  EXPECT_EQ(findGmappingName("usable_range"), nullptr);
}

// Hand-computed conversions: squares for the motion noise (srt halved), lskip + 1.
TEST(Params, GmappingConversions) {
  EXPECT_DOUBLE_EQ(convertGmappingValue(*findGmappingName("srr"), 0.1), 0.01);
  EXPECT_DOUBLE_EQ(convertGmappingValue(*findGmappingName("srt"), 0.2), 0.02);
  EXPECT_DOUBLE_EQ(convertGmappingValue(*findGmappingName("stt"), 0.2), 0.04);
  EXPECT_DOUBLE_EQ(convertGmappingValue(*findGmappingName("lskip"), 0.0), 1.0);
  EXPECT_DOUBLE_EQ(convertGmappingValue(*findGmappingName("maxUrange"), 6.0), 6.0);
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
