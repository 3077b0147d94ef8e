#include "evidential_slam/ros/map_fusion_nodelet.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <pluginlib/class_list_macros.hpp>

#include "evidential_slam/core/fusion/alignment.h"
#include "evidential_slam/core/fusion/map_fusion.h"
#include "evidential_slam/ros/parameter_text.h"

namespace evidential_slam {
namespace ros_adapter {
MapFusionNodelet::~MapFusionNodelet() {
  // No timer or subscriber callback may run into members being destroyed.
  discovery_timer_.stop();
  merging_timer_.stop();
  for (auto& [name, robot] : robots_) robot.sub.shutdown();  // outside the lock onGrid takes
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  publisher_.reset();  // its thread reads fused_
}

void MapFusionNodelet::onInit() {
  nh_ = getNodeHandle();
  private_nh_ = getPrivateNodeHandle();
  std::string why;
  if (!readMapFusionParams(private_nh_, &params_, &why) || !params_.isValid(&why)) {
    NODELET_FATAL("map_fusion: invalid parameters: %s; the fusion does not start", why.c_str());
    return;
  }
  fusion::parseRule(params_.rule, &rule_);
  publisher_ = std::make_unique<MapPublisher>(nh_, private_nh_, params_.world_frame, [this] {
    std::lock_guard<std::mutex> lock(fused_mutex_);
    return fused_;
  });
  publisher_->setThresholds(params_.session.occupied_thresh, params_.session.free_thresh);
  NODELET_INFO("map_fusion: %s rule, discount %g, robots' maps on */%s%s%s, %s poses",
               params_.rule.c_str(), params_.discount, params_.robot_map_topic.c_str(),
               params_.robot_namespace.empty() ? "" : " containing ",
               params_.robot_namespace.c_str(),
               params_.known_init_poses ? "known initial" : "estimated");
  thread_ = std::thread([this] { run(); });
  discover();
  discovery_timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / params_.discovery_rate),
                                         [this](const ros::WallTimerEvent&) { discover(); });
  merging_timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / params_.merging_rate),
                                       [this](const ros::WallTimerEvent&) {
                                         {
                                           std::lock_guard<std::mutex> lock(mutex_);
                                           wake_requested_ = true;
                                         }
                                         wake_.notify_one();
                                       });
}

void MapFusionNodelet::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || wake_requested_; });
    if (stop_) return;
    wake_requested_ = false;
    lock.unlock();
    try {
      fuseOnce();
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "map_fusion: %s", e.what());
    }
    lock.lock();
  }
}

