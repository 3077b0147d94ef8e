#include "evidential_slam/core/slam_engine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace evidential_slam {

SlamEngine::SlamEngine(const SlamConfig& config) : config_(config) {
  std::string why;
  if (!config_.isValid(&why)) throw std::invalid_argument("invalid SLAM configuration: " + why);
  filter_ = std::make_unique<ParticleFilter>(config_);
}

SlamEngine::~SlamEngine() = default;

void SlamEngine::reset() {
  filter_ = std::make_unique<ParticleFilter>(config_);
  stats_ = SlamStats{};
  have_last_processed_ = false;
  scan_records_.clear();
  step_odometry_.clear();
  step_stamps_.clear();
  filter_->setMapUpdates(!mapping_paused_);
  if (start_) filter_->startOnMap(start_->map, start_->pose);
}

void SlamEngine::setMappingPaused(bool paused) {
  mapping_paused_ = paused;
  filter_->setMapUpdates(!paused);
}

bool SlamEngine::startFromMap(const EvidentialGridMap& map, const Pose2& pose, std::string* why,
                              const Pose2* odometry) {
  const auto finite = [](const Pose2& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
  };
  std::string reason;
  if (!(std::abs(map.resolution() - config_.resolution) <= 1e-9 * config_.resolution)) {
    reason = "the map's resolution (" + std::to_string(map.resolution()) +
             " m) is not the configured one (" + std::to_string(config_.resolution) + " m)";
  } else if (!finite(pose) || (odometry != nullptr && !finite(*odometry))) {
    reason = "the start pose is not finite";
  }
  if (!reason.empty()) {
    if (why != nullptr) *why = reason;
    return false;
  }
  auto start = std::make_unique<MapStart>();
  start->map = map;
  start->pose = pose;
  start->anchored = odometry != nullptr;
  if (odometry != nullptr) start->odometry = *odometry;
  start_ = std::move(start);
  reset();
  return true;
}

Pose2 SlamEngine::poseBeforeFirstScan(const Pose2& odometry) const {
  if (!start_) return odometry;  // the map frame starts as the odom frame
  return start_->anchored ? start_->pose.compose(start_->odometry.between(odometry)) : start_->pose;
}

bool SlamEngine::reconfigure(const SlamConfig& config, std::string* why) {
  SlamConfig next = config;
  next.particles = config_.particles;
  next.resolution = config_.resolution;
  next.seed = config_.seed;
  next.threads = config_.threads;
  if (!next.isValid(why)) return false;
  config_ = next;
  filter_->reconfigure(config_);
  return true;
}

ScanUpdate SlamEngine::processScan(const Pose2& odometry, const LaserScan& scan) {
  ScanUpdate out;
  ++stats_.scans_received;
  last_odometry_ = odometry;
  const int step = static_cast<int>(step_odometry_.size()) - 1;  // last processed step, -1: none
  scan_records_.push_back(ScanRecord{scan.stamp, step, odometry});

  stats_.rays_total += scan.ranges.size();
  size_t usable = 0, no_returns = 0;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const float z = scan.ranges[i];
    if (!scan.valid.empty() && i < scan.valid.size() && scan.valid[i] == 0) {
      ++stats_.rays_no_return;
      ++no_returns;
    } else if (!std::isfinite(z) || z < 0.0f) {
      ++stats_.rays_bad;
    } else {
      ++usable;
    }
  }
  std::string why;
  const bool nothing_to_use = usable == 0 && (no_returns == 0 || !config_.sensor.clear_no_return);
  if (!scan.isConsistent(&why) || nothing_to_use) {
    if (why.empty()) why = "scan has no usable ray";
    ++stats_.scans_rejected;
    out.rejected = true;
    out.why = why;
    out.best_pose = bestPose();
    return out;
  }

  FilterStepInfo info;
  if (!have_last_processed_ && start_) {
    // The particles wait on the start map: this scan is their first step from the start pose.
    const Pose2 increment = start_->anchored ? start_->odometry.between(odometry) : Pose2();
    info = filter_->update(increment, scan, 0);
  } else if (!have_last_processed_) {
    info = filter_->initialize(odometry, scan, 0);
  } else {
    const Pose2 increment = last_processed_odometry_.between(odometry);
    const bool moved = std::hypot(increment.x, increment.y) >= config_.update_min_distance ||
                       std::abs(increment.theta) >= config_.update_min_angle;
    if (!moved) {
      out.best_pose = bestPose();
      return out;
    }
    info = filter_->update(increment, scan, static_cast<int>(step_odometry_.size()));
    stats_.group_updates += filter_->lastUpdateGroups();
  }
  have_last_processed_ = true;
  last_processed_odometry_ = odometry;
  step_odometry_.push_back(odometry);
  step_stamps_.push_back(scan.stamp);
  scan_records_.back().step = static_cast<int>(step_odometry_.size()) - 1;
  ++stats_.scans_processed;
  if (info.resampled) ++stats_.resamplings;
  if (info.long_step) ++stats_.long_steps;
  out.processed = true;
  out.external_conflict_added = info.best_conflict_added_bits;
  out.conflict_mass_added = info.best_conflict.mass_added;
  out.open_space_conflict_added = info.best_conflict.open_space_added;
  out.contradiction_added = info.best_conflict.contradiction;
  out.best_pose = bestPose();
  return out;
}

