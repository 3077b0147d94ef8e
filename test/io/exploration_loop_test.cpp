// Exploration in closed loop without ROS (io/exploration_run.h): the simulator, the SLAM engine
// (K = 100) and the Explorer on the two-room fixture map (test/data/sim_map.png, 16 m x 12 m,
// two doors): with either strategy the robot must map at least 95 % of the free space it can
// reach, stop by itself well within the simulated time allowed, and never touch a wall. Each run
// takes about 30 s here.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "evidential_slam/io/exploration_run.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

io::ExplorationRunConfig twoRoomRun(const std::string& strategy) {
  io::ExplorationRunConfig c;
  c.simulator.map = test::dataPath("sim_map.png");
  c.simulator.resolution = 0.05;
  c.simulator.start_x = -6.0;  // the left room's lower left, facing east
  c.simulator.start_y = -4.0;
  c.simulator.seed = 1;
  c.slam.particles = 100;
  c.slam.seed = 1;
  c.slam.threads = 2;
  c.explorer.frontiers.strategy = strategy;
  c.max_time = 400.0;
  return c;
}

// Runs, prints the figures and checks the run's promises.
void exploreAndCheck(const std::string& strategy) {
  const io::ExplorationRunConfig c = twoRoomRun(strategy);
  io::ExplorationRunResult r;
  std::string error;
  ASSERT_TRUE(io::runExploration(c, &r, &error)) << error;
  std::printf(
      "%s: coverage %.4f after %.1f m in %.1f s simulated (%.1f s wall: SLAM %.1f s, explorer "
      "%.1f s), %llu collision(s), closest to a wall %.2f m, to 90 %%: %.0f s, pose error "
      "%.3f m, ATE %.3f m (max %.3f m); beyond the %.3f m gap band: coverage %.4f of %llu cells; "
      "%s\n",
      strategy.c_str(), r.final_coverage, r.distance_m, r.sim_time_s,
      r.wall_time_s, r.slam_time_s, r.explorer_time_s,
      static_cast<unsigned long long>(r.collisions), r.min_wall_distance_m, r.time_to_90_s,
      r.final_position_error_m, r.ate_rmse_m, r.ate_max_m, r.gap_band_m, r.final_coverage_beyond_gap,
      static_cast<unsigned long long>(r.reachable_cells_beyond_gap), r.stop_reason.c_str());
  EXPECT_TRUE(r.done) << r.stop_reason;
  EXPECT_LT(r.sim_time_s, 300.0);
  EXPECT_GE(r.final_coverage, 0.95);
  EXPECT_EQ(r.collisions, 0u);
  EXPECT_GT(r.min_wall_distance_m, 0.2);  // the simulator's robot_radius
  ASSERT_TRUE(r.final_map);
  EXPECT_GT(r.reachable_cells, 40000u);  // most of the 16 m x 12 m at 0.05 m
  // The default sensor model's band: 3 x 0.025 m + 0.05 m; it holds some cells, not most.
  EXPECT_NEAR(r.gap_band_m, 0.125, 1e-12);
  EXPECT_LT(r.reachable_cells_beyond_gap, r.reachable_cells);
  EXPECT_GT(r.reachable_cells_beyond_gap, r.reachable_cells * 9 / 10);
  EXPECT_GE(r.final_coverage_beyond_gap, r.final_coverage);
  EXPECT_LT(r.final_position_error_m, 0.3);
  // The final path's ATE: measured (not the -1 of "not measured"), a SLAM that kept its pose.
  EXPECT_GT(r.ate_rmse_m, 0.0);
  EXPECT_LT(r.ate_rmse_m, 0.3);
  EXPECT_GE(r.ate_max_m, r.ate_rmse_m);
  ASSERT_GE(r.coverage.size(), 2u);
  EXPECT_EQ(r.coverage.front().time, 0.0);
  EXPECT_EQ(r.coverage.back().time, r.sim_time_s);
  EXPECT_EQ(r.coverage.back().coverage, r.final_coverage);
  for (size_t k = 1; k < r.coverage.size(); ++k) {
    EXPECT_GT(r.coverage[k].time, r.coverage[k - 1].time);
    EXPECT_GE(r.coverage[k].distance, r.coverage[k - 1].distance);
  }
  EXPECT_GT(r.time_to_90_s, 0.0);

  // exploration.json holds the fields.
  const std::string path = (test::scratchDir() / "exploration.json").string();
  ASSERT_TRUE(io::writeExplorationJson(path, r, &error)) << error;
  const nlohmann::json j = nlohmann::json::parse(test::readText(path));
  EXPECT_DOUBLE_EQ(j.at("final_coverage").get<double>(), r.final_coverage);
  EXPECT_EQ(j.at("coverage").size(), r.coverage.size());
  EXPECT_EQ(j.at("coverage")[0].size(), 3u);
  EXPECT_DOUBLE_EQ(j.at("distance_m").get<double>(), r.distance_m);
  EXPECT_EQ(j.at("collisions").get<int>(), 0);
  EXPECT_DOUBLE_EQ(j.at("time_to_90_s").get<double>(), r.time_to_90_s);
  EXPECT_TRUE(r.time_to_99_s < 0.0 ? j.at("time_to_99_s").is_null()
                                   : j.at("time_to_99_s").get<double>() == r.time_to_99_s);
  EXPECT_EQ(j.at("stop_reason").get<std::string>(), r.stop_reason);
  EXPECT_DOUBLE_EQ(j.at("final_coverage_beyond_gap").get<double>(), r.final_coverage_beyond_gap);
  EXPECT_DOUBLE_EQ(j.at("gap_band_m").get<double>(), r.gap_band_m);
  EXPECT_DOUBLE_EQ(j.at("ate_rmse_m").get<double>(), r.ate_rmse_m);
  EXPECT_DOUBLE_EQ(j.at("ate_max_m").get<double>(), r.ate_max_m);
}

