#include "evidential_slam/core/laser_scan.h"

namespace evidential_slam {

bool LaserScan::isConsistent(std::string* why) const {
  auto fail = [why](const std::string& m) {
    if (why != nullptr) *why = m;
    return false;
  };
  if (ranges.empty()) return fail("scan has no rays");
  if (bearings.size() != ranges.size())
    return fail("scan has a different number of bearings and ranges");
  if (!valid.empty() && valid.size() != ranges.size())
    return fail("scan validity flags do not match its ranges");
  return true;
}

}  // namespace evidential_slam
