// Test-only rawlog surgery. See rawlog_fixtures.h.
#include "rawlog_fixtures.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include "evidential_slam/io/ground_truth.h"

namespace evidential_slam {
namespace test {
namespace {

using mrpt::obs::CActionCollection;
using mrpt::obs::CActionRobotMovement2D;
using mrpt::obs::CObservation;
using mrpt::obs::CObservation2DRangeScan;
using mrpt::obs::CObservationOdometry;
using mrpt::obs::CRawlog;
using mrpt::obs::CSensoryFrame;
using mrpt::poses::CPose2D;

bool load(const std::string& path, CRawlog* rawlog, std::string* error) {
  if (!rawlog->loadFromRawLogFile(path)) {
    if (error) *error = "cannot load rawlog '" + path + "'";
    return false;
  }
  return true;
}

// Writes objects in order to a gzip rawlog.
class Writer {
 public:
  explicit Writer(const std::string& path) : file_(path), archive_(file_) {}
  void write(const mrpt::serialization::CSerializable& obj) { archive_ << obj; }

 private:
  mrpt::io::CFileGZOutputStream file_;
  mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZOutputStream> archive_;
};

CActionCollection movement(const CPose2D& increment, const mrpt::Clock::time_point& stamp) {
  CActionRobotMovement2D act;
  CActionRobotMovement2D::TMotionModelOptions options;
  options.modelSelection = CActionRobotMovement2D::mmGaussian;
  act.computeFromOdometry(increment, options);
  act.timestamp = stamp;
  CActionCollection acts;
  acts.insert(act);
  return acts;
}

mrpt::Clock::time_point frameStamp(const CSensoryFrame& sf) {
  for (const auto& o : sf) {
    if (o && o->timestamp != INVALID_TIMESTAMP) return o->timestamp;
  }
  return INVALID_TIMESTAMP;
}

void blankRanges(CObservation2DRangeScan& scan) {
  for (size_t i = 0; i < scan.getScanSize(); ++i) {
    scan.setScanRange(i, std::numeric_limits<float>::quiet_NaN());
  }
}

void spoilRanges(CObservation2DRangeScan& scan) {
  const size_t n = scan.getScanSize();
  if (n > 10) scan.setScanRange(10, std::numeric_limits<float>::quiet_NaN());
  if (n > 20) scan.setScanRange(20, std::numeric_limits<float>::infinity());
  if (n > 30) scan.setScanRange(30, -1.0f);
}

}  // namespace

bool addNoisyOdometry(const std::string& in, const std::string& out, const std::string& gt_path,
                      const OdometryNoise& noise, const std::string& laser_label,
                      std::string* error) {
  CRawlog rawlog;
  if (!load(in, &rawlog, error)) return false;
  std::vector<StampedPose> truth;
  if (!io::readGroundTruth(gt_path, &truth, error)) return false;
  std::mt19937_64 rng(noise.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);

  Writer writer(out);
  size_t frame = 0;
  mrpt::Clock::time_point last_stamp = INVALID_TIMESTAMP;
  for (size_t i = 0; i < rawlog.size(); ++i) {
    // The input's own actions (zero increments) are replaced.
    if (rawlog.getType(i) != CRawlog::etSensoryFrame) continue;
    auto sf = rawlog.getAsObservations(i);
    if (frame >= truth.size()) {
      if (error) *error = "more sensory frames than ground-truth poses";
      return false;
    }
    CPose2D increment;
    if (frame > 0) {
      const Pose2& a = truth[frame - 1].pose;
      const Pose2& b = truth[frame].pose;
      const CPose2D step = CPose2D(b.x, b.y, b.theta) - CPose2D(a.x, a.y, a.theta);
      const double d = std::hypot(step.x(), step.y());
      const double turn = std::abs(step.phi());
      increment =
          CPose2D(noise.scale * step.x() + gauss(rng) * noise.sigma_xy_per_m * d,
                  noise.scale * step.y() + gauss(rng) * noise.sigma_xy_per_m * d,
                  step.phi() + noise.bias_phi_per_m * d +
                      gauss(rng) * (noise.sigma_phi_per_rad * turn + noise.sigma_phi_per_m * d));
    }
    last_stamp = frameStamp(*sf);
    writer.write(movement(increment, last_stamp));
    for (auto& o : *sf) {
      if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o)) {
        scan->sensorLabel = laser_label;
      }
    }
    writer.write(*sf);
    ++frame;
  }
  // Like simul-gridmap, end with an action that no frame follows: readers must take it as a clean
  // end of file.
  writer.write(movement(CPose2D(), last_stamp));
  if (frame != truth.size()) {
    if (error) {
      *error = std::to_string(frame) + " sensory frames for " + std::to_string(truth.size()) +
               " ground-truth poses";
    }
    return false;
  }
  return true;
}

