#include "evidential_slam/core/exploration/explorer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {
namespace exploration {

ExplorerConfig::ExplorerConfig() { ES_EXPLORER_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this)) }

bool ExplorerConfig::isValid(std::string* why) const {
  bool ok =
      cells.isValid(why) && frontiers.isValid(why) && planner.isValid(why) && pursuit.isValid(why);
  ES_EXPLORER_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  return ok;
}

Explorer::Explorer(const ExplorerConfig& config) : config_(config) {}

namespace {

// The first layer the explorer reads that holds a non-finite value ("BetP(o) at cell 12: nan"),
// or "" (EC may be +inf, never NaN).
std::string nonFiniteLayer(const LayerRaster& map) {
  const size_t n = static_cast<size_t>(map.width) * static_cast<size_t>(map.height);
  const std::pair<Layer, const char*> layers[] = {{Layer::kPignistic, "BetP(o)"},
                                                  {Layer::kNonspecificity, "NS"},
                                                  {Layer::kEntropy, "H(BetP)"},
                                                  {Layer::kExternalConflict, "EC"}};
  for (const auto& [layer, name] : layers) {
    const std::vector<float>& v = map.layer(layer);
    if (v.size() < n) return std::string(name) + " has fewer values than cells";
    for (size_t i = 0; i < n; ++i) {
      if (layer == Layer::kExternalConflict ? std::isnan(v[i]) : !std::isfinite(v[i])) {
        return std::string(name) + " at cell " + std::to_string(i) + ": " + std::to_string(v[i]);
      }
    }
  }
  return "";
}

}  // namespace

bool Explorer::wantsMap(double time) const {
  return !done() && (!map_ || !has_goal_ || time >= next_replan_);
}

bool Explorer::isBlacklisted(const Eigen::Vector2d& position) const {
  for (const BlacklistEntry& b : blacklist_) {
    if ((b.position - position).norm() < config_.blacklist_radius) return true;
  }
  return false;
}

void Explorer::addToBlacklist(const Eigen::Vector2d& position, double time,
                              const std::string& why) {
  blacklist_.push_back({position, time, why});
}

VelocityCommand Explorer::update(double time, const Pose2& pose,
                                 std::shared_ptr<const LayerRaster> map) {
  if (map) {
    const std::string bad = nonFiniteLayer(*map);
    if (!bad.empty()) {
      // A map that cannot be read must not be driven on, nor the one before it (the SLAM that
      // made it is in trouble): stop until a good one comes.
      map_.reset();
      has_goal_ = false;
      path_.clear();
      map_failed_ = true;
      fault_ = "map refused: " + bad;
      return {};
    }
    // A map without a single observed cell is no map yet (nothing integrated): it would read as
    // "no frontier left".
    if (std::find(map->observed.begin(), map->observed.end(), 1) != map->observed.end()) {
      map_ = std::move(map);
      map_failed_ = false;
    }
  }
  if (!map_failed_) fault_.clear();
  if (!std::isfinite(time) || !std::isfinite(pose.x) || !std::isfinite(pose.y) ||
      !std::isfinite(pose.theta)) {
    if (!map_failed_) fault_ = "the pose or the time is not finite";
    return {};
  }
  if (done() || !map_) return {};
  if (!has_goal_ || time >= next_replan_) replan(time, pose);
  if (done()) return {};
  VelocityCommand cmd = purePursuit(pose, path_, config_.pursuit);
  if (cmd.goal_reached) {
    ++stats_.goals_reached;
    addToBlacklist(goal_.goal, time, "reached");
    has_goal_ = false;
    replan(time, pose);
    if (done()) return {};
    cmd = purePursuit(pose, path_, config_.pursuit);
    cmd.goal_reached = false;
  }
  return cmd;
}

