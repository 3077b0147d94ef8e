#include "evidential_slam/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2/LinearMath/Vector3.h>

#include "evidential_slam/core/measures.h"
#include "evidential_slam/core/parameters.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

tf2::Quaternion yawQuaternion(double yaw) {
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, yaw);
  return q;
}

}  // namespace

Pose2 pose2FromTransform(const geometry_msgs::Transform& t, bool* upside_down) {
  const tf2::Quaternion q(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w);
  const tf2::Matrix3x3 r(q.normalized());
  const tf2::Vector3 x_axis = r.getColumn(0);
  const tf2::Vector3 z_axis = r.getColumn(2);
  if (upside_down != nullptr) *upside_down = z_axis.z() < 0.0;
  return Pose2(t.translation.x, t.translation.y, std::atan2(x_axis.y(), x_axis.x()));
}

geometry_msgs::Transform toTransformMsg(const Pose2& pose) {
  geometry_msgs::Transform t;
  t.translation.x = pose.x;
  t.translation.y = pose.y;
  t.translation.z = 0.0;
  const tf2::Quaternion q = yawQuaternion(pose.theta);
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  t.rotation.w = q.w();
  return t;
}

geometry_msgs::TransformStamped toTransformStamped(const Pose2& pose, const ros::Time& stamp,
                                                   const std::string& parent,
                                                   const std::string& child) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform = toTransformMsg(pose);
  return t;
}

geometry_msgs::Pose toPoseMsg(const Pose2& pose) {
  const geometry_msgs::Transform t = toTransformMsg(pose);
  geometry_msgs::Pose p;
  p.position.x = t.translation.x;
  p.position.y = t.translation.y;
  p.position.z = t.translation.z;
  p.orientation = t.rotation;
  return p;
}

Pose2 pose2FromPoseMsg(const geometry_msgs::Pose& pose) {
  geometry_msgs::Transform t;
  t.translation.x = pose.position.x;
  t.translation.y = pose.position.y;
  t.translation.z = pose.position.z;
  t.rotation = pose.orientation;
  return pose2FromTransform(t);
}

bool checkLaserScan(const sensor_msgs::LaserScan& msg, int max_rays, std::string* why) {
  auto fail = [why](const std::string& what) {
    if (why != nullptr) *why = what;
    return false;
  };
  auto text = [](double v) {
    char s[32];
    std::snprintf(s, sizeof(s), "%.6g", v);
    return std::string(s);
  };
  const size_t n = msg.ranges.size();
  if (n == 0) return fail("ranges is empty");
  if (n > static_cast<size_t>(max_rays)) {
    return fail("ranges has " + std::to_string(n) + " values, more than max_scan_rays (" +
                std::to_string(max_rays) + ")");
  }
  if (!std::isfinite(msg.angle_min)) return fail("angle_min is " + text(msg.angle_min));
  if (!std::isfinite(msg.angle_max)) return fail("angle_max is " + text(msg.angle_max));
  if (!std::isfinite(msg.angle_increment)) {
    return fail("angle_increment is " + text(msg.angle_increment));
  }
  if (std::abs(msg.angle_increment) < kMinAngleIncrement) {
    return fail("angle_increment " + text(msg.angle_increment) + " rad is (almost) zero");
  }
  const double span = static_cast<double>(msg.angle_max) - msg.angle_min;
  if (std::abs(span) > 2.0 * M_PI + std::abs(msg.angle_increment)) {
    return fail("angle_max - angle_min spans " + text(span) + " rad, more than a turn");
  }
  if (n > 1 && span * msg.angle_increment < 0.0) {
    return fail("angle_increment " + text(msg.angle_increment) + " goes the other way from " +
                "angle_min to angle_max (" + text(msg.angle_min) + " to " + text(msg.angle_max) +
                ")");
  }
  // Drivers disagree on whether angle_max is the last ray's bearing or one step beyond it.
  const double implied = span / msg.angle_increment + 1.0;
  if (std::abs(implied - static_cast<double>(n)) > 1.5) {
    return fail("ranges has " + std::to_string(n) + " values where the angles imply " +
                text(std::round(implied)));
  }
  if (!msg.intensities.empty() && msg.intensities.size() != n) {
    return fail("intensities has " + std::to_string(msg.intensities.size()) + " values for " +
                std::to_string(n) + " ranges");
  }
  if (!std::isfinite(msg.range_min) || msg.range_min < 0.0f) {
    return fail("range_min is " + text(msg.range_min));
  }
  if (!std::isfinite(msg.range_max) || !(msg.range_max > msg.range_min)) {
    return fail("range_max " + text(msg.range_max) + " is not above range_min " +
                text(msg.range_min));
  }
  return true;
}

