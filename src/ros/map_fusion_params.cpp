#include "evidential_slam/ros/map_fusion_params.h"

#include <cmath>

#include <xmlrpcpp/XmlRpcValue.h>

#include "evidential_slam/core/fusion/combination.h"
#include "evidential_slam/ros/parameter_rows.h"
#include "evidential_slam/ros/parameter_text.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

bool readNumber(const std::string& name, double* value) {
  XmlRpc::XmlRpcValue v;
  if (!ros::param::get(name, v)) return false;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    *value = static_cast<double>(v);
  } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    *value = static_cast<int>(v);
  } else {
    return false;
  }
  return std::isfinite(*value);
}

}  // namespace

MapFusionParams::MapFusionParams() { ES_MAP_FUSION_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool MapFusionParams::isValid(std::string* why) const {
  if (!session.isValid(why)) return false;
  bool ok = true;
  ES_MAP_FUSION_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (!ok) return false;
  fusion::Rule r;
  if (!fusion::parseRule(rule, &r)) {
    if (why != nullptr) {
      *why = "fusion_rule '" + rule +
             "' is none of cautious, conjunctive, dempster, yager, "
             "disjunctive";
    }
    return false;
  }
  if (robot_map_topic.empty() || world_frame.empty()) {
    if (why != nullptr) *why = "robot_map_topic and world_frame must not be empty";
    return false;
  }
  return true;
}

bool readMapFusionParams(const ros::NodeHandle& nh, MapFusionParams* params, std::string* why) {
  bool ok = true;
  forEachMapFusionParameter(*params, [&](const ParameterSpec& spec, auto& field) {
    XmlRpc::XmlRpcValue value;
    if (!ok || !nh.getParam(spec.name, value)) return;
    ok = parseServerValue(spec, value, &field, why);
  });
  return ok;
}

bool readInitPose(const std::string& robot, Pose2* pose) {
  const std::string ns = ros::names::append(robot, "map_merge");
  double x = 0, y = 0, z = 0, yaw = 0;
  if (!readNumber(ros::names::append(ns, "init_pose_x"), &x) ||
      !readNumber(ros::names::append(ns, "init_pose_y"), &y) ||
      !readNumber(ros::names::append(ns, "init_pose_z"), &z) ||
      !readNumber(ros::names::append(ns, "init_pose_yaw"), &yaw)) {
    return false;
  }
  *pose = Pose2(x, y, yaw);
  return true;
}

}  // namespace ros_adapter
}  // namespace evidential_slam
