// The map fusion node's parameters (ros/map_fusion_nodelet.h): the defaults are valid, and a value
// the node cannot use is refused with a one-line reason naming it.
#include <gtest/gtest.h>

#include <string>

#include "evidential_slam/ros/map_fusion_nodelet.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

TEST(MapFusionParams, DefaultsAreValidAndBadValuesAreRefused) {
  std::string why;
  EXPECT_TRUE(MapFusionParams().isValid(&why)) << why;
  EXPECT_EQ(MapFusionParams().rule, "cautious");
  EXPECT_TRUE(MapFusionParams().known_init_poses);

  MapFusionParams p;
  p.rule = "max";
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("fusion_rule 'max'"), std::string::npos) << why;

  p = MapFusionParams();
  p.merging_rate = 0.0;
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("merging_rate"), std::string::npos) << why;

  p = MapFusionParams();
  p.discount = 1.5;
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("fusion_discount"), std::string::npos) << why;

  p = MapFusionParams();
  p.world_frame.clear();
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_NE(why.find("world_frame"), std::string::npos) << why;

  p = MapFusionParams();
  p.session.occupied_thresh = 0.1;  // below free_thresh
  EXPECT_FALSE(p.isValid(&why));
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
