#include "evidential_slam/session/session.h"

#include <cstdio>

namespace evidential_slam {

MappingSession::MappingSession(const Parameters& params)
    : params_(params), engine_(params.slam), alarm_(params.conflict_alarm) {}

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
  result.update = engine_.processScan(odometry, scan);
  if (result.update.processed) {
    result.alarm = alarm_.update(result.update.open_space_conflict_added);
    conflict_log_.push_back(ConflictRecord{stamp, result.update.external_conflict_added,
                                           result.update.conflict_mass_added, result.alarm});
  }
  return result;
}

bool MappingSession::reconfigure(const Parameters& params, std::string* why) {
  Parameters next = params;
  if (!next.isValid(why) || !engine_.reconfigure(next.slam, why)) return false;
  next.slam = engine_.config();  // the start-up parameters keep their values
  params_ = next;
  alarm_.setConfig(params_.conflict_alarm);
  return true;
}

void MappingSession::reset() {
  engine_.reset();
  alarm_.reset();
  conflict_log_.clear();
  have_last_stamp_ = false;
}

bool MappingSession::startFromMap(const EvidentialGridMap& map, const Pose2& pose, std::string* why,
                                  const Pose2* odometry) {
  if (!engine_.startFromMap(map, pose, why, odometry)) return false;
  alarm_.reset();
  conflict_log_.clear();
  have_last_stamp_ = false;
  return true;
}

}  // namespace evidential_slam
