#include "evidential_slam/ros/exploration_conversions.h"

#include <cmath>

#include "evidential_slam/core/measures.h"
#include "evidential_slam/ros/conversions.h"

namespace evidential_slam {
namespace ros_adapter {

bool layerRasterFromMsg(const EvidentialGrid& msg, LayerRaster* out, std::string* why) {
  auto fail = [why](const std::string& what) {
    if (why != nullptr) *why = what;
    return false;
  };
  const size_t cells = static_cast<size_t>(msg.info.width) * msg.info.height;
  if (msg.layers.size() != msg.data.size()) {
    return fail("grid: " + std::to_string(msg.layers.size()) + " layer names for " +
                std::to_string(msg.data.size()) + " layers");
  }
  if (msg.observed.size() != cells) {
    return fail("grid: 'observed' holds " + std::to_string(msg.observed.size()) +
                " cells, not width x height = " + std::to_string(cells));
  }
  LayerRaster r;
  r.resolution = msg.info.resolution;
  r.origin_x = msg.info.origin.position.x;
  r.origin_y = msg.info.origin.position.y;
  r.width = static_cast<int>(msg.info.width);
  r.height = static_cast<int>(msg.info.height);
  for (int l = 0; l < kLayerCount; ++l) {
    const std::string& name = layerNames()[l];
    size_t k = 0;
    while (k < msg.layers.size() && msg.layers[k] != name) ++k;
    if (k == msg.layers.size()) return fail("grid: no layer '" + name + "'");
    if (msg.data[k].data.size() != cells) {
      return fail("grid: layer '" + name + "' holds " + std::to_string(msg.data[k].data.size()) +
                  " cells, not width x height = " + std::to_string(cells));
    }
    r.values[l] = msg.data[k].data;
  }
  r.observed = msg.observed;
  *out = std::move(r);
  return true;
}

void toTrinaryGrid(const LayerRaster& raster, const std::vector<exploration::CellClass>& classes,
                   const std_msgs::Header& header, nav_msgs::OccupancyGrid* out) {
  out->header = header;
  out->info = mapMetaData(raster, header.stamp);
  out->data.resize(classes.size());
  for (size_t i = 0; i < classes.size(); ++i) {
    switch (classes[i]) {
      case exploration::CellClass::kOccupied:
        out->data[i] = 100;
        break;
      case exploration::CellClass::kFree:
        out->data[i] = 0;
        break;
      default:
        out->data[i] = -1;
    }
  }
}

void toPathMsg(const std::vector<Eigen::Vector2d>& points, const std_msgs::Header& header,
               nav_msgs::Path* out) {
  out->header = header;
  out->poses.clear();
  double yaw = 0.0;
  for (size_t k = 0; k < points.size(); ++k) {
    if (k + 1 < points.size()) {
      const Eigen::Vector2d d = points[k + 1] - points[k];
      if (d.squaredNorm() > 0.0) yaw = std::atan2(d.y(), d.x());
    }
    geometry_msgs::PoseStamped p;
    p.header = header;
    p.pose = toPoseMsg(Pose2(points[k].x(), points[k].y(), yaw));
    out->poses.push_back(p);
  }
}

void toFrontierMarkers(const std::vector<exploration::Frontier>& frontiers, int chosen,
                       const exploration::GridGeometry& geometry, const std_msgs::Header& header,
                       visualization_msgs::MarkerArray* out) {
  out->markers.clear();
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out->markers.push_back(clear);
  for (size_t k = 0; k < frontiers.size(); ++k) {
    const exploration::Frontier& f = frontiers[k];
    std_msgs::ColorRGBA color;
    color.a = 1.0f;
    if (static_cast<int>(k) == chosen) {
      color.g = 0.9f;
    } else if (f.revisit) {
      color.r = 1.0f, color.g = 0.5f;
    } else if (f.reachable) {
      color.g = 0.4f, color.b = 1.0f;
    } else {
      color.r = color.g = color.b = 0.5f;
    }
    visualization_msgs::Marker cells;
    cells.header = header;
    cells.ns = "frontiers";
    cells.id = static_cast<int>(k);
    cells.type = visualization_msgs::Marker::POINTS;
    cells.action = visualization_msgs::Marker::ADD;
    cells.pose.orientation.w = 1.0;
    cells.scale.x = cells.scale.y = geometry.resolution;
    cells.color = color;
    for (int i : f.cells) {
      const Eigen::Vector2d c = geometry.center(i);
      geometry_msgs::Point p;
      p.x = c.x(), p.y = c.y();
      cells.points.push_back(p);
    }
    out->markers.push_back(cells);
    if (f.goal_cell < 0) continue;
    visualization_msgs::Marker goal;
    goal.header = header;
    goal.ns = "goals";
    goal.id = static_cast<int>(k);
    goal.type = visualization_msgs::Marker::SPHERE;
    goal.action = visualization_msgs::Marker::ADD;
    goal.pose.position.x = f.goal.x();
    goal.pose.position.y = f.goal.y();
    goal.pose.orientation.w = 1.0;
    goal.scale.x = goal.scale.y = goal.scale.z = 0.25;
    goal.color = color;
    out->markers.push_back(goal);
  }
}

}  // namespace ros_adapter
}  // namespace evidential_slam
