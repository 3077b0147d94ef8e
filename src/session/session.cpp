#include "evidential_slam/session/session.h"

#include <cmath>
#include <cstdio>

namespace evidential_slam {

MappingSession::MappingSession(const Parameters& params)
    : params_(params),
      engine_(std::make_unique<SlamEngine>(params.slam)),
      alarm_(params.conflict_alarm) {}

SessionScanResult MappingSession::processScan(const Pose2& odometry, const LaserScan& scan) {
  SessionScanResult result;
  const double stamp = scan.stamp;
  result.stamp = stamp;
  if (have_last_stamp_ && stamp < last_stamp_) {
    char text[160];
    const double back = last_stamp_ - stamp;
    if (back > params_.session.time_jump_tolerance) {
      std::snprintf(text, sizeof(text),
                    "time jumped back by %.3f s (%.3f -> %.3f): the SLAM starts over", back,
                    last_stamp_, stamp);
      reset();
      ++restarts_;
      result.order = SessionScanResult::Order::kRestarted;
      result.message = text;
    } else {
      std::snprintf(text, sizeof(text),
                    "scan at %.3f is older than the previous one (%.3f): dropped", stamp,
                    last_stamp_);
      ++dropped_;
      result.order = SessionScanResult::Order::kDropped;
      result.message = text;
      return result;
    }
  }
  have_last_stamp_ = true;
  last_stamp_ = stamp;
  result.update = engine_->processScan(odometry, scan);
  if (result.update.processed && !engine_->mappingPaused()) {
    result.alarm = alarm_.update(result.update.open_space_conflict_added);
    conflict_log_.push_back(ConflictRecord{stamp, result.update.external_conflict_added,
                                           result.update.conflict_mass_added, result.alarm});
  }
  return result;
}

bool MappingSession::reconfigure(const Parameters& params, std::string* why) {
  Parameters next = params;
  if (!next.isValid(why) || !engine_->reconfigure(next.slam, why)) return false;
  next.slam = engine_->config();  // the start-up parameters keep their values
  params_ = next;
  alarm_.setConfig(params_.conflict_alarm);
  return true;
}

void MappingSession::reset() {
  engine_->reset();
  alarm_.reset();
  conflict_log_.clear();
  have_last_stamp_ = false;
}

void MappingSession::startOver() {
  engine_->clearStartMap();
  reset();
}

bool MappingSession::startFromMap(const EvidentialGridMap& map, const Pose2& pose, std::string* why,
                                  const Pose2* odometry) {
  const double resolution = map.resolution();
  if (!(resolution > 0.0) || std::abs(resolution - params_.slam.resolution) <= 1e-9 * resolution) {
    if (!engine_->startFromMap(map, pose, why, odometry)) return false;
  } else {
    // The resolution is a start-up parameter: the map's comes with a new engine.
    Parameters next = params_;
    next.slam = engine_->config();
    next.slam.resolution = resolution;
    if (!next.isValid(why)) return false;
    auto engine = std::make_unique<SlamEngine>(next.slam);
    engine->setMappingPaused(engine_->mappingPaused());
    if (!engine->startFromMap(map, pose, why, odometry)) return false;
    engine_ = std::move(engine);
    params_.slam.resolution = resolution;
  }
  alarm_.reset();
  conflict_log_.clear();
  have_last_stamp_ = false;
  return true;
}

EvidentialGridMap MappingSession::currentMap() const {
  if (!engine_->filter().particles().empty()) return engine_->bestMap();
  return EvidentialGridMap(params_.slam.resolution);
}

}  // namespace evidential_slam
