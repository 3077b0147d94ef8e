// A parameter server value as the text the parameter table's parsers read (parseParameter): the
// one conversion every node's parameter reader uses.
#pragma once

#include <string>

#include <xmlrpcpp/XmlRpcValue.h>

namespace evidential_slam {
namespace ros_adapter {

// False for arrays, structs and other non-scalar values.
bool parameterText(XmlRpc::XmlRpcValue& value, std::string* text);

}  // namespace ros_adapter
}  // namespace evidential_slam