bool MapFusionNodelet::fuseOnce() {
  const ros::WallTime cycle_start = ros::WallTime::now();
  // A consistent copy of the robots (maps are shared, immutable).
  std::vector<Robot> robots;
  uint64_t changes = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    changes = changes_;
    if (changes == fused_changes_) return false;
    for (const auto& [name, r] : robots_) {
      if (!r.map) continue;
      Robot copy;
      copy.name = r.name;
      copy.has_pose = r.has_pose;
      copy.pose = r.pose;
      copy.has_prior = r.has_prior;
      copy.prior = r.prior;
      copy.map = r.map;
      copy.grid_frame = r.grid_frame;
      copy.version = r.version;
      copy.stamp = r.stamp;
      copy.estimated_at = r.estimated_at;
      copy.estimated = r.estimated;
      robots.push_back(std::move(copy));
    }
  }
  if (robots.empty()) return false;

  if (!params_.known_init_poses) {
    // The first robot (by name) is the reference: its map frame is world_frame.
    robots[0].has_pose = true;
    robots[0].pose = Pose2();
    const ros::WallTime now = ros::WallTime::now();
    for (size_t i = 1; i < robots.size(); ++i) {
      Robot& r = robots[i];
      const fusion::AlignmentInputs inputs{r.version, robots[0].name, robots[0].version};
      if (!fusion::alignmentDue(r.has_pose, r.estimated, r.estimated_at.toSec(), inputs,
                                now.toSec(), 1.0 / params_.estimation_rate)) {
        continue;
      }
      const bool new_reference = r.estimated.reference != inputs.reference;
      fusion::AlignmentResult result;
      std::string why;
      r.estimated_at = now;
      r.estimated = inputs;
      fusion::AlignmentConfig align;
      if (robots[0].has_prior && r.has_prior) {
        // Both init poses in world_frame: r's map frame in the reference's, then grid frames.
        align.has_prior = true;
        align.prior = robots[0]
                          .grid_frame.inverse()
                          .compose(robots[0].prior.inverse().compose(r.prior))
                          .compose(r.grid_frame);
      }
      const bool aligned = fusion::alignMaps(*robots[0].map, *r.map, align, &result, &why);
      times_.align_s += (ros::WallTime::now() - now).toSec();
      ++times_.alignments;
      if (aligned) {
        // Grid poses -> map frames: reference grid frame ∘ aligned ∘ this grid frame⁻¹.
        r.pose = robots[0].grid_frame.compose(result.pose).compose(r.grid_frame.inverse());
        r.has_pose = true;
        NODELET_INFO("map_fusion: robot %s at (%.3f, %.3f, %.4f) in %s's map (conflict %.3f)",
                     r.name.c_str(), r.pose.x, r.pose.y, r.pose.theta, robots[0].name.c_str(),
                     result.conflict);
      } else {
        if (new_reference) r.has_pose = false;  // its pose was in the former reference's frame
        auto warned = refusal_warned_at_.find(r.name);
        if (warned == refusal_warned_at_.end() || now.toSec() - warned->second >= 10.0) {
          refusal_warned_at_[r.name] = now.toSec();
          NODELET_WARN("map_fusion: robot %s not aligned yet: %s", r.name.c_str(), why.c_str());
        }
      }
    }
    std::lock_guard<std::mutex> lock(mutex_);
    for (const Robot& r : robots) {
      auto it = robots_.find(r.name);
      if (it == robots_.end()) continue;
      it->second.has_pose = r.has_pose;
      it->second.pose = r.pose;
      it->second.estimated_at = r.estimated_at;
      it->second.estimated = r.estimated;
    }
  }

  std::vector<fusion::FusionSource> sources;
  double stamp = 0.0;
  for (const Robot& r : robots) {
    if (!r.has_pose) continue;
    if (!sources.empty() &&
        std::abs(r.map->resolution() - sources.front().map->resolution()) > 1e-9) {
      NODELET_WARN_THROTTLE(10.0, "map_fusion: robot %s: %g m cells, not %g m: left out",
                            r.name.c_str(), r.map->resolution(), sources.front().map->resolution());
      continue;
    }
    fusion::FusionSource s;
    s.map = r.map.get();
    s.pose = r.pose.compose(r.grid_frame);
    s.discount = params_.discount;
    sources.push_back(s);
    stamp = std::max(stamp, r.stamp);
  }
  fused_changes_ = changes;
  if (sources.empty()) return false;
  fusion::FusionConfig config;
  config.rule = rule_;
  EvidentialGridMap fused;
  fusion::FusionReport report;
  std::string why;
  const ros::WallTime fuse_start = ros::WallTime::now();
  if (!fusion::fuseMaps(sources, config, &fused, &report, &why)) {
    NODELET_WARN_THROTTLE(10.0, "map_fusion: %s", why.c_str());
    return false;
  }
  const ros::WallTime end = ros::WallTime::now();
  {
    std::lock_guard<std::mutex> lock(fused_mutex_);
    fused_.grid = std::make_shared<const EvidentialGridMap>(std::move(fused));
    fused_.stamp = stamp;
    ++fused_.version;
    fused_.anomaly_version = fused_.version;
  }
  publisher_->requestUpdate();
  const double cycle_s = (end - cycle_start).toSec();
  ++times_.cycles;
  times_.fuse_s += (end - fuse_start).toSec();
  times_.total_s += cycle_s;
  times_.max_s = std::max(times_.max_s, cycle_s);
  NODELET_DEBUG("map_fusion: %zu maps, %zu cells, %zu overlapping, mean conflict %.4f; %.3f s",
                sources.size(), report.fused_cells, report.overlap_cells, report.mean_conflict,
                cycle_s);
  const double n = static_cast<double>(times_.cycles);
  NODELET_INFO_THROTTLE(60.0,
                        "map_fusion: %zu fusions of %zu cells (last), mean wall time %.3f s "
                        "(fusion %.3f s), longest cycle %.3f s; %zu alignments, %.3f s each",
                        times_.cycles, report.fused_cells, times_.total_s / n, times_.fuse_s / n,
                        times_.max_s, times_.alignments,
                        times_.alignments > 0 ? times_.align_s / times_.alignments : 0.0);
  return true;
}

}  // namespace ros_adapter
}  // namespace evidential_slam

PLUGINLIB_EXPORT_CLASS(evidential_slam::ros_adapter::MapFusionNodelet, nodelet::Nodelet)
