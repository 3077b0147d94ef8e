// `t x y phi` ground-truth reader. See ground_truth.h.
#include "evidential_slam/io/ground_truth.h"

#include <charconv>
#include <cmath>
#include <fstream>

#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace {

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ','; }

}  // namespace

bool parseGroundTruthLine(const std::string& line, StampedPose* pose) {
  double v[4];
  int n = 0;
  const char* p = line.data();
  const char* end = p + line.size();
  while (true) {
    while (p < end && isSpace(*p)) ++p;
    if (p == end) break;
    if (n == 4) return false;  // a fifth field
    // from_chars does not take a leading '+'.
    if (*p == '+') ++p;
    const auto r = std::from_chars(p, end, v[n]);
    if (r.ec != std::errc() || (r.ptr < end && !isSpace(*r.ptr))) return false;
    if (!std::isfinite(v[n])) return false;
    ++n;
    p = r.ptr;
  }
  if (n != 4) return false;
  pose->stamp = v[0];
  pose->pose = Pose2(v[1], v[2], v[3]);
  return true;
}

bool readGroundTruth(const std::string& path, std::vector<StampedPose>* poses, std::string* error) {
  poses->clear();
  std::ifstream in(path);
  if (!in) {
    if (error) *error = "cannot open ground truth '" + path + "'";
    return false;
  }
  return readGroundTruth(in, path, poses, error);
}

bool readGroundTruth(std::istream& in, const std::string& name, std::vector<StampedPose>* poses,
                     std::string* error) {
  poses->clear();
  std::string line;
  size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#' || line[first] == '%') continue;
    StampedPose sp;
    if (!parseGroundTruthLine(line, &sp)) {
      if (error) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        *error = name + ":" + std::to_string(line_no) + ": expected 't x y phi', got " +
                 quotedForMessage(line);
      }
      poses->clear();
      return false;
    }
    poses->push_back(sp);
  }
  if (in.bad()) {
    if (error) *error = "error reading ground truth '" + name + "'";
    poses->clear();
    return false;
  }
  return true;
}

}  // namespace io
}  // namespace evidential_slam