bool scanFromRos(const sensor_msgs::LaserScan& msg, const Pose2& laser_in_base, bool upside_down,
                 float range_sigma, LaserScan* out, std::string* why, int max_rays) {
  if (!checkLaserScan(msg, max_rays, why)) return false;
  LaserScan& s = *out;
  s = LaserScan();
  s.stamp = msg.header.stamp.toSec();
  s.sensor_pose = laser_in_base;
  s.max_range = msg.range_max;
  s.range_sigma = clampDeclaredRangeSigma(range_sigma);  // the rawlog reader's bound too
  const size_t n = msg.ranges.size();
  s.ranges.resize(n);
  s.bearings.resize(n);
  s.valid.assign(n, 1);
  const float min_range = msg.range_min;
  for (size_t i = 0; i < n; ++i) {
    const double bearing = msg.angle_min + static_cast<double>(i) * msg.angle_increment;
    s.bearings[i] = static_cast<float>(upside_down ? -bearing : bearing);
    const float z = msg.ranges[i];
    if (std::isnan(z) || z == -std::numeric_limits<float>::infinity() || z < min_range) {
      s.ranges[i] = std::numeric_limits<float>::quiet_NaN();  // bad data: skipped by the core
    } else if (z > msg.range_max) {  // +inf or beyond range: no return (REP-117)
      s.ranges[i] = msg.range_max;
      s.valid[i] = 0;
    } else {
      s.ranges[i] = z;
    }
  }
  return true;
}

bool scanToRos(const LaserScan& scan, const std::string& frame_id, sensor_msgs::LaserScan* out,
               std::string* why, double tolerance) {
  auto fail = [why](const std::string& what) {
    if (why != nullptr) *why = what;
    return false;
  };
  std::string inconsistency;
  if (!scan.isConsistent(&inconsistency)) return fail(inconsistency);
  const size_t n = scan.ranges.size();
  if (n < 2) return fail("a LaserScan needs at least two rays");
  const double increment =
      (static_cast<double>(scan.bearings[n - 1]) - scan.bearings[0]) / static_cast<double>(n - 1);
  for (size_t i = 0; i < n; ++i) {
    const double expected = scan.bearings[0] + increment * static_cast<double>(i);
    if (std::abs(scan.bearings[i] - expected) > tolerance) {
      return fail("bearings are not evenly spaced (ray " + std::to_string(i) + ")");
    }
  }
  sensor_msgs::LaserScan& m = *out;
  m = sensor_msgs::LaserScan();
  m.header.stamp.fromSec(scan.stamp);
  m.header.frame_id = frame_id;
  m.angle_min = scan.bearings[0];
  m.angle_max = scan.bearings[n - 1];
  m.angle_increment = static_cast<float>(increment);
  m.range_min = 0.0f;
  m.range_max = scan.max_range;
  m.ranges.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const bool no_return = !scan.valid.empty() && scan.valid[i] == 0;
    m.ranges[i] = no_return ? std::numeric_limits<float>::infinity() : scan.ranges[i];
  }
  return true;
}

nav_msgs::MapMetaData mapMetaData(const LayerRaster& raster, const ros::Time& load_time) {
  nav_msgs::MapMetaData info;
  info.map_load_time = load_time;
  info.resolution = static_cast<float>(raster.resolution);
  info.width = static_cast<uint32_t>(raster.width);
  info.height = static_cast<uint32_t>(raster.height);
  info.origin = toPoseMsg(Pose2(raster.origin_x, raster.origin_y, 0.0));
  return info;
}

