// libFuzzer target for readGroundTruth (`t x y phi` lines). A file it accepts holds only finite
// poses, one per non-comment line; a file it refuses leaves no poses and a one-line error.
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>

#include "evidential_slam/io/ground_truth.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace io = evidential_slam::io;
  using evidential_slam::fuzz::die;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::vector<evidential_slam::StampedPose> poses;
  std::string error;
  if (!io::readGroundTruth(in, "fuzz input", &poses, &error)) {
    if (!poses.empty()) die("poses left after an error", "");
    evidential_slam::fuzz::checkErrorLine(error);
    return 0;
  }
  for (const auto& p : poses) {
    if (!std::isfinite(p.stamp) || !std::isfinite(p.pose.x) || !std::isfinite(p.pose.y) ||
        !std::isfinite(p.pose.theta)) {
      die("non-finite pose accepted", "");
    }
  }
  return 0;
}