void Explorer::replan(double time, const Pose2& pose) {
  ++stats_.replans;
  next_replan_ = time + 1.0 / config_.planner_frequency;
  const LayerRaster& map = *map_;
  const GridGeometry g = GridGeometry::of(map);
  const Eigen::Vector2d robot = pose.translation();
  const std::vector<CellClass> classes = classifyCells(map, config_.cells);
  const CostGrid grid(g, classes, config_.planner, &robot);
  const std::vector<float> reach = costToReach(grid, robot);

  frontiers_ = findFrontiers(g, classes, robot, config_.frontiers);
  const size_t frontier_count = frontiers_.size();
  if (config_.frontiers.revisit_conflict) {
    for (Frontier& f : findConflictClusters(map, robot, config_.frontiers)) {
      frontiers_.push_back(std::move(f));
    }
  }
  placeGoals(g, classes, reach, config_.frontiers, &frontiers_);
  // Blacklisted goals are not scored (scoring casts rays); they stay listed, unreachable.
  for (Frontier& f : frontiers_) {
    if (f.reachable && isBlacklisted(f.goal)) f.reachable = false;
  }
  scoreFrontiers(map, classes, config_.frontiers, &frontiers_);

  std::vector<size_t> order;
  for (size_t k = 0; k < frontiers_.size(); ++k) {
    if (frontiers_[k].reachable) order.push_back(k);
  }
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return frontiers_[a].utility > frontiers_[b].utility; });

  while (!order.empty()) {
    size_t chosen = order.front();
    // Keep the current goal (the candidate nearest it, within blacklist_radius) unless the best
    // beats it by the margin: goals of similar worth must not take turns.
    if (has_goal_) {
      for (size_t k : order) {
        const Frontier& f = frontiers_[k];
        if ((f.goal - goal_.goal).norm() >= config_.blacklist_radius) continue;
        const double best = frontiers_[order.front()].utility;
        if (best <= f.utility + config_.goal_switch_margin * std::abs(f.utility)) chosen = k;
        break;
      }
    }
    const Frontier& candidate = frontiers_[chosen];
    PlanResult plan = planPath(grid, robot, candidate.goal);
    const bool same_goal =
        has_goal_ && (candidate.goal - goal_.goal).norm() < config_.blacklist_radius;
    if (plan.found) {
      // Progress: the path got shorter, or the goal itself moved (the frontier receded: the map
      // grew there).
      if (!same_goal) ++stats_.goals_chosen;
      if (!same_goal || plan.cost < best_cost_ - config_.progress_distance ||
          (candidate.goal - progress_goal_).norm() > config_.progress_distance) {
        best_cost_ = plan.cost;
        progress_goal_ = candidate.goal;
        last_progress_ = time;
      }
      if (!same_goal || time - last_progress_ <= config_.progress_timeout) {
        goal_ = candidate;
        path_ = std::move(plan.path);
        has_goal_ = true;
        return;
      }
      char why[64];
      std::snprintf(why, sizeof(why), "no progress for %.0f s", time - last_progress_);
      addToBlacklist(candidate.goal, time, why);
      ++stats_.goals_no_progress;
    } else {
      addToBlacklist(candidate.goal, time, "no path: " + plan.why);
      ++stats_.goals_no_path;
    }
    has_goal_ = false;
    order.erase(std::find(order.begin(), order.end(), chosen));
    // Candidates that the new blacklist entry covers go too.
    order.erase(std::remove_if(order.begin(), order.end(),
                               [&](size_t k) { return isBlacklisted(frontiers_[k].goal); }),
                order.end());
  }

  has_goal_ = false;
  path_.clear();
  size_t blacklisted = 0, unreachable = 0;
  for (const Frontier& f : frontiers_) {
    if (f.goal_cell >= 0 && isBlacklisted(f.goal)) {
      ++blacklisted;
    } else {
      ++unreachable;
    }
  }
  if (frontiers_.empty()) {
    stop_reason_ = StopReason::kNoFrontier;
    stop_message_ = "done: no frontier left";
  } else {
    stop_reason_ = StopReason::kNoReachableGoal;
    stop_message_ = "done: " + std::to_string(frontier_count) + " frontier(s) and " +
                    std::to_string(frontiers_.size() - frontier_count) +
                    " revisit cluster(s) left, none to go to (" + std::to_string(unreachable) +
                    " unreachable, " + std::to_string(blacklisted) + " blacklisted)";
  }
}

}  // namespace exploration
}  // namespace evidential_slam
