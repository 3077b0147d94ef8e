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
  if (have_origin_) {
    const double distance = std::hypot(odometry.x - origin_.x, odometry.y - origin_.y);
    if (distance > c.max_map_extent) {
      return refuse(format("scan at %.3f refused: the odometry is %.0f m from where the map "
                           "started, beyond max_map_extent (%.0f m)",
                           stamp, distance, c.max_map_extent));
    }
  }

  if (have_last_stamp_) {
    const double step = stamp - last_stamp_;
    const bool back = step < -c.time_jump_tolerance;
    const bool ahead = step > c.time_jump_forward;
    if (back || ahead) {
      if (jumps_in_a_row_ == 0 || jump_back_ != back) jumps_in_a_row_ = 0;
      jump_back_ = back;
      ++jumps_in_a_row_;
      if (jumps_in_a_row_ < c.time_jump_scans) {
        ++outliers_;
        result.order = SessionScanResult::Order::kOutlier;
        result.message = "scan at " + format("%.3f", stamp) + " dropped: stamped " +
                         format("%.3f", std::abs(step)) + " s " + (back ? "behind" : "ahead of") +
                         " the previous one (" + format("%.3f", last_stamp_) + "), an outlier; " +
                         std::to_string(jumps_in_a_row_) + " of " +
                         std::to_string(c.time_jump_scans) + " such scans in a row before " +
                         (back ? "the SLAM starts over" : "time moves on");
        return result;
      }
      jumps_in_a_row_ = 0;
      if (back) {
        const std::string reason = format("time jumped back by %.3f s (%.3f -> %.3f)", -step,
                                          last_stamp_, stamp) +
                                   " for " + std::to_string(c.time_jump_scans) + " scans in a row";
        restart(reason, &result.message);
        result.order = SessionScanResult::Order::kRestarted;
      }
    } else if (step < 0.0) {
      jumps_in_a_row_ = 0;
      ++dropped_;
      result.order = SessionScanResult::Order::kDropped;
      result.message = format("scan at %.3f is older than the previous one (%.3f): dropped", stamp,
                              last_stamp_);
      return result;
    } else {
      jumps_in_a_row_ = 0;
    }
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
    result.alarm = alarm_.update(result.update.open_space_conflict_added);
    conflict_log_.push_back(ConflictRecord{stamp, result.update.external_conflict_added,
                                           result.update.conflict_mass_added, result.alarm});
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
  return true;
}

void MappingSession::forgetScanOrder() {
  alarm_.reset();
  conflict_log_.clear();
  have_last_stamp_ = false;
  jumps_in_a_row_ = 0;
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

bool MappingSession::startLocalizer(Localizer* localizer, const LocalizationStart& start,
                                    std::string* why) {
  return start.global ? localizer->globalLocalization(why)
                      : localizer->resetAt(start.pose, start.covariance, why);
}

bool MappingSession::startLocalization(const EvidentialGridMap& map, const LocalizationStart& start,
                                       std::string* why) {
  auto localizer = std::make_unique<Localizer>(params_.localization, engine_->config());
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
  if (!startLocalizer(localizer_.get(), start, why)) return false;
  localization_start_ = start;
  return true;
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
  localizer_.reset();
  forgetScanOrder();
  return true;
}

EvidentialGridMap MappingSession::currentMap() const {
  if (!engine_->filter().particles().empty()) return engine_->bestMap();
  return EvidentialGridMap(params_.slam.resolution);
}

}  // namespace evidential_slam
