// The closed exploration loop on the simulator. See exploration_run.h.
#include "evidential_slam/io/exploration_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>

#include "evidential_slam/core/exploration/coverage.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/slam_engine.h"
#include "evidential_slam/io/atomic_files.h"

namespace evidential_slam {
namespace io {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

bool ExplorationRunConfig::isValid(std::string* why) const {
  auto fail = [why](const std::string& what) {
    if (why != nullptr) *why = what;
    return false;
  };
  std::string reason;
  if (!simulator.isValid(&reason)) return fail("simulator: " + reason);
  if (!simulator.waypoints.empty()) return fail("simulator: exploration drives it: no waypoints");
  if (!slam.isValid(&reason)) return fail("slam: " + reason);
  if (!explorer.isValid(&reason)) return fail("explorer: " + reason);
  if (!(max_time > 0.0) || !std::isfinite(max_time)) return fail("max_time must be > 0 (s)");
  if (!(coverage_period > 0.0) || !std::isfinite(coverage_period)) {
    return fail("coverage_period must be > 0 (s)");
  }
  if (map_margin_cells < 1) return fail("map_margin_cells must be >= 1");
  return true;
}

bool runExploration(const ExplorationRunConfig& config, ExplorationRunResult* result,
                    std::string* error, const ExplorationProgress& progress) {
  auto fail = [error](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  std::string why;
  if (!config.isValid(&why)) return fail("invalid exploration run: " + why);
  GridmapSimulatorConfig sim_config = config.simulator;
  sim_config.duration = 0.0;  // the loop decides when to stop
  GridmapSimulator sim(sim_config);
  if (!sim.load(&why)) return fail(why);
  SlamEngine engine(config.slam);
  exploration::Explorer explorer(config.explorer);

  ExplorationRunResult& r = *result;
  r = ExplorationRunResult();
  const Clock::time_point wall_start = Clock::now();
  const Pose2 start = sim.truePose();  // the SLAM's map frame is the robot's start pose
  const exploration::OccupancyImage& truth = sim.obstacles();
  const std::vector<uint8_t> reachable =
      exploration::reachableFreeCells(truth, start.translation());
  for (uint8_t cell : reachable) r.reachable_cells += cell;
  r.gap_band_m = exploration::thetaGapBand(
      config.slam.sensor.free_gap, std::max(config.slam.sensor.hit_sigma, sim_config.range_noise),
      config.slam.resolution);
  const std::vector<uint8_t> beyond_gap =
      exploration::cellsBeyondBand(truth, reachable, r.gap_band_m);
  for (uint8_t cell : beyond_gap) r.reachable_cells_beyond_gap += cell;
  r.min_wall_distance_m = 1.0;

  std::shared_ptr<const LayerRaster> raster;
  double next_sample = 0.0;
  Eigen::Vector2d last_position = start.translation();
  auto sample = [&](double t) {
    const double covered = exploration::knownFraction(truth, reachable, *raster, start);
    r.coverage.push_back({t, r.distance_m, covered});
    if (r.time_to_90_s < 0.0 && covered >= 0.90) r.time_to_90_s = t;
    if (r.time_to_99_s < 0.0 && covered >= 0.99) r.time_to_99_s = t;
    r.final_coverage = covered;
    r.final_coverage_beyond_gap =
        exploration::knownFraction(truth, beyond_gap, *raster, start);
  };

  SimulatedScan scan;
  double t = 0.0;
  std::vector<StampedPose> true_path;  // in the SLAM's map frame (the start pose)
  while (sim.step(&scan)) {
    t = scan.stamp - sim_config.start_time;
    true_path.push_back({scan.stamp, start.between(scan.true_pose)});
    r.distance_m += (scan.true_pose.translation() - last_position).norm();
    last_position = scan.true_pose.translation();
    r.min_wall_distance_m = std::min(
        r.min_wall_distance_m, exploration::distanceToObstacle(truth, last_position, 1.0));
    ++r.scans;

    Clock::time_point tick = Clock::now();
    engine.processScan(scan.odometry, scan.scan);
    r.slam_time_s += secondsSince(tick);

    tick = Clock::now();
    const Pose2 pose = engine.bestPose();
    std::shared_ptr<const LayerRaster> fresh;
    const bool stopping = t >= config.max_time;
    if (explorer.wantsMap(scan.stamp) || t >= next_sample) {
      fresh = std::make_shared<const LayerRaster>(
          extractLayers(engine.bestMap(), config.map_margin_cells));
      raster = fresh;
    }
    const exploration::VelocityCommand cmd = explorer.update(scan.stamp, pose, fresh);
    r.explorer_time_s += secondsSince(tick);
    sim.setVelocityCommand(cmd.linear, cmd.angular);

    if (explorer.done() || stopping || (progress && !progress(t, r))) break;
    if (t >= next_sample) {
      sample(t);
      next_sample += config.coverage_period;
    }
  }
  // The last sample on the map as it is at the end.
  raster = std::make_shared<const LayerRaster>(
      extractLayers(engine.bestMap(), config.map_margin_cells));
  sample(t);

  r.sim_time_s = t;
  r.collisions = sim.collisions();
  r.scans_processed = engine.stats().scans_processed;
  r.done = explorer.done();
  r.stop_reason = r.done ? explorer.stopMessage() : "max_time reached";
  r.explorer_stats = explorer.stats();
  r.final_map = raster;
  r.start_pose = start;
  const Pose2 truth_in_map = start.between(sim.truePose());
  r.final_position_error_m = (engine.bestPose().translation() - truth_in_map.translation()).norm();
  AteResult ate;
  if (computeAte(engine.bestTrajectory(), true_path, 0.05, &ate, nullptr)) {
    r.ate_rmse_m = ate.rmse;
    r.ate_max_m = ate.max_error;
  }
  r.wall_time_s = secondsSince(wall_start);
  return true;
}

bool writeExplorationJson(const std::string& path, const ExplorationRunResult& r,
                          std::string* error) {
  nlohmann::ordered_json j;
  j["final_coverage"] = r.final_coverage;
  nlohmann::ordered_json curve = nlohmann::ordered_json::array();
  for (const CoverageSample& s : r.coverage) curve.push_back({s.time, s.distance, s.coverage});
  j["coverage"] = curve;
  j["distance_m"] = r.distance_m;
  j["sim_time_s"] = r.sim_time_s;
  j["collisions"] = r.collisions;
  j["min_wall_distance_m"] = r.min_wall_distance_m;
  auto seconds_or_null = [](double s) {
    return s < 0.0 ? nlohmann::ordered_json() : nlohmann::ordered_json(s);
  };
  j["time_to_90_s"] = seconds_or_null(r.time_to_90_s);
  j["time_to_99_s"] = seconds_or_null(r.time_to_99_s);
  j["stop_reason"] = r.stop_reason;
  j["done"] = r.done;
  j["scans"] = r.scans;
  j["reachable_cells"] = r.reachable_cells;
  j["gap_band_m"] = r.gap_band_m;
  j["reachable_cells_beyond_gap"] = r.reachable_cells_beyond_gap;
  j["final_coverage_beyond_gap"] = r.final_coverage_beyond_gap;
  j["final_position_error_m"] = r.final_position_error_m;
  auto metres_or_null = [](double m) {
    return m < 0.0 ? nlohmann::ordered_json() : nlohmann::ordered_json(m);
  };
  j["ate_rmse_m"] = metres_or_null(r.ate_rmse_m);
  j["ate_max_m"] = metres_or_null(r.ate_max_m);
  j["wall_time_s"] = r.wall_time_s;
  if (r.internals_measured) {
    j["scans_processed"] = r.scans_processed;
    j["slam_time_s"] = r.slam_time_s;
    j["explorer_time_s"] = r.explorer_time_s;
    j["goals"] = {{"chosen", r.explorer_stats.goals_chosen},
                  {"reached", r.explorer_stats.goals_reached},
                  {"no_path", r.explorer_stats.goals_no_path},
                  {"no_progress", r.explorer_stats.goals_no_progress},
                  {"replans", r.explorer_stats.replans}};
  }
  return writeFileAtomically(
      path, [&](std::ostream& out) { return static_cast<bool>(out << j.dump(2) << '\n'); }, error);
}

}  // namespace io
}  // namespace evidential_slam
