// The explorer node's conversions and parameter reading, without a ROS master: the grid message
// back into a raster (and refused when malformed), the trinary map, the path's headings, the
// frontier markers, and the private parameters read through the parameter table's rows.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "evidential_slam/ros/conversions.h"
#include "evidential_slam/ros/exploration_conversions.h"
#include "evidential_slam/ros/explorer_params.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

LayerRaster threeCellRaster() {
  LayerRaster r;
  r.resolution = 0.1;
  r.origin_x = -1.0;
  r.origin_y = 2.0;
  r.width = 3;
  r.height = 1;
  for (int l = 0; l < kLayerCount; ++l) r.values[l] = {0.1f * l, 0.2f, 0.3f};
  r.observed = {1, 1, 0};
  return r;
}

TEST(ExplorationConversions, GridMessageBackIntoTheSameRaster) {
  const LayerRaster in = threeCellRaster();
  std_msgs::Header header;
  header.frame_id = "map";
  EvidentialGrid msg;
  toEvidentialGridMsg(in, header, &msg);
  LayerRaster out;
  std::string why;
  ASSERT_TRUE(layerRasterFromMsg(msg, &out, &why)) << why;
  EXPECT_EQ(out.width, 3);
  EXPECT_EQ(out.height, 1);
  EXPECT_NEAR(out.resolution, 0.1, 1e-6);
  EXPECT_NEAR(out.origin_x, -1.0, 1e-9);
  EXPECT_NEAR(out.origin_y, 2.0, 1e-9);
  for (int l = 0; l < kLayerCount; ++l) EXPECT_EQ(out.values[l], in.values[l]) << l;
  EXPECT_EQ(out.observed, in.observed);
}

TEST(ExplorationConversions, MalformedGridIsRefusedWithAReason) {
  std_msgs::Header header;
  EvidentialGrid msg;
  toEvidentialGridMsg(threeCellRaster(), header, &msg);
  LayerRaster out;
  std::string why;
  EvidentialGrid bad = msg;
  bad.observed.pop_back();
  EXPECT_FALSE(layerRasterFromMsg(bad, &out, &why));
  EXPECT_EQ(why, "grid: 'observed' holds 2 cells, not width x height = 3");
  bad = msg;
  bad.layers[5] = "nonsense";
  EXPECT_FALSE(layerRasterFromMsg(bad, &out, &why));
  EXPECT_EQ(why, "grid: no layer '" + layerNames()[5] + "'");
  bad = msg;
  bad.data[0].data.push_back(0.0f);
  EXPECT_FALSE(layerRasterFromMsg(bad, &out, &why));
  EXPECT_EQ(why, "grid: layer '" + layerNames()[0] + "' holds 4 cells, not width x height = 3");
}

TEST(ExplorationConversions, TrinaryMapIsMinusOneZeroOrHundred) {
  using exploration::CellClass;
  LayerRaster r = threeCellRaster();
  r.width = 4;
  const std::vector<CellClass> classes = {CellClass::kFree, CellClass::kOccupied,
                                          CellClass::kUnknown, CellClass::kUncertain};
  std_msgs::Header header;
  header.frame_id = "map";
  nav_msgs::OccupancyGrid grid;
  toTrinaryGrid(r, classes, header, &grid);
  EXPECT_EQ(grid.data, std::vector<int8_t>({0, 100, -1, -1}));
  EXPECT_EQ(grid.info.width, 4u);
  EXPECT_EQ(grid.header.frame_id, "map");
}

TEST(ExplorationConversions, PathPosesFaceAlongThePath) {
  std_msgs::Header header;
  nav_msgs::Path path;
  toPathMsg({{0, 0}, {1, 0}, {1, 1}}, header, &path);
  ASSERT_EQ(path.poses.size(), 3u);
  EXPECT_NEAR(pose2FromPoseMsg(path.poses[0].pose).theta, 0.0, 1e-12);
  EXPECT_NEAR(pose2FromPoseMsg(path.poses[1].pose).theta, M_PI / 2, 1e-12);
  EXPECT_NEAR(pose2FromPoseMsg(path.poses[2].pose).theta, M_PI / 2, 1e-12);  // as the one before
  EXPECT_DOUBLE_EQ(path.poses[2].pose.position.y, 1.0);
}

