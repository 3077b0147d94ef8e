// Trajectories as TUM text files (`t x y z qx qy qz qw`, one pose per line), the format the usual
// evaluation tools (evo, TUM's evaluate_ate) read. Planar poses get z = 0 and a yaw-only
// quaternion.
#pragma once

#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"

namespace evidential_slam {
namespace io {

class AtomicFiles;

// Writes `poses`; the file replaces the old one only once complete (atomic_files.h), staged into
// `files` when given (the caller commits). False (and `error`, with the reason) on a write error.
bool writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses,
                        std::string* error, AtomicFiles* files = nullptr);

// Reads a TUM file back (yaw from the quaternion); '#' lines are skipped.
bool readTumTrajectory(const std::string& path, std::vector<StampedPose>* poses,
                       std::string* error);

}  // namespace io
}  // namespace evidential_slam
