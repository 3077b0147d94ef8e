#include "evidential_slam/session/session.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "evidential_slam/session/map_files.h"

namespace evidential_slam {
namespace {

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char text[200];
  std::snprintf(text, sizeof(text), fmt, a, b, c, d);
  return text;
}

}  // namespace

StampPolicy stampPolicy(const SessionConfig& c) {
  StampPolicy p;
  p.tolerance = c.time_jump_tolerance;
  p.forward = c.time_jump_forward;
  p.scans = c.time_jump_scans;
  return p;
}

bool poseWithinMapExtent(const Pose2& pose, double max_map_extent, const std::string& what,
                         std::string* why) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    if (why != nullptr) *why = what + " is not finite";
    return false;
  }
  if (std::abs(pose.x) > max_map_extent || std::abs(pose.y) > max_map_extent) {
    if (why != nullptr) {
      *why = what + format(
                        " (%.6g, %.6g) m is farther than max_map_extent (%.0f m) from the "
                        "map frame's origin",
                        pose.x, pose.y, max_map_extent);
    }
    return false;
  }
  return true;
}

MappingSession::MappingSession(const Parameters& params)
    : params_(params),
      engine_(std::make_unique<SlamEngine>(params.slam)),
      alarm_(params.conflict_alarm) {}

SessionScanResult MappingSession::processScan(const Pose2& odometry, const LaserScan& scan) {
  SessionScanResult result;
  const double stamp = scan.stamp;
  result.stamp = stamp;
  const SessionConfig& c = params_.session;
  auto refuse = [&](const std::string& why) {
    ++refused_;
    result.order = SessionScanResult::Order::kRefused;
    result.message = why;
    return result;
  };
  if (!std::isfinite(stamp)) return refuse("scan refused: its stamp is not a finite number");
  if (scan.size() > static_cast<size_t>(c.max_scan_rays)) {
    return refuse("scan at " + format("%.3f", stamp) + " refused: " + std::to_string(scan.size()) +
                  " rays, more than max_scan_rays (" + std::to_string(c.max_scan_rays) + ")");
  }
  if (!std::isfinite(odometry.x) || !std::isfinite(odometry.y) || !std::isfinite(odometry.theta)) {
    return refuse("scan at " + format("%.3f", stamp) + " refused: its odometry pose is not finite");
  }
  if (!have_origin_ && localizer_ == nullptr) {
    // Where the first scan puts the robot in the map frame (a fresh map's frame is the odom
    // frame; a start map's is its pose, moved by the odometry since its anchor).
    std::string why;
    if (!poseWithinMapExtent(engine_->poseBeforeFirstScan(odometry), c.max_map_extent,
                             "the pose its odometry gives", &why)) {
      return refuse(format("scan at %.3f refused: ", stamp) + why);
    }
  }
  if (have_origin_) {
    const double distance = std::hypot(odometry.x - origin_.x, odometry.y - origin_.y);
    if (distance > c.max_map_extent) {
      return refuse(
          format("scan at %.3f refused: the odometry is %.0f m from where the map "
                 "started, beyond max_map_extent (%.0f m)",
                 stamp, distance, c.max_map_extent));
    }
  }

  // The stamp policy shared with the rawlog reader (core/stamp_order.h).
  order_.setPolicy(stampPolicy(c));
  const double previous = order_.last();
  const double step = stamp - previous;
  switch (order_.next(stamp)) {
    case StampOrder::Verdict::kOutlier: {
      const bool back = step < 0.0;
      ++outliers_;
      result.order = SessionScanResult::Order::kOutlier;
      result.message = "scan at " + format("%.3f", stamp) + " dropped: stamped " +
                       format("%.3f", std::abs(step)) + " s " + (back ? "behind" : "ahead of") +
                       " the previous one (" + format("%.3f", previous) + "), an outlier; " +
                       std::to_string(order_.jumpsInARow()) + " of " +
                       std::to_string(c.time_jump_scans) + " such scans in a row before " +
                       (back ? "the SLAM starts over" : "time moves on");
      return result;
    }
    case StampOrder::Verdict::kDropped:
      ++dropped_;
      result.order = SessionScanResult::Order::kDropped;
      result.message =
          format("scan at %.3f is older than the previous one (%.3f): dropped", stamp, previous);
      return result;
    case StampOrder::Verdict::kJumpedBack: {
      const std::string reason =
          format("time jumped back by %.3f s (%.3f -> %.3f)", -step, previous, stamp) + " for " +
          std::to_string(c.time_jump_scans) + " scans in a row";
      restart(reason, &result.message);  // forgets the stamp order: this stamp starts it again
      order_.next(stamp);
      result.order = SessionScanResult::Order::kRestarted;
      break;
    }
    case StampOrder::Verdict::kInOrder:
    case StampOrder::Verdict::kJumpedAhead:
      break;
  }
  have_last_stamp_ = true;
  last_stamp_ = stamp;
  if (!have_origin_) {
    have_origin_ = true;
    origin_ = odometry;
  }
  if (localizer_ != nullptr) {
    result.localization = localizer_->processScan(odometry, scan);
    return result;
  }
  result.update = engine_->processScan(odometry, scan);
  if (result.update.processed && !engine_->mappingPaused()) {
    result.alarm = alarm_.update(result.update.contradiction_added);
    conflict_log_.push_back(ConflictRecord{stamp, result.update.external_conflict_added,
                                           result.update.conflict_mass_added,
                                           result.update.open_space_conflict_added, result.alarm});
  }
  return result;
}

