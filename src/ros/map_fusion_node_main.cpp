// map_fusion: the map fusion nodelet in a process of its own (same code, same parameters, private
// namespace = the node's).
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "map_fusion");
  nodelet::Loader loader;
  const nodelet::M_string remappings(ros::names::getRemappings());
  const nodelet::V_string nodelet_argv;
  if (!loader.load(ros::this_node::getName(), "evidential_slam/MapFusionNodelet", remappings,
                   nodelet_argv)) {
    ROS_FATAL(
        "could not load evidential_slam/MapFusionNodelet (is the workspace's setup.bash "
        "sourced?)");
    return 1;
  }
  ros::spin();
  return 0;
}
