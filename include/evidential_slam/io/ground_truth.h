// Ground-truth trajectories in the GridmapNavSimul / simul-gridmap text format: one `t x y phi`
// line per pose (seconds, metres, radians). Used to score the SLAM path (ATE).
#pragma once

#include <istream>
#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"

namespace evidential_slam {
namespace io {

// Reads `path`; blank lines and lines starting with '#' or '%' are skipped. Any other line must
// hold exactly four finite numbers. False (and a one-line `error` naming the file and line) on a
// missing file or a malformed line; `poses` is then left empty.
bool readGroundTruth(const std::string& path, std::vector<StampedPose>* poses, std::string* error);
// The same from a stream; `name` stands for the file in messages.
bool readGroundTruth(std::istream& in, const std::string& name, std::vector<StampedPose>* poses,
                     std::string* error);

// Parses one non-comment line; false when it is not four finite numbers.
bool parseGroundTruthLine(const std::string& line, StampedPose* pose);

}  // namespace io
}  // namespace evidential_slam
