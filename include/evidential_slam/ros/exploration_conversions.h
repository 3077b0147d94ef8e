// ROS messages of the explorer <-> core types, as free functions: the SLAM's EvidentialGrid as a
// layer raster, and the explorer's state (trinary map, path, goal, frontiers) as messages.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/exploration/frontiers.h"
#include "evidential_slam/core/layers.h"

namespace evidential_slam {
namespace ros_adapter {

// EvidentialGrid -> raster (every layer, by name). False (and a one-line `why`) when a layer is
// missing or a layer's or `observed`'s size is not width × height.
bool layerRasterFromMsg(const EvidentialGrid& msg, LayerRaster* out, std::string* why);

// The cell classes as a trinary OccupancyGrid, the form explore_lite and move_base read:
// occupied 100, free 0, not yet observed or in between -1.
void toTrinaryGrid(const LayerRaster& raster, const std::vector<exploration::CellClass>& classes,
                   const std_msgs::Header& header, nav_msgs::OccupancyGrid* out);

// A polyline as a path (poses facing along it; the last one as the one before).
void toPathMsg(const std::vector<Eigen::Vector2d>& points, const std_msgs::Header& header,
               nav_msgs::Path* out);

// Markers for rviz, replacing the previous ones (a DELETEALL first): per frontier its cells
// (POINTS, namespace "frontiers") and its goal (SPHERE, "goals"); the frontier being driven to in
// green, the other reachable ones in blue, those unreachable or blacklisted in grey, revisit
// clusters in orange. `chosen` is an index into `frontiers`, or -1.
void toFrontierMarkers(const std::vector<exploration::Frontier>& frontiers, int chosen,
                       const exploration::GridGeometry& geometry, const std_msgs::Header& header,
                       visualization_msgs::MarkerArray* out);

}  // namespace ros_adapter
}  // namespace evidential_slam
