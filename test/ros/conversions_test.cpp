// Tests of the ROS <-> core converters (conversions.h), with hand-made messages.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "evidential_slam/ros/conversions.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

sensor_msgs::LaserScan fiveRayScan() {
  sensor_msgs::LaserScan m;
  m.header.stamp.fromSec(12.5);
  m.header.frame_id = "laser";
  m.angle_min = -0.2f;
  m.angle_increment = 0.1f;
  m.angle_max = 0.2f;
  m.range_min = 0.1f;
  m.range_max = 10.0f;
  m.ranges = {1.0f, kNaN, kInf, 0.05f, 12.0f};
  return m;
}

// REP-117: a plain reading stays; NaN and below-range_min are bad data (NaN for the core);
// +inf and beyond range_max are "no return" rays (valid = 0, range = range_max).
TEST(Conversions, ScanFromRosFollowsRep117) {
  LaserScan s;
  std::string why;
  ASSERT_TRUE(scanFromRos(fiveRayScan(), Pose2(0.2, 0.0, 0.0), false, 0.01f, &s, &why)) << why;
  EXPECT_DOUBLE_EQ(s.stamp, 12.5);
  EXPECT_FLOAT_EQ(s.max_range, 10.0f);
  EXPECT_FLOAT_EQ(s.range_sigma, 0.01f);
  EXPECT_DOUBLE_EQ(s.sensor_pose.x, 0.2);
  ASSERT_EQ(s.size(), 5u);
  EXPECT_FLOAT_EQ(s.ranges[0], 1.0f);
  EXPECT_EQ(s.valid[0], 1);
  EXPECT_TRUE(std::isnan(s.ranges[1]));
  EXPECT_FLOAT_EQ(s.ranges[2], 10.0f);
  EXPECT_EQ(s.valid[2], 0);
  EXPECT_TRUE(std::isnan(s.ranges[3]));
  EXPECT_EQ(s.valid[4], 0);
  EXPECT_NEAR(s.bearings[0], -0.2f, 1e-6);
  EXPECT_NEAR(s.bearings[4], 0.2f, 1e-6);
  EXPECT_TRUE(s.isConsistent(&why)) << why;
}

// Upside down (z axis down), the laser sweeps the other way round: bearings are mirrored.
TEST(Conversions, UpsideDownLaserMirrorsBearings) {
  geometry_msgs::Transform t;
  t.rotation.x = 1.0;  // 180° about x
  t.rotation.w = 0.0;
  bool upside_down = false;
  const Pose2 p = pose2FromTransform(t, &upside_down);
  EXPECT_TRUE(upside_down);
  EXPECT_NEAR(p.theta, 0.0, 1e-12);
  LaserScan s;
  std::string why;
  ASSERT_TRUE(scanFromRos(fiveRayScan(), p, upside_down, 0.0f, &s, &why));
  EXPECT_NEAR(s.bearings[0], 0.2f, 1e-6);
  EXPECT_NEAR(s.bearings[4], -0.2f, 1e-6);
}

TEST(Conversions, ScanFromRosRefusesMessagesThatAreNoScan) {
  LaserScan s;
  std::string why;
  sensor_msgs::LaserScan m = fiveRayScan();
  m.angle_increment = 0.0f;
  EXPECT_FALSE(scanFromRos(m, Pose2(), false, 0.0f, &s, &why));
  EXPECT_NE(why.find("angle_increment"), std::string::npos) << why;
  m = fiveRayScan();
  m.ranges.clear();
  EXPECT_FALSE(scanFromRos(m, Pose2(), false, 0.0f, &s, &why));
  m = fiveRayScan();
  m.range_max = kNaN;
  EXPECT_FALSE(scanFromRos(m, Pose2(), false, 0.0f, &s, &why));
  EXPECT_NE(why.find("range_max"), std::string::npos) << why;
}

