// explorer_node: the explorer nodelet in a process of its own (same code, same parameters,
// private namespace = the node's).
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "explorer");
  nodelet::Loader loader;
  const nodelet::M_string remappings(ros::names::getRemappings());
  const nodelet::V_string nodelet_argv;
  if (!loader.load(ros::this_node::getName(), "evidential_slam/ExplorerNodelet", remappings,
                   nodelet_argv)) {
    ROS_FATAL(
        "could not load evidential_slam/ExplorerNodelet (is the workspace's setup.bash sourced?)");
    return 1;
  }
  ros::spin();
  return 0;
}