void toEvidentialGridMsg(const LayerRaster& raster, const std_msgs::Header& header,
                         EvidentialGrid* out) {
  out->header = header;
  out->info = mapMetaData(raster, header.stamp);
  out->layers.assign(layerNames().begin(), layerNames().end());
  out->data.resize(kLayerCount);
  for (int l = 0; l < kLayerCount; ++l) out->data[l].data = raster.values[l];
  out->observed = raster.observed;
}

OccupancyRendering layerRendering(Layer layer, double external_conflict_display_max) {
  OccupancyRendering r;
  if (layer == Layer::kExternalConflict || layer == Layer::kAnomaly) {
    r.full_scale = external_conflict_display_max;
  }
  return r;
}

void toOccupancyGrid(const LayerRaster& raster, Layer layer, const OccupancyRendering& rendering,
                     const std_msgs::Header& header, nav_msgs::OccupancyGrid* out) {
  out->header = header;
  out->info = mapMetaData(raster, header.stamp);
  const std::vector<float>& v = raster.layer(layer);
  out->data.resize(v.size());
  const double scale = 100.0 / rendering.full_scale;
  for (size_t i = 0; i < v.size(); ++i) {
    const double value = std::isfinite(v[i]) ? v[i] * scale : (v[i] > 0 ? 100.0 : 0.0);
    out->data[i] = static_cast<int8_t>(std::lround(std::clamp(value, 0.0, 100.0)));
  }
}

bool layerRasterFromMsg(const EvidentialGrid& msg, LayerRaster* raster, Pose2* frame,
                        std::string* why) {
  auto fail = [&](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!(msg.info.resolution > 0.0f) || !std::isfinite(msg.info.resolution)) {
    return fail("EvidentialGrid: resolution must be positive");
  }
  if (msg.layers.size() != msg.data.size()) {
    return fail("EvidentialGrid: " + std::to_string(msg.layers.size()) + " layer names for " +
                std::to_string(msg.data.size()) + " layers");
  }
  const size_t cells = static_cast<size_t>(msg.info.width) * msg.info.height;
  LayerRaster r;
  r.resolution = msg.info.resolution;
  r.width = static_cast<int>(msg.info.width);
  r.height = static_cast<int>(msg.info.height);
  const Pose2 origin = pose2FromPoseMsg(msg.info.origin);
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.theta)) {
    return fail("EvidentialGrid: origin is not finite");
  }
  Pose2 raster_frame;
  if (origin.theta == 0.0) {
    r.origin_x = origin.x;
    r.origin_y = origin.y;
  } else {
    raster_frame = origin;
  }
  for (size_t i = 0; i < msg.layers.size(); ++i) {
    for (int l = 0; l < kLayerCount; ++l) {
      if (msg.layers[i] == layerNames()[l]) r.values[l] = msg.data[i].data;
    }
  }
  for (const Layer l :
       {Layer::kOccupied, Layer::kFree, Layer::kUnknown, Layer::kExternalConflict}) {
    if (r.layer(l).size() != cells) {
      return fail("EvidentialGrid: layer " + layerName(l) + " has " +
                  std::to_string(r.layer(l).size()) + " values for " + std::to_string(cells) +
                  " cells");
    }
  }
  if (msg.observed.size() != cells) {
    return fail("EvidentialGrid: observed has " + std::to_string(msg.observed.size()) +
                " values for " + std::to_string(cells) + " cells");
  }
  r.observed = msg.observed;
  *raster = std::move(r);
  if (frame != nullptr) *frame = raster_frame;
  return true;
}

void toTrinaryOccupancyGrid(const LayerRaster& raster, double occupied_thresh, double free_thresh,
                            const std_msgs::Header& header, nav_msgs::OccupancyGrid* out) {
  out->header = header;
  out->info = mapMetaData(raster, header.stamp);
  const std::vector<float>& betp = raster.layer(Layer::kPignistic);
  out->data.resize(betp.size());
  for (size_t i = 0; i < betp.size(); ++i) {
    const bool observed = i < raster.observed.size() && raster.observed[i] != 0;
    int8_t value = -1;
    if (observed && betp[i] > occupied_thresh) {
      value = 100;
    } else if (observed && betp[i] < free_thresh) {
      value = 0;
    }
    out->data[i] = value;
  }
}

}  // namespace ros_adapter
}  // namespace evidential_slam