// Every malformed LaserScan of issue 36 is refused, and the reason names the field.
TEST(Conversions, MalformedScansAreRefusedNamingTheField) {
  struct Case {
    const char* what;
    std::function<void(sensor_msgs::LaserScan*)> spoil;
    const char* field;
  };
  const std::vector<Case> cases = {
      {"more ranges than the angles imply",
       [](auto* m) {
         m->ranges.push_back(1.0f);
         m->ranges.push_back(1.0f);
       },
       "ranges"},
      {"fewer ranges", [](auto* m) { m->ranges.resize(2); }, "ranges"},
      {"negative increment", [](auto* m) { m->angle_increment = -0.1f; }, "angle_increment"},
      {"1e-30 increment", [](auto* m) { m->angle_increment = 1e-30f; }, "angle_increment"},
      {"100,000 beams",
       [](auto* m) {
         m->ranges.assign(100000, 1.0f);
         m->angle_increment = 6.0f / 100000;
         m->angle_min = -3.0f;
         m->angle_max = 3.0f;
       },
       "max_scan_rays"},
      {"a span of 2e6 rad",
       [](auto* m) {
         m->angle_min = -1e6f;
         m->angle_max = 1e6f;
       },
       "angle_max - angle_min"},
      {"NaN angle_max", [](auto* m) { m->angle_max = kNaN; }, "angle_max"},
      {"inf angle_min", [](auto* m) { m->angle_min = -kInf; }, "angle_min"},
      {"intensities of another length", [](auto* m) { m->intensities.assign(3, 1.0f); },
       "intensities"},
      {"range_max below range_min", [](auto* m) { m->range_max = 0.05f; }, "range_max"},
      {"range_max equal to range_min", [](auto* m) { m->range_max = m->range_min; }, "range_max"},
      {"negative range_min", [](auto* m) { m->range_min = -1.0f; }, "range_min"},
      {"no ranges", [](auto* m) { m->ranges.clear(); }, "ranges"},
  };
  for (const Case& c : cases) {
    sensor_msgs::LaserScan m = fiveRayScan();
    c.spoil(&m);
    LaserScan s;
    std::string why;
    EXPECT_FALSE(scanFromRos(m, Pose2(), false, 0.0f, &s, &why, 10000)) << c.what;
    EXPECT_NE(why.find(c.field), std::string::npos) << c.what << ": " << why;
  }
  // Accepted: intensities one per range, angle_max one step beyond the last ray, and a clockwise
  // scan (negative increment from angle_min down to angle_max).
  sensor_msgs::LaserScan m = fiveRayScan();
  m.intensities.assign(5, 1.0f);
  m.angle_max = 0.3f;
  LaserScan s;
  std::string why;
  EXPECT_TRUE(scanFromRos(m, Pose2(), false, 0.0f, &s, &why, 10000)) << why;
  m = fiveRayScan();
  m.angle_min = 0.2f;
  m.angle_max = -0.2f;
  m.angle_increment = -0.1f;
  EXPECT_TRUE(scanFromRos(m, Pose2(), false, 0.0f, &s, &why, 10000)) << why;
}

// Core -> ROS -> core keeps ranges, bearings and no-return flags.
TEST(Conversions, ScanRoundTrip) {
  LaserScan core;
  core.stamp = 3.25;
  core.max_range = 8.0f;
  for (int i = 0; i < 7; ++i) {
    core.bearings.push_back(-0.3f + 0.1f * i);
    core.ranges.push_back(1.0f + i);
    core.valid.push_back(i == 5 ? 0 : 1);
  }
  core.ranges[5] = 8.0f;
  sensor_msgs::LaserScan msg;
  std::string why;
  ASSERT_TRUE(scanToRos(core, "laser", &msg, &why)) << why;
  EXPECT_EQ(msg.header.frame_id, "laser");
  EXPECT_TRUE(std::isinf(msg.ranges[5]));
  LaserScan back;
  ASSERT_TRUE(scanFromRos(msg, Pose2(), false, 0.0f, &back, &why)) << why;
  EXPECT_DOUBLE_EQ(back.stamp, 3.25);
  for (size_t i = 0; i < 7; ++i) {
    EXPECT_NEAR(back.bearings[i], core.bearings[i], 1e-6) << i;
    EXPECT_EQ(back.valid[i], core.valid[i]) << i;
    if (core.valid[i]) {
      EXPECT_FLOAT_EQ(back.ranges[i], core.ranges[i]) << i;
    }
  }
  core.bearings[3] += 0.01f;  // uneven spacing cannot be a LaserScan
  EXPECT_FALSE(scanToRos(core, "laser", &msg, &why));
}

