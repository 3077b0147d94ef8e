// Exploration in closed loop without ROS: the grid-map simulator (velocity commands) feeds the
// SLAM engine, whose best map (as a layer raster) and pose drive the Explorer, whose command
// drives the simulator. The run measures what the exploration.json holds: the share of
// the world's reachable free space the map knows over simulated time and distance, collisions,
// why it stopped. Tests and benchmarks call it; a ROS node wires the same three parts through
// topics.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/exploration/explorer.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/io/gridmap_simulator.h"

namespace evidential_slam {
namespace io {

struct ExplorationRunConfig {
  GridmapSimulatorConfig simulator;  // velocity commands: no waypoints; its duration is ignored
  SlamConfig slam;
  exploration::ExplorerConfig explorer;
  double max_time = 600.0;        // s of simulated time at most (from the first scan)
  double coverage_period = 5.0;   // s of simulated time between coverage samples
  int map_margin_cells = 10;      // vacuous border around the observed map in each raster

  bool isValid(std::string* why) const;
};

struct CoverageSample {
  double time = 0.0;      // s since the first scan
  double distance = 0.0;  // m driven (truth)
  double coverage = 0.0;  // exploration::knownFraction of the reachable free cells
};

// Mean layers of the final map over one kind of place of the world (the truth's cells of that kind
// whose map cell holds evidence).
struct PlaceLayers {
  std::string kind;  // glass, clutter, people (free cells a person walked over), wall, free
  uint64_t cells = 0;
  double betp = 0.0, ns = 0.0, ic = 0.0, ec = 0.0, entropy = 0.0;
};

struct ExplorationRunResult {
  double final_coverage = 0.0;
  std::vector<CoverageSample> coverage;  // every coverage_period, and at the end
  double distance_m = 0.0;               // driven (truth)
  double sim_time_s = 0.0;               // since the first scan
  uint64_t collisions = 0;
  double min_wall_distance_m = 0.0;  // closest the robot's centre came to a wall (truth, <= 1 m)
  double time_to_90_s = -1.0;  // first sample at or above 90 % coverage; < 0: never
  double time_to_99_s = -1.0;
  bool done = false;        // the explorer stopped by itself (else max_time ran out)
  std::string stop_reason;  // its message, or "max_time reached"
  uint64_t scans = 0;
  uint64_t scans_processed = 0;
  uint64_t reachable_cells = 0;  // free cells of the image reachable from the start
  // The same share over the reachable cells further than gap_band_m from every wall
  // (exploration::thetaGapBand of the SLAM's sensor model): the inverse model never marks the
  // band itself free.
  double gap_band_m = 0.0;
  uint64_t reachable_cells_beyond_gap = 0;
  double final_coverage_beyond_gap = 0.0;
  double final_position_error_m = 0.0;  // SLAM pose against the truth at the end
  // ATE of the best particle's path at the end (the final map's trajectory) against the true
  // poses of every scan (core/metrics.h: SE(2)-aligned RMSE and maximum); < 0: not measured.
  double ate_rmse_m = -1.0;
  double ate_max_m = -1.0;
  // Simulated s the explorer held the robot stopped for a fault (Explorer::fault(): a map with a
  // non-finite value, a non-finite pose), and the first such fault ("" when none).
  double fault_time_s = 0.0;
  std::string first_fault;
  // Simulated s with the robot's centre within kNearRegion m of a glass or clutter region.
  double time_near_regions_s = 0.0;
  // At the end, per kind of place (kinds without a cell are left out).
  std::vector<PlaceLayers> place_layers;
  double wall_time_s = 0.0;
  double slam_time_s = 0.0;     // inside processScan
  double explorer_time_s = 0.0;  // raster extraction and Explorer::update
  exploration::ExplorerStats explorer_stats;
  // False when the run was watched from outside (the ROS monitor): processing times, scans
  // processed, the goal counts, the faults, the time near regions and the place layers were not
  // measured and are left out of exploration.json.
  bool internals_measured = true;
  std::shared_ptr<const LayerRaster> final_map;  // the best map at the end, as a raster
  Pose2 start_pose;                              // the robot's true start (the map frame)
};

// "Near" a glass or clutter region for time_near_regions_s (m from the robot's centre).
constexpr double kNearRegion = 1.0;

// Called after every scan with the simulated time (s since the first scan); return false to stop.
using ExplorationProgress = std::function<bool(double time, const ExplorationRunResult& so_far)>;

// Runs to the explorer's stop or max_time. False with a one-line `error` on a bad configuration
// or an unloadable map.
bool runExploration(const ExplorationRunConfig& config, ExplorationRunResult* result,
                    std::string* error, const ExplorationProgress& progress = nullptr);

// exploration.json: final_coverage, coverage ([time s, distance m, coverage] per sample),
// distance_m, collisions, time_to_90_s and time_to_99_s (null when not reached), stop_reason,
// and the counts and times above. False with a one-line `error` when it cannot be written.
bool writeExplorationJson(const std::string& path, const ExplorationRunResult& result,
                          std::string* error);

}  // namespace io
}  // namespace evidential_slam
