// When map fusion without known initial poses estimates again where a robot's map lies on the
// reference robot's map. An alignment depends on the two maps only, so one that was refused is
// tried again only once either map changed, and one that succeeded is refreshed at a bounded rate.
#pragma once

#include <cstdint>
#include <string>

namespace evidential_slam {
namespace fusion {

// What an alignment of a robot's map was (or would be) computed from.
struct AlignmentInputs {
  uint64_t map_version = 0;  // the robot's map; 0 = no attempt yet
  std::string reference;     // the reference robot
  uint64_t reference_version = 0;
  bool operator==(const AlignmentInputs& o) const {
    return map_version == o.map_version && reference == o.reference &&
           reference_version == o.reference_version;
  }
  bool operator!=(const AlignmentInputs& o) const { return !(*this == o); }
};

// Whether to align now, given the last attempt (its inputs and time) and the current inputs. A
// robot not aligned yet: whenever the inputs differ from the last attempt's. An aligned robot: at
// once when the reference is another robot than at the last attempt (its pose is in another
// frame), else when its own map changed and at least min_interval_s after the last attempt.
inline bool alignmentDue(bool aligned, const AlignmentInputs& last, double last_s,
                         const AlignmentInputs& current, double now_s, double min_interval_s) {
  if (!aligned || current.reference != last.reference) return current != last;
  return current.map_version != last.map_version && now_s - last_s >= min_interval_s;
}

}  // namespace fusion
}  // namespace evidential_slam
