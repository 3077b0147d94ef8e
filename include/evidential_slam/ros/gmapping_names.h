// slam_gmapping's parameter names, so that a user's gmapping <param> block works unchanged: the
// one table of what each of its names becomes here (docs/ros.md, "gmapping's parameters", shows
// it). readParams applies it: a gmapping name with a counterpart sets ours (converted) unless
// ours is given too; one without is reported.
#pragma once

#include <string>
#include <vector>

namespace evidential_slam {
namespace ros_adapter {

struct GmappingName {
  enum class Conversion { kNone, kSame, kLinear, kSquare };
  const char* theirs;
  const char* ours;  // "" when we have no counterpart
  Conversion conversion;
  // kLinear: ours = factor * theirs + offset; kSquare: ours = factor * theirs^2.
  double factor;
  double offset;
  const char* note;  // the conversion's reason, or why the name is not used
};

// Every parameter slam_gmapping reads (its ~ names), in its documentation's order.
const std::vector<GmappingName>& gmappingNames();

// The row of `theirs`, or nullptr.
const GmappingName* findGmappingName(const std::string& theirs);

// Our value for gmapping's `value` (a row with a counterpart).
double convertGmappingValue(const GmappingName& row, double value);

// What readParams did with gmapping's names, for the node's log.
struct GmappingReport {
  std::vector<std::string> used;      // "maxUrange -> usable_range = 6"
  std::vector<std::string> shadowed;  // "maxUrange (usable_range is given)"
  std::vector<std::string> ignored;   // gmapping names without a counterpart
  std::vector<std::string> refused;   // a converted value out of our range: one line each
};

}  // namespace ros_adapter
}  // namespace evidential_slam