std::string MappingSession::saveBeforeReset() {
  if (!params_.session.save_before_reset) return "the map was not saved (save_before_reset off)";
  if (engine_->stats().scans_processed == 0) return "there was no map to save";
  if (reset_save_root_.empty()) return "the map was not saved (no directory given)";
  const std::string dir =
      (std::filesystem::path(reset_save_root_) / ("before_reset_" + format("%.3f", last_stamp_)))
          .string();
  MapFilesReport report;
  std::string error;
  if (!writeMapFiles(dir, captureMapSave(*this), params_.session, &report, &error)) {
    return "the map could not be saved: " + error;
  }
  last_reset_save_ = dir;
  return "the map before it is saved in " + dir;
}

void MappingSession::restart(const std::string& reason, std::string* message) {
  if (localizer_ != nullptr) {
    reset();
    ++restarts_;
    if (message != nullptr) *message = reason + ": localization starts over where it started";
    return;
  }
  const std::string saved = saveBeforeReset();
  reset();
  ++restarts_;
  if (message != nullptr) *message = reason + ": the SLAM starts over; " + saved;
}

bool MappingSession::reconfigure(const Parameters& params, std::string* why) {
  Parameters next = params;
  // Both engines refuse only invalid parameters, which isValid has checked.
  if (!next.isValid(why) || !engine_->reconfigure(next.slam, why)) return false;
  next.slam = engine_->config();  // the start-up parameters keep their values
  if (localizer_ != nullptr && !localizer_->reconfigure(next.localization, next.slam, why)) {
    return false;
  }
  params_ = next;
  alarm_.setConfig(params_.conflict_alarm);
  if (localizer_ != nullptr) localizer_->setAlarmConfig(params_.conflict_alarm);
  return true;
}

void MappingSession::forgetScanOrder() {
  alarm_.reset();
  conflict_log_.clear();
  have_last_stamp_ = false;
  order_.reset();
  have_origin_ = false;
}

void MappingSession::reset() {
  engine_->reset();
  if (localizer_ != nullptr) {
    std::string why;
    // The start was accepted on this map before: it is again.
    startLocalizer(localizer_.get(), localization_start_, &why);
  }
  forgetScanOrder();
}

void MappingSession::startOver() {
  localizer_.reset();
  engine_->clearStartMap();
  reset();
}

void MappingSession::startOver(const std::string& reason, std::string* message) {
  const std::string saved = saveBeforeReset();
  startOver();
  if (message != nullptr) *message = reason + ": the SLAM starts over with no map; " + saved;
}

bool MappingSession::startLocalizer(Localizer* localizer, const LocalizationStart& start,
                                    std::string* why) {
  return start.global ? localizer->globalLocalization(why)
                      : localizer->resetAt(start.pose, start.covariance, why);
}

bool MappingSession::startLocalization(const EvidentialGridMap& map, const LocalizationStart& start,
                                       std::string* why) {
  if (!start.global &&
      !poseWithinMapExtent(start.pose, params_.session.max_map_extent, "the start pose", why)) {
    return false;
  }
  auto localizer =
      std::make_unique<Localizer>(params_.localization, engine_->config(), params_.conflict_alarm);
  if (!localizer->setMap(map, why) || !startLocalizer(localizer.get(), start, why)) return false;
  localizer_ = std::move(localizer);
  localization_start_ = start;
  engine_->reset();
  forgetScanOrder();
  return true;
}

bool MappingSession::restartLocalization(const LocalizationStart& start, std::string* why) {
  if (localizer_ == nullptr) {
    if (why != nullptr) *why = "not in localization mode";
    return false;
  }
  if (!start.global &&
      !poseWithinMapExtent(start.pose, params_.session.max_map_extent, "the start pose", why)) {
    return false;
  }
  if (!startLocalizer(localizer_.get(), start, why)) return false;
  localization_start_ = start;
  return true;
}

bool MappingSession::startFromMap(const EvidentialGridMap& map, const Pose2& pose, std::string* why,
                                  const Pose2* odometry) {
  if (!poseWithinMapExtent(pose, params_.session.max_map_extent, "the start pose", why)) {
    return false;
  }
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
  localizer_.reset();
  forgetScanOrder();
  return true;
}

EvidentialGridMap MappingSession::currentMap() const {
  if (!engine_->filter().particles().empty()) return engine_->bestMap();
  return EvidentialGridMap(params_.slam.resolution);
}

}  // namespace evidential_slam
