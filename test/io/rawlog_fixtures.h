// Test-only rawlog surgery with MRPT: gives simul-gridmap's rawlogs a noisy odometry, converts them
// to the observation-only format and makes the broken variants the reader and runner must survive
// (bad ranges, no laser, no odometry, truncation). Used by make_fixtures.py (through
// evidential_slam_fixture_tool) and directly by the tests.
#pragma once

#include <cstdint>
#include <string>

namespace evidential_slam {
namespace test {

struct OdometryNoise {
  uint64_t seed = 1;
  double sigma_xy_per_m = 0.05;     // σ of each translation component per metre moved
  double sigma_phi_per_rad = 0.05;  // σ of the rotation per radian turned
  double sigma_phi_per_m = 0.01;    // σ of the rotation per metre moved (rad/m)
  double scale = 1.02;              // systematic distance error (wheel radius)
  double bias_phi_per_m = 0.004;    // systematic heading drift (rad per metre)
};

// Rewrites the CActionRobotMovement2D increment before every sensory frame of an
// Actions/SensoryFrame rawlog from the true poses in `gt_path` (one `t x y phi` per scan, in
// order), with `noise`; labels the scans `laser_label`. The first frame gets a zero increment.
bool addNoisyOdometry(const std::string& in, const std::string& out, const std::string& gt_path,
                      const OdometryNoise& noise, const std::string& laser_label,
                      std::string* error);

// Actions/SensoryFrame -> observation-only: per frame, the scan followed by a CObservationOdometry
// with the accumulated odometry stamped like the scan (the order some loggers use, so the reader
// must look ahead for it).
bool convertToObservations(const std::string& in, const std::string& out, std::string* error);

enum class Variant {
  kBadRanges,      // NaN, +inf and negative ranges in every scan (3 rays each)
  kNoLaser,        // scans removed
  kNoOdometry,     // odometry removed (empty action collections / no CObservationOdometry)
  kNanOdometry,    // every odometry reading (increment or pose) has a NaN x
  kUnusableScans,  // every 10th scan (the 10th, 20th, ...) has only NaN ranges
  kAllUnusable,    // every scan has only NaN ranges
};
// Copies `in` to `out` with the change of `variant`; works on both formats.
bool makeVariant(const std::string& in, const std::string& out, Variant variant,
                 std::string* error);

// Copies the first `fraction` of the bytes of `in` to `out` (a truncated download).
bool truncateCopy(const std::string& in, const std::string& out, double fraction,
                  std::string* error);

// Writes the rawlog fuzzer's seed corpus (test/fuzz/corpus/rawlog) to `out_dir`, plain
// (uncompressed) rawlogs of a few entries each: the heads of the two committed fixtures, of those
// of MRPT's datasets (older class versions, other sensors) found under `mrpt_datasets_dir`, and
// logs written here with MRPT for the branches those lack (a Thrun motion model, an action holding
// a pose PDF, odometry with encoders and velocities, a scan with intensities, a comment).
bool writeRawlogFuzzSeeds(const std::string& data_dir, const std::string& mrpt_datasets_dir,
                          const std::string& out_dir, std::string* error);

}  // namespace test
}  // namespace evidential_slam
