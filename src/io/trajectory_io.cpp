// TUM trajectory files. See trajectory_io.h.
#include "evidential_slam/io/trajectory_io.h"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>

#include "evidential_slam/io/atomic_files.h"

namespace evidential_slam {
namespace io {

bool writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses,
                        std::string* error, AtomicFiles* files) {
  auto write = [&](std::ostream& out) {
    char line[200];
    for (const StampedPose& sp : poses) {
      const Eigen::Quaterniond q(Eigen::AngleAxisd(sp.pose.theta, Eigen::Vector3d::UnitZ()));
      std::snprintf(line, sizeof(line), "%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", sp.stamp,
                    sp.pose.x, sp.pose.y, 0.0, q.x(), q.y(), q.z(), q.w());
      out << line;
    }
    return static_cast<bool>(out);
  };
  if (files) return files->add(path, write, error);
  return writeFileAtomically(path, write, error);
}

bool readTumTrajectory(const std::string& path, std::vector<StampedPose>* poses,
                       std::string* error) {
  poses->clear();
  std::ifstream in(path);
  if (!in) {
    if (error) *error = "cannot open '" + path + "'";
    return false;
  }
  std::string line;
  size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double t, x, y, z, qx, qy, qz, qw;
    if (!(ss >> t >> x >> y >> z >> qx >> qy >> qz >> qw)) {
      if (error) *error = path + ":" + std::to_string(line_no) + ": not a TUM pose line";
      return false;
    }
    const Eigen::Quaterniond q(qw, qx, qy, qz);
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    poses->push_back({t, Pose2(x, y, std::atan2(r(1, 0), r(0, 0)))});
  }
  return true;
}

}  // namespace io
}  // namespace evidential_slam
