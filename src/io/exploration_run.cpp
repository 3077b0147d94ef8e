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

// The final map's layers averaged over each kind of place of the world: the regions (glass,
// clutter), the free cells people walked over, the walls' faces (obstacle cells beside a free one)
// and the free space beyond the Θ-gap band at least kNearRegion from any region.
std::vector<PlaceLayers> placeLayers(const GridmapSimulator& sim,
                                     const std::vector<uint8_t>& beyond_gap, const LayerRaster& map,
                                     const Pose2& start) {
  const exploration::OccupancyImage& truth = sim.obstacles();
  const exploration::GridGeometry& g = truth.geometry;
  const exploration::GridGeometry m = exploration::GridGeometry::of(map);
  const Pose2 truth_in_map = start.inverse();
  const char* names[] = {"glass", "clutter", "people", "wall", "free"};
  std::vector<PlaceLayers> out(5);
  for (int k = 0; k < 5; ++k) out[k].kind = names[k];
  for (int i = 0; i < g.size(); ++i) {
    const Eigen::Vector2d p = g.center(i);
    int kind = -1;
    double nearest_region = 1e9;
    for (const WorldRegion& r : sim.regions()) {
      const double d = r.distanceTo(p);
      nearest_region = std::min(nearest_region, d);
      if (kind < 0 && d <= 0.5 * g.resolution) kind = r.kind == RegionKind::kGlass ? 0 : 1;
    }
    if (kind < 0 && truth.occupied[i]) {
      const int c = g.col(i), row = g.row(i);
      const bool face = (g.inside(c + 1, row) && !truth.occupiedAt(c + 1, row)) ||
                        (g.inside(c - 1, row) && !truth.occupiedAt(c - 1, row)) ||
                        (g.inside(c, row + 1) && !truth.occupiedAt(c, row + 1)) ||
                        (g.inside(c, row - 1) && !truth.occupiedAt(c, row - 1));
      if (face) kind = 3;
    }
    if (kind < 0 && !truth.occupied[i]) {
      for (const DynamicObject& o : sim.objects()) {
        if ((o.a0 - o.b0).norm() > 1e-9 || (o.a1 - o.b1).norm() > 1e-9) continue;  // bars
        const WorldRegion swept{RegionKind::kGlass, o.a0, o.a1, o.radius, 0.0};
        if (swept.contains(p)) {
          kind = 2;
          break;
        }
      }
      if (kind < 0 && beyond_gap[i] && nearest_region >= kNearRegion) kind = 4;
    }
    if (kind < 0) continue;
    const int j = m.indexOf(truth_in_map.transformPoint(p));
    if (j < 0 || !map.observed[j]) continue;
    PlaceLayers& l = out[kind];
    ++l.cells;
    l.betp += map.layer(Layer::kPignistic)[j];
    l.ns += map.layer(Layer::kNonspecificity)[j];
    l.ic += map.layer(Layer::kInternalConflict)[j];
    l.ec += map.layer(Layer::kExternalConflict)[j];
    l.entropy += map.layer(Layer::kEntropy)[j];
  }
  std::vector<PlaceLayers> kept;
  for (PlaceLayers& l : out) {
    if (l.cells == 0) continue;
    const double n = static_cast<double>(l.cells);
    l.betp /= n;
    l.ns /= n;
    l.ic /= n;
    l.ec /= n;
    l.entropy /= n;
    kept.push_back(l);
  }
  return kept;
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
    if (r.scans > 0) {
      for (const WorldRegion& region : sim.regions()) {
        if (region.distanceTo(last_position) <= kNearRegion) {
          r.time_near_regions_s += sim_config.scan_period;
          break;
        }
      }
    }
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
    if (!explorer.fault().empty()) {
      r.fault_time_s += sim_config.scan_period;
      if (r.first_fault.empty()) r.first_fault = explorer.fault();
    }
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
  if (!explorer.fault().empty()) r.stop_reason += " (stopped by a fault: " + explorer.fault() + ")";
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
  r.place_layers = placeLayers(sim, beyond_gap, *raster, start);
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
    j["fault_time_s"] = r.fault_time_s;
    j["first_fault"] = r.first_fault;
    j["time_near_regions_s"] = r.time_near_regions_s;
    nlohmann::ordered_json places = nlohmann::ordered_json::object();
    for (const PlaceLayers& l : r.place_layers) {
      places[l.kind] = {{"cells", l.cells}, {"betp", l.betp}, {"ns", l.ns},
                        {"ic", l.ic},       {"ec", l.ec},     {"entropy", l.entropy}};
    }
    j["place_layers"] = places;
  }
  return writeFileAtomically(
      path, [&](std::ostream& out) { return static_cast<bool>(out << j.dump(2) << '\n'); }, error);
}

}  // namespace io
}  // namespace evidential_slam