bool convertToObservations(const std::string& in, const std::string& out, std::string* error) {
  CRawlog rawlog;
  if (!load(in, &rawlog, error)) return false;
  Writer writer(out);
  CPose2D odometry;
  for (size_t i = 0; i < rawlog.size(); ++i) {
    if (rawlog.getType(i) == CRawlog::etActionCollection) {
      if (auto move = rawlog.getAsAction(i)->getBestMovementEstimation()) {
        odometry = odometry + move->rawOdometryIncrementReading;
      }
      continue;
    }
    if (rawlog.getType(i) != CRawlog::etSensoryFrame) continue;
    auto sf = rawlog.getAsObservations(i);
    for (const auto& o : *sf) writer.write(*o);
    CObservationOdometry odo;
    odo.sensorLabel = "ODOMETRY";
    odo.timestamp = frameStamp(*sf);
    odo.odometry = odometry;
    writer.write(odo);
  }
  return true;
}

bool makeVariant(const std::string& in, const std::string& out, Variant variant,
                 std::string* error) {
  CRawlog rawlog;
  if (!load(in, &rawlog, error)) return false;
  Writer writer(out);
  size_t scans = 0;
  // Applies the scan-level changes; false when the scan is to be dropped.
  auto edit = [&](CObservation2DRangeScan& scan) {
    if (variant == Variant::kNoLaser) return false;
    if (variant == Variant::kBadRanges) spoilRanges(scan);
    if (variant == Variant::kUnusableScans && ++scans % 10 == 0) blankRanges(scan);
    return true;
  };
  for (size_t i = 0; i < rawlog.size(); ++i) {
    switch (rawlog.getType(i)) {
      case CRawlog::etActionCollection:
        if (variant == Variant::kNoOdometry) {
          writer.write(CActionCollection());
        } else {
          writer.write(*rawlog.getAsAction(i));
        }
        break;
      case CRawlog::etSensoryFrame: {
        CSensoryFrame sf;
        for (const auto& o : *rawlog.getAsObservations(i)) {
          auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o);
          if (scan && !edit(*scan)) continue;
          sf.insert(o);
        }
        writer.write(sf);
        break;
      }
      case CRawlog::etObservation: {
        auto o = rawlog.getAsObservation(i);
        auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o);
        if (scan && !edit(*scan)) break;
        if (std::dynamic_pointer_cast<CObservationOdometry>(o) && variant == Variant::kNoOdometry) {
          break;
        }
        writer.write(*o);
        break;
      }
      default:
        break;
    }
  }
  return true;
}

bool truncateCopy(const std::string& in, const std::string& out, double fraction,
                  std::string* error) {
  std::ifstream src(in, std::ios::binary);
  if (!src) {
    if (error) *error = "cannot open '" + in + "'";
    return false;
  }
  const std::vector<char> bytes((std::istreambuf_iterator<char>(src)),
                                std::istreambuf_iterator<char>());
  const size_t keep = static_cast<size_t>(fraction * static_cast<double>(bytes.size()));
  std::ofstream dst(out, std::ios::binary | std::ios::trunc);
  dst.write(bytes.data(), static_cast<std::streamsize>(keep));
  if (!dst) {
    if (error) *error = "cannot write '" + out + "'";
    return false;
  }
  return true;
}

}  // namespace test
}  // namespace evidential_slam