TEST(ExplorationConversions, FrontierMarkersClearThenCellsAndGoals) {
  exploration::GridGeometry g;
  g.resolution = 0.5;
  g.width = 4;
  g.height = 4;
  exploration::Frontier chosen, unreachable;
  chosen.cells = {0, 1};
  chosen.goal_cell = 1;
  chosen.goal = {0.75, 0.25};
  chosen.reachable = true;
  unreachable.cells = {15};
  unreachable.goal_cell = -1;
  std_msgs::Header header;
  visualization_msgs::MarkerArray markers;
  toFrontierMarkers({chosen, unreachable}, 0, g, header, &markers);
  ASSERT_EQ(markers.markers.size(), 4u);  // delete-all, 2 x cells, 1 goal
  EXPECT_EQ(markers.markers[0].action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(markers.markers[1].points.size(), 2u);
  EXPECT_FLOAT_EQ(markers.markers[1].color.g, 0.9f);  // chosen: green
  EXPECT_EQ(markers.markers[2].ns, "goals");
  EXPECT_DOUBLE_EQ(markers.markers[2].pose.position.x, 0.75);
  EXPECT_FLOAT_EQ(markers.markers[3].color.r, 0.5f);  // unreachable: grey
}

TEST(ExplorerParams, ReadThroughTheTableAndRefusedWithAReason) {
  std::map<std::string, XmlRpc::XmlRpcValue> server;
  server["strategy"] = XmlRpc::XmlRpcValue(std::string("frontier"));
  server["gain_rays"] = XmlRpc::XmlRpcValue(90);
  server["max_time"] = XmlRpc::XmlRpcValue(120);  // an int where a double is expected
  server["save_map_directory"] = XmlRpc::XmlRpcValue(std::string("/tmp/x"));
  const ParameterLookup lookup = [&server](const std::string& name, XmlRpc::XmlRpcValue* v) {
    auto it = server.find(name);
    if (it == server.end()) return false;
    *v = it->second;
    return true;
  };
  ExplorerNodeParams p;
  std::string why;
  ASSERT_TRUE(readExplorerParams(lookup, &p, &why)) << why;
  EXPECT_TRUE(p.isValid(&why)) << why;
  EXPECT_EQ(p.explorer.frontiers.kind(), exploration::Strategy::kFrontier);
  EXPECT_EQ(p.explorer.frontiers.gain_rays, 90);
  EXPECT_DOUBLE_EQ(p.max_time, 120.0);
  EXPECT_EQ(p.save_map_directory, "/tmp/x");
  EXPECT_EQ(p.map_frame, "map");

  server["gain_rays"] = XmlRpc::XmlRpcValue(2);
  EXPECT_FALSE(readExplorerParams(lookup, &p, &why));
  EXPECT_EQ(why, "gain_rays must be in [4, 10000]");
  server["gain_rays"] = XmlRpc::XmlRpcValue(90);
  server["base_frame"] = XmlRpc::XmlRpcValue(std::string(""));
  p = ExplorerNodeParams();
  EXPECT_FALSE(readExplorerParams(lookup, &p, &why));
  EXPECT_EQ(why, "base_frame must not be empty");
  server.erase("base_frame");
  server["max_time"] = XmlRpc::XmlRpcValue(std::string("soon"));
  EXPECT_FALSE(readExplorerParams(lookup, &p, &why));
  EXPECT_EQ(why, "max_time wants a number, not 'soon'");

  EXPECT_EQ(unknownExplorerParams({"strategy", "particles", "robot_radius", "gain_rays"}),
            std::vector<std::string>({"particles"}));
}

TEST(ExplorationMonitorParams, ReadThroughTheTableAndRefusedWithAReason) {
  std::map<std::string, XmlRpc::XmlRpcValue> server;
  const ParameterLookup lookup = [&server](const std::string& name, XmlRpc::XmlRpcValue* v) {
    auto it = server.find(name);
    if (it == server.end()) return false;
    *v = it->second;
    return true;
  };
  ExplorationMonitorParams p;
  std::string why;
  ASSERT_TRUE(readExplorationMonitorParams(lookup, &p, &why)) << why;  // all defaults
  EXPECT_TRUE(p.isValid(&why)) << why;
  EXPECT_EQ(p.simulator, "gridmap_simulator");
  EXPECT_EQ(p.slam, "evidential_slam");
  EXPECT_EQ(p.out, "");
  EXPECT_DOUBLE_EQ(p.coverage_period, 5.0);
  EXPECT_TRUE(p.wait_for_saved_map);
  EXPECT_TRUE(p.exit_when_done);

  server["out"] = XmlRpc::XmlRpcValue(std::string("/tmp/x"));
  server["coverage_period"] = XmlRpc::XmlRpcValue(2);  // an int where a double is expected
  server["exit_when_done"] = XmlRpc::XmlRpcValue(false);
  ASSERT_TRUE(readExplorationMonitorParams(lookup, &p, &why)) << why;
  EXPECT_EQ(p.out, "/tmp/x");
  EXPECT_DOUBLE_EQ(p.coverage_period, 2.0);
  EXPECT_FALSE(p.exit_when_done);

  server["coverage_period"] = XmlRpc::XmlRpcValue(0.0);
  EXPECT_FALSE(readExplorationMonitorParams(lookup, &p, &why));
  EXPECT_EQ(why, "coverage_period must be in [0.01, 3600] s");
  server["coverage_period"] = XmlRpc::XmlRpcValue(5.0);
  server["simulator"] = XmlRpc::XmlRpcValue(std::string(""));
  EXPECT_FALSE(readExplorationMonitorParams(lookup, &p, &why));
  EXPECT_EQ(why, "simulator must not be empty");
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
