// A parameter server value as the text the parameter table's parsers read (parseParameter): the
// one conversion every node's parameter reader uses.
#pragma once

#include <string>

#include <xmlrpcpp/XmlRpcValue.h>

#include "evidential_slam/core/parameters.h"

namespace evidential_slam {
namespace ros_adapter {

// False for arrays, structs and other non-scalar values.
bool parameterText(XmlRpc::XmlRpcValue& value, std::string* text);

// A parameter server value of `spec` through the table's parser into `field`: false with
// "<name> must be a single value" for a non-scalar, else parseParameter's verdict and `why`.
template <typename Field>
bool parseServerValue(const ParameterSpec& spec, XmlRpc::XmlRpcValue& value, Field* field,
                      std::string* why) {
  std::string text;
  if (!parameterText(value, &text)) {
    if (why != nullptr) *why = std::string(spec.name) + " must be a single value";
    return false;
  }
  return parseParameter(spec, text, field, why);
}

}  // namespace ros_adapter
}  // namespace evidential_slam
