// libFuzzer target for RawlogReader (plain rawlog bytes, read through MRPT's deserialisation).
// Besides the sanitizers' checks: reading ends with a status and, when it stopped early, a one-line
// message; every scan handed out is consistent with finite geometry and odometry; and the
// pre-check agrees with MRPT on the length of every object it passed (the reader reports a
// mismatch as corrupt data, which would hide a pre-check that lets a length field through).
#include <cmath>
#include <cstdint>
#include <regex>
#include <string>

#include "evidential_slam/io/rawlog_reader.h"
#include "fuzz_check.h"

namespace {

namespace io = evidential_slam::io;
using evidential_slam::fuzz::checkErrorLine;
using evidential_slam::fuzz::die;

bool finite(const evidential_slam::Pose2& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  io::RawlogReader reader;
  std::string error;
  if (!reader.openBytes(std::string(reinterpret_cast<const char*>(data), size), "fuzz input",
                        &error)) {
    die("openBytes failed:", error);
  }
  io::RawlogScan scan;
  io::RawlogReader::Status status;
  uint64_t scans = 0;
  while ((status = reader.next(&scan)) == io::RawlogReader::Status::kScan) {
    ++scans;
    std::string why;
    if (!scan.scan.isConsistent(&why)) die("inconsistent scan:", why);
    if (!finite(scan.odometry) || !finite(scan.scan.sensor_pose)) die("non-finite pose", "");
    if (!std::isfinite(scan.scan.max_range) || !std::isfinite(scan.scan.range_sigma)) {
      die("non-finite scan parameters", "");
    }
    for (float b : scan.scan.bearings) {
      if (!std::isfinite(b)) die("non-finite bearing", "");
    }
  }
  const std::string& message = reader.message();
  if (status == io::RawlogReader::Status::kEnd) {
    if (!message.empty()) die("a message at a clean end:", message);
  } else {
    checkErrorLine(message);
    // The reader's own words for a disagreement end the message (a class name read from the
    // input is quoted, so it cannot end it).
    static const std::regex mismatch(
        "(MRPT reads past its checked length|reads as \\d+ bytes where its check found \\d+)$");
    if (std::regex_search(message, mismatch)) die("pre-check and MRPT disagree:", message);
  }
  if (reader.counts().scans_emitted != scans) die("scans_emitted disagrees", "");
  return 0;
}
