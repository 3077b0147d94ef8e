// Continuing a map through its file: test/data/sim.rawlog mapped in one go, and in two halves
// (a MappingSession on the first half, the map saved with writeMapFile, read back with
// readMapFile, a new session started on it with startFromMap at the saved pose, the second half).
// The two final maps must agree on >= 98 % of the observed cells' BetP class (occupied > 0.65,
// free < 0.196, else unknown: map_server's thresholds, LayerWriterConfig's), and the ATEs against
// the ground truth must differ by <= 0.1 m. Done twice: with the odometry pose saved in the file
// (the continuation knows where the next scan is relative to the saved pose) and without it (the
// next scan is taken to be at the saved pose; the matcher absorbs one scan's motion). Then a time
// jump back makes the session start over on the loaded map.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/io/parameter_file.h"
#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/session/session.h"
#include "map_compare.h"
#include "test_util.h"
#include "../core/cell_support.h"

namespace evidential_slam {
namespace {

using testing_cells::sharedTiles;

constexpr size_t kFixtureScans = 159;
constexpr size_t kFirstHalf = 80;

// The fixture is simulated: config/sim.yaml, and few particles like the offline e2e tests.
Parameters fixtureParameters() {
  Parameters params;
  std::vector<std::pair<std::string, std::string>> entries;
  std::string error;
  EXPECT_TRUE(io::readParameterFile(std::string(ES_CONFIG_DIR) + "/sim.yaml", &entries, &error))
      << error;
  entries.insert(entries.end(), {{"particles", "20"}, {"seed", "3"}, {"threads", "2"}});
  for (const auto& [name, value] : entries) {
    EXPECT_TRUE(setParameter(name, value, &params, &error)) << error;
  }
  return params;
}

std::vector<io::RawlogScan> readFixture() {
  io::RawlogReader reader;
  std::string error;
  EXPECT_TRUE(reader.open(test::dataPath("sim.rawlog"), &error)) << error;
  std::vector<io::RawlogScan> scans;
  io::RawlogScan s;
  while (reader.next(&s) == io::RawlogReader::Status::kScan) scans.push_back(s);
  return scans;
}

void feed(MappingSession* session, const std::vector<io::RawlogScan>& scans, size_t from,
          size_t to) {
  for (size_t i = from; i < to; ++i) session->processScan(scans[i].odometry, scans[i].scan);
}

double ate(const std::vector<StampedPose>& path) {
  std::vector<StampedPose> truth;
  std::string error;
  EXPECT_TRUE(io::readGroundTruth(test::dataPath("sim.GT.txt"), &truth, &error)) << error;
  AteResult result;
  EXPECT_TRUE(computeAte(path, truth, 0.05, &result, &error)) << error;
  EXPECT_EQ(result.matched, kFixtureScans);
  return result.rmse;
}

void twoHalves(bool anchored) {
  const std::vector<io::RawlogScan> scans = readFixture();
  ASSERT_EQ(scans.size(), kFixtureScans);
  const Parameters params = fixtureParameters();

  MappingSession whole(params);
  feed(&whole, scans, 0, scans.size());

  MappingSession first(params);
  feed(&first, scans, 0, kFirstHalf);
  io::MapFileInfo saved;
  saved.robot_pose = first.engine().bestPose();
  saved.has_odometry_pose = anchored;
  saved.odometry_pose = first.engine().lastOdometry();
  for (const auto& [name, value] : parameterValues(params)) saved.parameters[name] = value;
  saved.metadata = {{"source", "sim.rawlog"}, {"scans", std::to_string(kFirstHalf)}};
  const std::string path = (test::scratchDir() / io::kMapFileName).string();
  std::string error;
  ASSERT_TRUE(io::writeMapFile(path, first.engine().bestMap(), saved, &error)) << error;

  EvidentialGridMap map;
  io::MapFileInfo info;
  ASSERT_TRUE(io::readMapFile(path, &map, &info, &error)) << error;
  EXPECT_EQ(info.parameters.at("particles"), "20");
  MappingSession second(params);
  ASSERT_TRUE(second.startFromMap(map, info.robot_pose, &error,
                                  info.has_odometry_pose ? &info.odometry_pose : nullptr))
      << error;
  feed(&second, scans, kFirstHalf, scans.size());

  std::vector<StampedPose> halves = first.engine().bestTrajectory();
  for (const StampedPose& p : second.engine().bestTrajectory()) halves.push_back(p);
  const double ate_whole = ate(whole.engine().bestTrajectory());
  const double ate_halves = ate(halves);
  size_t compared = 0;
  const double agreement =
      test::classAgreement(whole.engine().bestMap(), second.engine().bestMap(), &compared);
  std::printf("%s: ATE one go %.4f m, two halves %.4f m; BetP class agreement %.4f of %zu cells\n",
              anchored ? "with the saved odometry" : "at the saved pose", ate_whole, ate_halves,
              agreement, compared);
  EXPECT_GT(compared, 10000u);
  EXPECT_GE(agreement, 0.98);
  EXPECT_LE(std::abs(ate_halves - ate_whole), 0.1);

  // A jump back in time (a looping log: time_jump_scans scans back in a row, here the first scan
  // again) starts over on the loaded map.
  const int jumps = second.parameters().session.time_jump_scans;
  for (int i = 0; i + 1 < jumps; ++i) {
    EXPECT_EQ(second.processScan(scans[0].odometry, scans[0].scan).order,
              SessionScanResult::Order::kOutlier);
  }
  const SessionScanResult restart = second.processScan(scans[0].odometry, scans[0].scan);
  EXPECT_EQ(restart.order, SessionScanResult::Order::kRestarted);
  EXPECT_EQ(second.restarts(), 1u);
  EXPECT_GT(sharedTiles(second.engine().bestMap(), map), map.allocatedTiles() / 2);
}

TEST(MapContinue, TwoHalvesWithTheSavedOdometry) { twoHalves(true); }

TEST(MapContinue, TwoHalvesAtTheSavedPose) { twoHalves(false); }

}  // namespace
}  // namespace evidential_slam
