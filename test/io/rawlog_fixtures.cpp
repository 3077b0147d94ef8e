// Test-only rawlog surgery. See rawlog_fixtures.h.
#include "rawlog_fixtures.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPosePDFGaussian.h>
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
    if (variant == Variant::kAllUnusable) blankRanges(scan);
    return true;
  };
  for (size_t i = 0; i < rawlog.size(); ++i) {
    switch (rawlog.getType(i)) {
      case CRawlog::etActionCollection:
        if (variant == Variant::kNoOdometry) {
          writer.write(CActionCollection());
        } else if (variant == Variant::kNanOdometry) {
          CActionCollection spoiled;
          for (const auto& action : *rawlog.getAsAction(i)) {
            const auto* move = dynamic_cast<const CActionRobotMovement2D*>(action.get());
            if (move == nullptr) {
              spoiled.insert(*action);
              continue;
            }
            CActionRobotMovement2D nan_move(*move);
            nan_move.estimationMethod = CActionRobotMovement2D::emOdometry;
            nan_move.rawOdometryIncrementReading.x(std::numeric_limits<double>::quiet_NaN());
            spoiled.insert(nan_move);
          }
          writer.write(spoiled);
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
        auto odometry = std::dynamic_pointer_cast<CObservationOdometry>(o);
        if (odometry && variant == Variant::kNoOdometry) break;
        if (odometry && variant == Variant::kNanOdometry) {
          CObservationOdometry nan_reading(*odometry);
          nan_reading.odometry.x(std::numeric_limits<double>::quiet_NaN());
          writer.write(nan_reading);
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

namespace {

// The first `objects` serialised objects of a rawlog (gzip or plain), as bytes.
bool headOf(const std::string& path, int objects, std::string* bytes, std::string* error) {
  mrpt::io::CFileGZInputStream in;
  if (!in.open(path)) {
    if (error) *error = "cannot open '" + path + "'";
    return false;
  }
  auto archive = mrpt::serialization::archiveFrom(in);
  for (int i = 0; i < objects; ++i) archive.ReadObject();
  const uint64_t length = in.getPosition();
  in.close();
  in.open(path);
  bytes->assign(length, '\0');
  if (in.Read(bytes->data(), length) != length) {
    if (error) *error = "cannot read '" + path + "'";
    return false;
  }
  return true;
}

class MemoryLog {
 public:
  MemoryLog& operator<<(const mrpt::serialization::CSerializable& object) {
    auto archive = mrpt::serialization::archiveFrom(stream_);
    archive << object;
    return *this;
  }
  std::string bytes() const {
    return std::string(static_cast<const char*>(stream_.getRawBufferData()),
                       static_cast<size_t>(stream_.getTotalBytesCount()));
  }

 private:
  mrpt::io::CMemoryStream stream_;
};

CObservation2DRangeScan::Ptr smallScan(double t, bool intensity) {
  auto s = CObservation2DRangeScan::Create();
  s->timestamp = mrpt::Clock::fromDouble(t);
  s->sensorLabel = "LASER";
  s->aperture = static_cast<float>(M_PI);
  s->maxRange = 10.0f;
  s->resizeScanAndAssign(5, 3.0f, true);
  s->setScanRange(1, std::numeric_limits<float>::quiet_NaN());
  s->setScanRangeValidity(2, false);
  if (intensity) {
    s->setScanHasIntensity(true);
    for (size_t i = 0; i < 5; ++i) s->setScanIntensity(i, static_cast<int>(10 * i));
  }
  return s;
}

}  // namespace

bool writeRawlogFuzzSeeds(const std::string& data_dir, const std::string& mrpt_datasets_dir,
                          const std::string& out_dir, std::string* error) {
  auto save = [&](const std::string& name, const std::string& bytes) {
    std::ofstream out(out_dir + "/" + name, std::ios::binary | std::ios::trunc);
    out << bytes;
    if (!out) {
      if (error) *error = "cannot write '" + out_dir + "/" + name + "'";
      return false;
    }
    return true;
  };
  std::string bytes;
  for (const auto& [source, objects, name] : std::vector<std::tuple<std::string, int, std::string>>{
           {data_dir + "/sim.rawlog", 4, "sim_actions_frames.rawlog"},
           {data_dir + "/sim_obs.rawlog", 4, "sim_observations.rawlog"}}) {
    if (!headOf(source, objects, &bytes, error) || !save(name, bytes)) return false;
  }
  // Older class versions (scans 6, CPose3D 1 and 2 with a CMatrixD, actions 6 and 7) and sensors
  // the reader leaves to MRPT (beacons, landmarks), when mrpt-common's datasets are installed.
  for (const auto& [source, objects, name] : std::vector<std::tuple<std::string, int, std::string>>{
           {"localization_demo.rawlog", 4, "mrpt_localization_demo.rawlog"},
           {"2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog", 3, "mrpt_sena.rawlog"},
           {"uwb_ro-localization_demo.rawlog", 2, "mrpt_uwb_beacons.rawlog"},
           {"kf-slam_demo.rawlog", 2, "mrpt_kf_slam_landmarks.rawlog"}}) {
    const std::string path = mrpt_datasets_dir + "/" + source;
    if (!std::ifstream(path)) continue;
    if (!headOf(path, objects, &bytes, error) || !save(name, bytes)) return false;
  }

  // An odometry action with the Thrun model (MRPT draws its samples while reading), then one
  // holding a Gaussian pose PDF (scan matching), each with a frame.
  MemoryLog motion;
  {
    CActionRobotMovement2D::TMotionModelOptions options;
    options.modelSelection = CActionRobotMovement2D::mmThrun;
    options.thrunModel.nParticlesCount = 20;
    CActionRobotMovement2D act;
    act.computeFromOdometry(CPose2D(0.2, 0.0, 0.05), options);
    act.timestamp = mrpt::Clock::fromDouble(1.0);
    act.hasVelocities = true;
    act.velocityLocal = mrpt::math::TTwist2D(0.2, 0.0, 0.05);
    act.hasEncodersInfo = true;
    act.encoderLeftTicks = 100;
    act.encoderRightTicks = 110;
    CActionCollection actions;
    actions.insert(act);
    CSensoryFrame frame;
    frame.insert(smallScan(1.0, false));
    motion << actions << frame;

    CActionRobotMovement2D matched;
    matched.estimationMethod = CActionRobotMovement2D::emScan2DMatching;
    mrpt::math::CMatrixDouble33 cov;
    cov.setDiagonal(3, 0.01);
    matched.poseChange = mrpt::poses::CPosePDFGaussian::Create(CPose2D(0.1, 0.0, 0.0), cov);
    CActionCollection matched_actions;
    matched_actions.insert(matched);
    CSensoryFrame next;
    next.insert(smallScan(2.0, true));
    motion << matched_actions << next;
  }
  if (!save("synthetic_motion_models.rawlog", motion.bytes())) return false;

  // Observation-only: odometry with encoders and velocities, a scan with intensities, a comment.
  MemoryLog observations;
  {
    CObservationOdometry odo;
    odo.timestamp = mrpt::Clock::fromDouble(1.0);
    odo.odometry = CPose2D(1.0, 2.0, 0.3);
    odo.hasEncodersInfo = true;
    odo.encoderLeftTicks = 5;
    odo.encoderRightTicks = 7;
    odo.hasVelocities = true;
    odo.velocityLocal = mrpt::math::TTwist2D(0.1, 0.0, 0.01);
    mrpt::obs::CObservationComment comment;
    comment.text = "a comment";
    CObservationOdometry later = odo;
    later.timestamp = mrpt::Clock::fromDouble(2.0);
    later.odometry = CPose2D(1.5, 2.0, 0.3);
    observations << odo << comment << *smallScan(1.5, true) << later;
  }
  return save("synthetic_observations.rawlog", observations.bytes());
}

}  // namespace test
}  // namespace evidential_slam
