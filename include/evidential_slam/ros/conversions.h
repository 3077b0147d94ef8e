// ROS messages <-> core types, as free functions (no state, no node handles), so the nodelet stays
// thin and each conversion is tested on its own.
#pragma once

#include <string>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/Header.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace ros_adapter {

// Planar part of a 3-D transform: x, y and the yaw of the rotated x axis. `upside_down` is set
// when the frame's z axis points down (a laser mounted upside down sweeps clockwise).
Pose2 pose2FromTransform(const geometry_msgs::Transform& t, bool* upside_down = nullptr);
geometry_msgs::Transform toTransformMsg(const Pose2& pose);
// `pose` of `child` in `parent` at `stamp`, ready for a tf broadcaster.
geometry_msgs::TransformStamped toTransformStamped(const Pose2& pose, const ros::Time& stamp,
                                                   const std::string& parent,
                                                   const std::string& child);
geometry_msgs::Pose toPoseMsg(const Pose2& pose);
Pose2 pose2FromPoseMsg(const geometry_msgs::Pose& pose);

// Smallest |angle_increment| taken for a scan (rad): 1e-6 rad is over six million rays a turn.
constexpr double kMinAngleIncrement = 1e-6;

// True when `msg` can be a scan: 1 to `max_rays` ranges, finite angles, |angle_increment| of at
// least kMinAngleIncrement going from angle_min towards angle_max, at most one turn, as many ranges
// as the angles imply (give or take one), intensities empty or one per range, 0 <= range_min <
// range_max, both finite. Else false and `why` names the field and what is wrong with it.
bool checkLaserScan(const sensor_msgs::LaserScan& msg, int max_rays, std::string* why);

// sensor_msgs/LaserScan -> core scan, by REP-117: +inf (and readings beyond range_max) are
// "no return" rays; NaN, -inf and readings below range_min are bad data the core skips.
// `laser_in_base` is the laser's pose on the robot (from tf); with `upside_down` the bearings are
// mirrored. False (and `why`) when checkLaserScan refuses the message.
bool scanFromRos(const sensor_msgs::LaserScan& msg, const Pose2& laser_in_base, bool upside_down,
                 float range_sigma, LaserScan* out, std::string* why, int max_rays = 100000);

// Core scan -> sensor_msgs/LaserScan (evenly spaced bearings; rays flagged "no return" become
// +inf). False (and `why`) when the bearings are not evenly spaced within `tolerance` rad.
bool scanToRos(const LaserScan& scan, const std::string& frame_id, sensor_msgs::LaserScan* out,
               std::string* why, double tolerance = 1e-4);

// The raster's geometry as nav_msgs/MapMetaData (origin at the corner of cell (0, 0)).
nav_msgs::MapMetaData mapMetaData(const LayerRaster& raster, const ros::Time& load_time);

// Every layer, as floats, into one message (layout in msg/EvidentialGrid.msg).
void toEvidentialGridMsg(const LayerRaster& raster, const std_msgs::Header& header,
                         EvidentialGrid* out);

// How a layer is rendered as a 0..100 OccupancyGrid.
struct OccupancyRendering {
  double full_scale = 1.0;  // layer value drawn as 100 (EC: its display maximum)
};
// The rendering of `layer` on ~layers/<name>: values in [0, 1] (masses, BetP, NS, and IC and H in
// bits over a two-element frame) scale by 100; EC and the anomaly by 100 /
// external_conflict_display_max.
OccupancyRendering layerRendering(Layer layer, double external_conflict_display_max);
void toOccupancyGrid(const LayerRaster& raster, Layer layer, const OccupancyRendering& rendering,
                     const std_msgs::Header& header, nav_msgs::OccupancyGrid* out);
// The `map` topic and `dynamic_map`: trinary like gmapping's map and map_server's trinary mode,
// which amcl and costmap_2d read: 100 where BetP(o) > occupied_thresh, 0 where BetP(o) <
// free_thresh, -1 elsewhere and wherever the cell was never observed.
void toTrinaryOccupancyGrid(const LayerRaster& raster, double occupied_thresh, double free_thresh,
                            const std_msgs::Header& header, nav_msgs::OccupancyGrid* out);

// EvidentialGrid -> the layer raster it was made from (the layers the message names, in any
// order). `frame` gets the raster's frame in the message's frame: the origin's pose when it is
// turned (the raster's origin is then 0, 0), else the identity (the origin is the raster's). False
// (and a one-line `why`) for a message that is no evidential grid: a non-positive resolution, a
// layer of the wrong size, a missing occupied, free, unknown or external_conflict layer.
bool layerRasterFromMsg(const EvidentialGrid& msg, LayerRaster* raster, Pose2* frame,
                        std::string* why);

}  // namespace ros_adapter
}  // namespace evidential_slam
