// The dynamic_reconfigure file and the core agree: every cfg default is the core's default, and
// parameters survive the round trip through the generated config struct.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include <dynamic_reconfigure/Config.h>

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
  NodeParams p;
  applyReconfigure(c, &p);
  EXPECT_DOUBLE_EQ(p.slam.sensor.hit_sigma, 0.07);
  EXPECT_DOUBLE_EQ(p.slam.update_min_distance, 0.2);
  EXPECT_FALSE(p.slam.matcher.enabled);
  EXPECT_EQ(p.slam.sensor.weight_beam_stride, 3);
  EXPECT_DOUBLE_EQ(p.map_update_interval, 1.5);
  EXPECT_DOUBLE_EQ(toReconfigure(p).hit_sigma, 0.07);
}

// The offline runner's --param names (core: setSlamParameter) are dynamic_reconfigure names, and
// each sets the same field as the cfg field of that name.
TEST(Params, CoreParameterNamesAreTheReconfigureNames) {
  const dynamic_reconfigure::Config defaults = asMessage(toReconfigure(NodeParams()));
  for (const std::string& name : slamParameterNames()) {
    dynamic_reconfigure::Config changed = defaults;
    std::string text;
    bool found = false;
    for (auto& d : changed.doubles) {
      if (d.name != name) continue;
      d.value += 0.125;  // exact in binary, so the text round trip is exact
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "%.17g", d.value);
      text = buffer;
      found = true;
    }
    for (auto& i : changed.ints) {
      if (i.name != name) continue;
      i.value += 1;
      text = std::to_string(i.value);
      found = true;
    }
    for (auto& b : changed.bools) {
      if (b.name != name) continue;
      b.value = !b.value;
      text = b.value ? "true" : "false";
      found = true;
    }
    ASSERT_TRUE(found) << name << " is not in cfg/EvidentialSlam.cfg";
    EvidentialSlamConfig cfg = EvidentialSlamConfig::__getDefault__();
    ASSERT_TRUE(cfg.__fromMessage__(changed)) << name;
    NodeParams via_reconfigure;
    applyReconfigure(cfg, &via_reconfigure);
    NodeParams via_core;
    std::string why;
    ASSERT_TRUE(setSlamParameter(name, text, &via_core.slam, &why)) << why;
    const dynamic_reconfigure::Config a = asMessage(toReconfigure(via_reconfigure));
    const dynamic_reconfigure::Config b = asMessage(toReconfigure(via_core));
    ASSERT_EQ(a.doubles.size(), b.doubles.size());
    for (size_t i = 0; i < a.doubles.size(); ++i) {
      EXPECT_EQ(a.doubles[i].value, b.doubles[i].value) << name << " vs " << a.doubles[i].name;
    }
    for (size_t i = 0; i < a.ints.size(); ++i) {
      EXPECT_EQ(a.ints[i].value, b.ints[i].value) << name << " vs " << a.ints[i].name;
    }
    for (size_t i = 0; i < a.bools.size(); ++i) {
      EXPECT_EQ(a.bools[i].value, b.bools[i].value) << name << " vs " << a.bools[i].name;
    }
  }
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

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