TEST(ExplorationLoop, NonSpecificityStrategyExploresTheTwoRooms) {
  exploreAndCheck("ns");
}

TEST(ExplorationLoop, FrontierStrategyExploresTheTwoRooms) {
  exploreAndCheck("frontier");
}

// A glass pane and clutter in the left room (objects file): the run reports the time the robot
// spent near them and what the final map holds there. The pane's beams pass or return at random,
// the clutter's scatter: both contradict the map scan after scan (EC), the free space does not.
TEST(ExplorationLoop, RegionsAreMeasuredWhereTheyAre) {
  io::ExplorationRunConfig c = twoRoomRun("ns");
  const fs::path objects = test::scratchDir() / "objects.txt";
  test::writeText(objects,
                  "glass -3 1 -3 3 0.025 0.5\n"
                  "clutter -6.5 -3 -5.5 -3 0.2 0.3\n");  // 0.8 m from the start
  c.simulator.objects = objects.string();
  c.slam.particles = 30;
  c.max_time = 60.0;
  io::ExplorationRunResult r;
  std::string error;
  ASSERT_TRUE(io::runExploration(c, &r, &error)) << error;
  EXPECT_EQ(r.collisions, 0u);
  EXPECT_GT(r.time_near_regions_s, 0.0);
  EXPECT_LE(r.time_near_regions_s, r.sim_time_s);
  std::map<std::string, io::PlaceLayers> places;
  for (const io::PlaceLayers& l : r.place_layers) places[l.kind] = l;
  ASSERT_EQ(places.count("glass"), 1u);
  ASSERT_EQ(places.count("clutter"), 1u);
  ASSERT_EQ(places.count("free"), 1u);
  ASSERT_EQ(places.count("wall"), 1u);
  EXPECT_EQ(places.count("people"), 0u);  // no disc in the file
  EXPECT_GT(places["glass"].cells, 20u);
  EXPECT_GT(places["clutter"].cells, 20u);
  for (const char* kind : {"glass", "clutter", "free", "wall"}) {
    const io::PlaceLayers& l = places[kind];
    std::printf("%s: %llu cells, BetP %.3f, NS %.3f, IC %.4f, EC %.3f, H %.3f\n", kind,
                static_cast<unsigned long long>(l.cells), l.betp, l.ns, l.ic, l.ec, l.entropy);
  }
  EXPECT_GT(places["glass"].ec, 1.0);
  for (const char* kind : {"glass", "clutter"}) {
    EXPECT_GT(places[kind].ec, 10.0 * places["free"].ec) << kind;
  }
  EXPECT_LT(places["free"].betp, 0.1);
  EXPECT_GT(places["wall"].betp, 0.6);
  const std::string path = (test::scratchDir() / "exploration.json").string();
  ASSERT_TRUE(io::writeExplorationJson(path, r, &error)) << error;
  const nlohmann::json j = nlohmann::json::parse(test::readText(path));
  EXPECT_DOUBLE_EQ(j.at("time_near_regions_s").get<double>(), r.time_near_regions_s);
  // No map was refused, the pose was always finite: no fault.
  EXPECT_EQ(j.at("fault_time_s").get<double>(), 0.0);
  EXPECT_EQ(j.at("first_fault").get<std::string>(), "");
  EXPECT_DOUBLE_EQ(j.at("place_layers").at("glass").at("ec").get<double>(), places["glass"].ec);
}

TEST(ExplorationLoop, BadConfigurationIsRefused) {
  io::ExplorationRunConfig c = twoRoomRun("ns");
  io::ExplorationRunResult r;
  std::string error;
  c.simulator.waypoints = test::dataPath("sim_map_waypoints.txt");
  EXPECT_FALSE(io::runExploration(c, &r, &error));
  EXPECT_EQ(error, "invalid exploration run: simulator: exploration drives it: no waypoints");
  c = twoRoomRun("ns");
  c.explorer.planner_frequency = -1.0;
  EXPECT_FALSE(io::runExploration(c, &r, &error));
  EXPECT_EQ(error, "invalid exploration run: explorer: planner_frequency must be in [0.01, 100] Hz");
  c = twoRoomRun("ns");
  c.simulator.map = test::dataPath("no_such_map.png");
  EXPECT_FALSE(io::runExploration(c, &r, &error));
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
}

}  // namespace
}  // namespace evidential_slam
