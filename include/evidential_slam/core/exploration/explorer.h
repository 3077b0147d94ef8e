// The exploration loop without ROS: given the latest layer raster, the robot's pose (map frame)
// and the time, it chooses a goal (frontiers.h), keeps or replaces it at a fixed rate, plans a
// path to it (planner.h) and follows it (pure_pursuit.h). Goals are blacklisted when reached (the
// frontier did not clear from there), when no path leads to them, or when the robot gains no
// distance on them for progress_timeout. It stops, and says why, when no goal is left.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/exploration/cell_classes.h"
#include "evidential_slam/core/exploration/frontiers.h"
#include "evidential_slam/core/exploration/planner.h"
#include "evidential_slam/core/exploration/pure_pursuit.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/parameter_fields/explorer.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace exploration {

struct ExplorerConfig {
  CellClassConfig cells;
  FrontierConfig frontiers;
  PlannerConfig planner;
  PursuitConfig pursuit;
  ExplorerConfig();  // the table's defaults
  ES_EXPLORER_FIELDS

  bool isValid(std::string* why) const;
};

enum class StopReason {
  kNone,
  kNoFrontier,       // no frontier (and no revisit goal) is left
  kNoReachableGoal,  // some are left, but none is reachable and not blacklisted
};

struct BlacklistEntry {
  Eigen::Vector2d position;
  double time = 0.0;
  std::string why;  // "reached", "no path: ...", "no progress for ... s"
};

struct ExplorerStats {
  uint64_t replans = 0;
  uint64_t goals_chosen = 0;  // goals different from the previous one
  uint64_t goals_reached = 0;
  uint64_t goals_no_path = 0;
  uint64_t goals_no_progress = 0;
};

class Explorer {
 public:
  // `config` must be valid (ExplorerConfig::isValid).
  explicit Explorer(const ExplorerConfig& config);

  // Call at the control rate with the time (s), the robot's pose in the map's frame and, when a
  // new one is at hand, the latest map (nullptr: keep the last; a map with no observed cell is
  // ignored; a map with a non-finite value stops the robot: fault()). Replans every 1 /
  // planner_frequency s, and at once when there is no goal or the goal was reached. Returns the
  // velocity command; (0, 0) without a map and once done.
  VelocityCommand update(double time, const Pose2& pose,
                         std::shared_ptr<const LayerRaster> map = nullptr);
  // Why the robot is stopped without being done, empty otherwise: the last map given held a
  // non-finite BetP(o), NS, H(BetP) or EC (it is dropped, with the last good one: the robot waits
  // for the next good map), or the pose or time of this update is not finite.
  const std::string& fault() const { return fault_; }
  // True when the next update() would replan: a caller that extracts rasters on demand gives a
  // fresh one then.
  bool wantsMap(double time) const;

  bool done() const { return stop_reason_ != StopReason::kNone; }
  StopReason stopReason() const { return stop_reason_; }
  // One line: why exploration stopped (empty while exploring).
  const std::string& stopMessage() const { return stop_message_; }

  bool hasGoal() const { return has_goal_; }
  const Frontier& goal() const { return goal_; }
  const std::vector<Eigen::Vector2d>& path() const { return path_; }
  // The frontiers and revisit clusters of the last replanning, scored.
  const std::vector<Frontier>& frontiers() const { return frontiers_; }
  const std::vector<BlacklistEntry>& blacklist() const { return blacklist_; }
  bool isBlacklisted(const Eigen::Vector2d& position) const;
  const ExplorerStats& stats() const { return stats_; }
  const ExplorerConfig& config() const { return config_; }

 private:
  void replan(double time, const Pose2& pose);
  void addToBlacklist(const Eigen::Vector2d& position, double time, const std::string& why);

  ExplorerConfig config_;
  std::shared_ptr<const LayerRaster> map_;
  double next_replan_ = -1e300;
  bool has_goal_ = false;
  Frontier goal_;
  std::vector<Eigen::Vector2d> path_;
  // At the last progress on the current goal: its path cost, its position, the time.
  double best_cost_ = 0.0;
  Eigen::Vector2d progress_goal_ = Eigen::Vector2d::Zero();
  double last_progress_ = 0.0;
  std::vector<Frontier> frontiers_;
  std::vector<BlacklistEntry> blacklist_;
  StopReason stop_reason_ = StopReason::kNone;
  std::string stop_message_;
  std::string fault_;
  bool map_failed_ = false;  // the last map given was refused (fault_ says why)
  ExplorerStats stats_;
};

}  // namespace exploration
}  // namespace evidential_slam