const EvidentialGridMap& SlamEngine::bestMap() const {
  static const EvidentialGridMap kEmpty(0.05);
  if (filter_->particles().empty()) return kEmpty;
  return filter_->best().map;
}

AnomalyGrid SlamEngine::bestAnomaly() const {
  if (filter_->particles().empty()) return AnomalyGrid();
  return accumulateAnomaly(filter_->best().anomaly.get());
}

std::shared_ptr<const AnomalyNode> SlamEngine::bestAnomalyLineage() const {
  if (filter_->particles().empty()) return nullptr;
  return filter_->best().anomaly;
}

Pose2 SlamEngine::bestPose() const {
  if (!have_last_processed_ || filter_->particles().empty()) {
    if (start_ && stats_.scans_received == 0) return start_->pose;
    return poseBeforeFirstScan(last_odometry_);
  }
  return filter_->best().pose.compose(last_processed_odometry_.between(last_odometry_));
}

void SlamEngine::particlePoses(std::vector<Pose2>* poses, std::vector<double>* weights) const {
  poses->clear();
  weights->clear();
  const std::vector<Particle>& particles = filter_->particles();
  if (!have_last_processed_ || particles.empty()) {
    poses->push_back(bestPose());
    weights->push_back(1.0);
    return;
  }
  const Pose2 since = last_processed_odometry_.between(last_odometry_);
  double max_log = -std::numeric_limits<double>::infinity();
  for (const Particle& p : particles) max_log = std::max(max_log, p.log_weight);
  double total = 0.0;
  for (const Particle& p : particles) {
    poses->push_back(p.pose.compose(since));
    weights->push_back(std::exp(p.log_weight - max_log));
    total += weights->back();
  }
  for (double& w : *weights) w /= total;
}

PoseEstimate SlamEngine::poseEstimate() const {
  std::vector<Pose2> poses;
  std::vector<double> weights;
  particlePoses(&poses, &weights);
  PoseEstimate e;
  double x = 0.0, y = 0.0, s = 0.0, c = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    x += weights[i] * poses[i].x;
    y += weights[i] * poses[i].y;
    s += weights[i] * std::sin(poses[i].theta);
    c += weights[i] * std::cos(poses[i].theta);
  }
  e.mean = Pose2(x, y, std::atan2(s, c));
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d d(poses[i].x - e.mean.x, poses[i].y - e.mean.y,
                            normalizeAngle(poses[i].theta - e.mean.theta));
    e.covariance += weights[i] * d * d.transpose();
  }
  return e;
}

Pose2 SlamEngine::mapToOdom() const { return bestPose().compose(last_odometry_.inverse()); }

std::vector<StampedPose> SlamEngine::bestTrajectory() const {
  std::vector<StampedPose> out;
  out.reserve(scan_records_.size());
  const size_t steps = step_odometry_.size();
  std::vector<Pose2> step_pose(steps);
  if (!filter_->particles().empty()) {
    for (const PathNode* n = filter_->best().path.get(); n != nullptr; n = n->parent.get()) {
      if (n->step >= 0 && static_cast<size_t>(n->step) < steps) step_pose[n->step] = n->pose;
    }
  }
  for (const ScanRecord& r : scan_records_) {
    if (r.step < 0) {             // before the first processed scan
      if (start_ && steps > 0) {  // on a start map: where the first processed scan puts it
        out.push_back(
            StampedPose{r.stamp, step_pose[0].compose(step_odometry_[0].between(r.odometry))});
      } else {
        out.push_back(StampedPose{r.stamp, poseBeforeFirstScan(r.odometry)});
      }
      continue;
    }
    const size_t s = static_cast<size_t>(r.step);
    // Dead reckoning from the processed scan before this one...
    Pose2 pose = step_pose[s].compose(step_odometry_[s].between(r.odometry));
    if (s + 1 < steps && step_stamps_[s + 1] > step_stamps_[s]) {
      // ...with the odometry's drift up to the next processed scan spread over the segment in
      // proportion to time (the path is written after the fact, so both ends are known).
      const Pose2 predicted_next =
          step_pose[s].compose(step_odometry_[s].between(step_odometry_[s + 1]));
      const Pose2 drift = predicted_next.between(step_pose[s + 1]);
      const double alpha = std::clamp(
          (r.stamp - step_stamps_[s]) / (step_stamps_[s + 1] - step_stamps_[s]), 0.0, 1.0);
      pose = pose.compose(Pose2(alpha * drift.x, alpha * drift.y, alpha * drift.theta));
    }
    out.push_back(StampedPose{r.stamp, pose});
  }
  return out;
}

}  // namespace evidential_slam
