// Every ROS parameter of the SLAM nodelet, read in one place, by the rows of the parameter table
// (core/parameters.def): the core's and the node's own. The run-time ones are also the fields of
// cfg/EvidentialSlam.cfg (dynamic_reconfigure), which is generated from the same table.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "evidential_slam/core/parameter_fields/node.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/ros/gmapping_names.h"

namespace evidential_slam {
class EvidentialSlamConfig;  // dynamic_reconfigure's, generated from the table

namespace ros_adapter {

struct NodeParams : Parameters {
  NodeParams();  // the table's defaults
  ES_NODE_FIELDS

  bool isValid(std::string* why) const;
};

// Reads every parameter from the private node handle; missing ones keep their defaults. False
// with a one-line `why` for a value of the wrong type or out of range. `unknown` gets the names
// under the private namespace that are not parameters (typos; worth a warning). slam_gmapping's
// names (gmapping_names.h) set their counterpart, converted, where ours is not given; `gmapping`
// gets what was done with them.
bool readParams(const ros::NodeHandle& private_nh, NodeParams* params, std::string* why,
                std::vector<std::string>* unknown = nullptr, GmappingReport* gmapping = nullptr);

// dynamic_reconfigure <-> parameters: the run-time part of `params` to and from the cfg struct.
EvidentialSlamConfig toReconfigure(const NodeParams& params);
void applyReconfigure(const EvidentialSlamConfig& config, NodeParams* params);

}  // namespace ros_adapter
}  // namespace evidential_slam