TEST(Conversions, PoseRoundTrip) {
  const Pose2 p(1.5, -2.0, 2.5);
  const Pose2 back = pose2FromPoseMsg(toPoseMsg(p));
  EXPECT_NEAR(back.x, 1.5, 1e-12);
  EXPECT_NEAR(back.y, -2.0, 1e-12);
  EXPECT_NEAR(back.theta, 2.5, 1e-12);
  bool upside_down = true;
  pose2FromTransform(toTransformMsg(p), &upside_down);
  EXPECT_FALSE(upside_down);
}

// A 2 x 1 raster: cell 0 observed (m(o) = 0.8, BetP 0.9, EC 1 bit, anomaly 3 bits), cell 1
// never observed.
LayerRaster twoCellRaster() {
  LayerRaster r;
  r.resolution = 0.1;
  r.origin_x = -1.0;
  r.origin_y = 2.0;
  r.width = 2;
  r.height = 1;
  for (auto& v : r.values) v.assign(2, 0.0f);
  r.values[static_cast<int>(Layer::kOccupied)] = {0.8f, 0.0f};
  r.values[static_cast<int>(Layer::kPignistic)] = {0.9f, 0.5f};
  r.values[static_cast<int>(Layer::kExternalConflict)] = {1.0f, 0.0f};
  r.values[static_cast<int>(Layer::kUnknown)] = {0.0f, 1.0f};
  r.values[static_cast<int>(Layer::kAnomaly)] = {3.0f, 0.0f};
  r.observed = {1, 0};
  return r;
}

TEST(Conversions, OccupancyGridRenderings) {
  const LayerRaster r = twoCellRaster();
  std_msgs::Header h;
  h.frame_id = "map";
  nav_msgs::OccupancyGrid g;
  toOccupancyGrid(r, Layer::kPignistic, layerRendering(Layer::kPignistic, 2.0), h, &g);
  EXPECT_EQ(g.info.width, 2u);
  EXPECT_EQ(g.info.height, 1u);
  EXPECT_FLOAT_EQ(g.info.resolution, 0.1f);
  EXPECT_DOUBLE_EQ(g.info.origin.position.x, -1.0);
  EXPECT_DOUBLE_EQ(g.info.origin.position.y, 2.0);
  EXPECT_EQ(g.data, (std::vector<int8_t>{90, 50}));

  // Layer topics show the vacuous value where nothing was seen (m(Θ) = 1 -> 100).
  toOccupancyGrid(r, Layer::kUnknown, layerRendering(Layer::kUnknown, 2.0), h, &g);
  EXPECT_EQ(g.data, (std::vector<int8_t>{0, 100}));
  // EC scales by its display maximum: 1 bit of 2 -> 50.
  toOccupancyGrid(r, Layer::kExternalConflict, layerRendering(Layer::kExternalConflict, 2.0), h,
                  &g);
  EXPECT_EQ(g.data, (std::vector<int8_t>{50, 0}));
  // So does the anomaly, clamped at 100: 3 bits of 4 -> 75, of 2 -> 100.
  toOccupancyGrid(r, Layer::kAnomaly, layerRendering(Layer::kAnomaly, 4.0), h, &g);
  EXPECT_EQ(g.data, (std::vector<int8_t>{75, 0}));
  toOccupancyGrid(r, Layer::kAnomaly, layerRendering(Layer::kAnomaly, 2.0), h, &g);
  EXPECT_EQ(g.data, (std::vector<int8_t>{100, 0}));
}

// The map topic: 100 above occupied_thresh, 0 below free_thresh, -1 between them (the thresholds
// themselves included, as map_server's trinary mode) and wherever nothing was observed. The
// values and thresholds are exact in binary, so the float layer meets them exactly.
TEST(Conversions, TrinaryMap) {
  LayerRaster r;
  r.resolution = 0.05;
  r.width = 7;
  r.height = 1;
  for (auto& v : r.values) v.assign(7, 0.0f);
  r.values[static_cast<int>(Layer::kPignistic)] = {0.9f, 0.76f, 0.75f, 0.5f, 0.25f, 0.24f, 0.9f};
  r.observed = {1, 1, 1, 1, 1, 1, 0};
  std_msgs::Header h;
  h.frame_id = "map";
  nav_msgs::OccupancyGrid g;
  toTrinaryOccupancyGrid(r, 0.75, 0.25, h, &g);
  EXPECT_EQ(g.header.frame_id, "map");
  EXPECT_EQ(g.info.width, 7u);
  EXPECT_EQ(g.data, (std::vector<int8_t>{100, 100, -1, -1, -1, 0, -1}));
  toTrinaryOccupancyGrid(r, 0.95, 0.625, h, &g);
  EXPECT_EQ(g.data, (std::vector<int8_t>{-1, -1, -1, 0, 0, 0, -1}));
}

TEST(Conversions, EvidentialGridMessageHasEveryLayer) {
  const LayerRaster r = twoCellRaster();
  std_msgs::Header h;
  h.frame_id = "map";
  EvidentialGrid m;
  toEvidentialGridMsg(r, h, &m);
  ASSERT_EQ(m.layers.size(), 10u);
  ASSERT_EQ(m.data.size(), 10u);
  EXPECT_EQ(m.layers[0], "occupied");
  EXPECT_EQ(m.layers[8], "entropy");
  EXPECT_EQ(m.layers[9], "anomaly");
  for (const auto& layer : m.data) EXPECT_EQ(layer.data.size(), 2u);
  EXPECT_FLOAT_EQ(m.data[0].data[0], 0.8f);
  EXPECT_EQ(m.observed, (std::vector<uint8_t>{1, 0}));
}

// EvidentialGrid back to its raster: the same layers, origin and observed cells; a turned origin
// becomes the raster's frame; messages that are no grid are refused with a reason.
TEST(Conversions, EvidentialGridMessageBackToItsRaster) {
  const LayerRaster r = twoCellRaster();
  std_msgs::Header h;
  EvidentialGrid m;
  toEvidentialGridMsg(r, h, &m);
  LayerRaster back;
  Pose2 frame(1, 1, 1);
  std::string why;
  ASSERT_TRUE(layerRasterFromMsg(m, &back, &frame, &why)) << why;
  EXPECT_NEAR(back.resolution, 0.1, 1e-7);
  EXPECT_DOUBLE_EQ(back.origin_x, -1.0);
  EXPECT_DOUBLE_EQ(back.origin_y, 2.0);
  EXPECT_EQ(back.width, 2);
  EXPECT_EQ(back.height, 1);
  for (int l = 0; l < kLayerCount; ++l) EXPECT_EQ(back.values[l], r.values[l]) << l;
  EXPECT_EQ(back.observed, r.observed);
  EXPECT_EQ(frame.x, 0.0);
  EXPECT_EQ(frame.theta, 0.0);

  EvidentialGrid turned = m;
  turned.info.origin = toPoseMsg(Pose2(3.0, 4.0, 0.5));
  ASSERT_TRUE(layerRasterFromMsg(turned, &back, &frame, &why)) << why;
  EXPECT_DOUBLE_EQ(back.origin_x, 0.0);
  EXPECT_NEAR(frame.x, 3.0, 1e-12);
  EXPECT_NEAR(frame.theta, 0.5, 1e-12);

  EvidentialGrid bad = m;
  bad.data[1].data.pop_back();  // free
  EXPECT_FALSE(layerRasterFromMsg(bad, &back, &frame, &why));
  EXPECT_NE(why.find("layer free has 1 values for 2 cells"), std::string::npos) << why;
  bad = m;
  bad.layers.pop_back();
  EXPECT_FALSE(layerRasterFromMsg(bad, &back, &frame, &why));
  EXPECT_NE(why.find("layer names"), std::string::npos) << why;
  bad = m;
  bad.info.resolution = 0.0f;
  EXPECT_FALSE(layerRasterFromMsg(bad, &back, &frame, &why));
  EXPECT_NE(why.find("resolution"), std::string::npos) << why;
  bad = m;
  bad.observed.clear();
  EXPECT_FALSE(layerRasterFromMsg(bad, &back, &frame, &why));
  EXPECT_NE(why.find("observed"), std::string::npos) << why;
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
