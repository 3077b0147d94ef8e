// Tests of MappingSession (session/session.h): the time-stamp policy (outliers dropped, a real
// restart only after time_jump_scans stamps back in a row, the map saved before it) and the limits
// on a scan (rays, ranges, the distance from where the map started, stamps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include "evidential_slam/io/evidential_octree.h"
#include "evidential_slam/session/map_files.h"
#include "evidential_slam/session/session.h"
#include "test_support.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;
using Order = SessionScanResult::Order;
using testing_room::roomScan;

Parameters smallConfig() {
  Parameters p;
  p.slam = testing_room::withoutRealRobotSettings(p.slam);
  p.slam.particles = 4;
  p.slam.threads = 1;
  p.session.time_jump_tolerance = 1.0;
  p.session.time_jump_scans = 3;
  p.session.time_jump_forward = 100.0;
  return p;
}

// The robot moves 0.6 m per second along x: every in-order scan passes the 0.5 m motion gate.
SessionScanResult feed(MappingSession* s, double t) {
  const Pose2 odometry(0.6 * (t - 100.0), 0.0, 0.0);
  return s->processScan(odometry, roomScan(Pose2(), t));
}

TEST(MappingSession, ASingleStampBackIsAnOutlierAndTheMapStays) {
  MappingSession s(smallConfig());
  for (double t : {100.0, 101.0, 102.0}) EXPECT_EQ(feed(&s, t).order, Order::kInOrder);
  const uint64_t processed = s.engine().stats().scans_processed;
  // A driver's glitch: a stamp of 0, then one 2 s behind.
  SessionScanResult r = feed(&s, 0.0);
  EXPECT_EQ(r.order, Order::kOutlier);
  EXPECT_NE(r.message.find("outlier"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("102.000"), std::string::npos) << r.message;
  EXPECT_EQ(feed(&s, 103.0).order, Order::kInOrder);
  r = feed(&s, 101.5);
  EXPECT_EQ(r.order, Order::kOutlier) << r.message;
  EXPECT_EQ(feed(&s, 104.0).order, Order::kInOrder);
  EXPECT_EQ(s.stampOutliers(), 2u);
  EXPECT_EQ(s.restarts(), 0u);
  EXPECT_EQ(s.engine().stats().scans_processed, processed + 2);
}

TEST(MappingSession, StampsBackForTimeJumpScansRestartAfterSavingTheMap) {
  const fs::path root = test::scratchDir();
  MappingSession s(smallConfig());
  s.setResetSaveRoot(root.string());
  for (double t : {100.0, 101.0, 102.0, 103.0}) feed(&s, t);
  EXPECT_EQ(feed(&s, 50.0).order, Order::kOutlier);  // a looping bag: 1 of 3
  EXPECT_EQ(feed(&s, 51.0).order, Order::kOutlier);  // 2 of 3
  const SessionScanResult r = feed(&s, 52.0);        // 3 of 3: a real restart
  EXPECT_EQ(r.order, Order::kRestarted);
  EXPECT_NE(r.message.find("time jumped back"), std::string::npos) << r.message;
  EXPECT_EQ(s.restarts(), 1u);
  EXPECT_EQ(s.engine().stats().scans_received, 1u);  // started over with this scan
  EXPECT_TRUE(r.update.processed);
  // The map of the first run, saved before the reset, where the message says.
  const fs::path saved = root / "before_reset_103.000";
  EXPECT_EQ(s.lastResetSave(), saved.string());
  EXPECT_NE(r.message.find(saved.string()), std::string::npos) << r.message;
  EXPECT_TRUE(fs::is_regular_file(saved / "trajectory.tum"));
  EXPECT_TRUE(fs::is_regular_file(saved / "layers" / "pignistic.png"));
  EXPECT_NE(test::readText(saved / "trajectory.tum").find("103.0"), std::string::npos);
  EXPECT_EQ(feed(&s, 53.0).order, Order::kInOrder);
}

TEST(MappingSession, OneStepBackWithinTheToleranceIsDropped) {
  MappingSession s(smallConfig());
  feed(&s, 100.0);
  const SessionScanResult r = feed(&s, 99.5);
  EXPECT_EQ(r.order, Order::kDropped);
  EXPECT_NE(r.message.find("older"), std::string::npos) << r.message;
  EXPECT_EQ(s.scansDropped(), 1u);
}

TEST(MappingSession, OutliersInBetweenDoNotAddUpToARestart) {
  MappingSession s(smallConfig());
  for (double t = 100.0; t < 110.0; t += 1.0) {
    feed(&s, t);
    EXPECT_EQ(feed(&s, 0.0).order, Order::kOutlier);  // every other scan, never 3 in a row
  }
  EXPECT_EQ(s.restarts(), 0u);
  EXPECT_EQ(s.stampOutliers(), 10u);
}

TEST(MappingSession, AStampFarAheadIsAnOutlierUnlessTheNextOnesFollow) {
  MappingSession s(smallConfig());
  // The robot stands still: only the stamps change.
  auto at = [&s](double t) { return s.processScan(Pose2(), roomScan(Pose2(), t)).order; };
  EXPECT_EQ(at(100.0), Order::kInOrder);
  EXPECT_EQ(at(1e12), Order::kOutlier);  // far in the future
  EXPECT_EQ(at(101.0), Order::kInOrder);
  // Time really moved on (the robot stood by for an hour): believed at the third scan.
  EXPECT_EQ(at(5000.0), Order::kOutlier);
  EXPECT_EQ(at(5001.0), Order::kOutlier);
  EXPECT_EQ(at(5002.0), Order::kInOrder);
  EXPECT_EQ(at(5003.0), Order::kInOrder);
  EXPECT_EQ(s.restarts(), 0u);
}

TEST(MappingSession, RestartWithoutASaveDirectorySaysSo) {
  MappingSession s(smallConfig());
  feed(&s, 100.0);
  std::string message;
  s.restart("ROS time jumped back by 10 s", &message);
  EXPECT_NE(message.find("ROS time jumped back by 10 s: the SLAM starts over"), std::string::npos)
      << message;
  EXPECT_NE(message.find("not saved"), std::string::npos) << message;
  EXPECT_EQ(s.restarts(), 1u);
  EXPECT_EQ(s.engine().stats().scans_received, 0u);
}

// A user's reset (~reset) also saves the map first, then forgets it.
TEST(MappingSession, StartOverOnRequestSavesTheMapFirst) {
  const fs::path root = test::scratchDir();
  MappingSession s(smallConfig());
  s.setResetSaveRoot(root.string());
  for (double t : {100.0, 101.0, 102.0}) feed(&s, t);
  std::string message;
  s.startOver("reset", &message);
  const fs::path saved = root / "before_reset_102.000";
  EXPECT_NE(message.find("reset: the SLAM starts over with no map"), std::string::npos) << message;
  EXPECT_NE(message.find(saved.string()), std::string::npos) << message;
  EXPECT_EQ(s.lastResetSave(), saved.string());
  EXPECT_NE(test::readText(saved / "trajectory.tum").find("102.0"), std::string::npos);
  EXPECT_EQ(s.engine().stats().scans_received, 0u);
  // Off, nothing is written and the message says so.
  Parameters off = smallConfig();
  off.session.save_before_reset = false;
  MappingSession quiet(off);
  quiet.setResetSaveRoot((root / "off").string());
  feed(&quiet, 100.0);
  quiet.startOver("reset", &message);
  EXPECT_NE(message.find("save_before_reset off"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(root / "off"));
}

TEST(MappingSession, AnUnwritableSaveDirectoryStillRestarts) {
  MappingSession s(smallConfig());
  s.setResetSaveRoot("/proc/evidential_slam_cannot_write_here");
  feed(&s, 100.0);
  std::string message;
  s.restart("test", &message);
  EXPECT_NE(message.find("could not be saved"), std::string::npos) << message;
  EXPECT_EQ(s.restarts(), 1u);
}

TEST(MappingSession, LimitsRefuseScansWithAClearMessage) {
  Parameters p = smallConfig();
  p.session.max_scan_rays = 1000;
  p.session.max_map_extent = 100.0;
  MappingSession s(p);
  LaserScan big = roomScan(Pose2(), 100.0);
  big.ranges.assign(1001, 1.0f);
  big.bearings.assign(1001, 0.0f);
  big.valid.assign(1001, 1);
  SessionScanResult r = s.processScan(Pose2(), big);
  EXPECT_EQ(r.order, Order::kRefused);
  EXPECT_NE(r.message.find("max_scan_rays"), std::string::npos) << r.message;

  LaserScan nan_stamp = roomScan(Pose2(), std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(s.processScan(Pose2(), nan_stamp).order, Order::kRefused);
  EXPECT_EQ(s.processScan(Pose2(std::numeric_limits<double>::infinity(), 0, 0),
                          roomScan(Pose2(), 100.0))
                .order,
            Order::kRefused);

  EXPECT_EQ(s.processScan(Pose2(5.0, 5.0, 0.0), roomScan(Pose2(), 100.0)).order, Order::kInOrder);
  r = s.processScan(Pose2(1e7, 0.0, 0.0), roomScan(Pose2(), 101.0));  // 10^7 m away
  EXPECT_EQ(r.order, Order::kRefused);
  EXPECT_NE(r.message.find("max_map_extent"), std::string::npos) << r.message;
  EXPECT_EQ(s.scansRefused(), 4u);
  EXPECT_EQ(s.engine().stats().scans_received, 1u);
}

// Every pose that enters the SLAM is bounded by max_map_extent from the map frame's origin, the
// same limit for every way in: a start map's pose (map file robot_pose, ~load_map use_pose,
// --initial-pose), a localization start and a fresh map's first odometry. Beyond it a start is
// refused with one line and the session keeps working; before, 10^9 m reached the scan matcher's
// correspondence search as overflowed cell indices (std::length_error).
TEST(MappingSession, PosesBeyondTheMapExtentAreRefusedWhereTheyEnter) {
  Parameters p = smallConfig();
  p.session.max_map_extent = 100.0;
  MappingSession s(p);
  EXPECT_EQ(s.processScan(Pose2(1e9, 0.0, 0.0), roomScan(Pose2(), 100.0)).order, Order::kRefused);
  SessionScanResult r = s.processScan(Pose2(0.0, -1e12, 0.0), roomScan(Pose2(), 100.0));
  EXPECT_EQ(r.order, Order::kRefused);
  EXPECT_NE(r.message.find("farther than max_map_extent (100 m)"), std::string::npos) << r.message;
  EXPECT_EQ(r.message.find('\n'), std::string::npos);
  EXPECT_EQ(s.processScan(Pose2(99.0, 0.0, 0.0), roomScan(Pose2(), 100.0)).order, Order::kInOrder);

  MappingSession m(p);
  for (double t : {100.0, 101.0, 102.0}) feed(&m, t);
  const EvidentialGridMap map = m.currentMap();
  std::string why;
  for (const Pose2& far : {Pose2(1e9, 0, 0), Pose2(0, 1e6, 0), Pose2(-100.5, 0, 0),
                           Pose2(std::numeric_limits<double>::quiet_NaN(), 0, 0)}) {
    MappingSession t(p);
    EXPECT_FALSE(t.startFromMap(map, far, &why));
    EXPECT_NE(why.find("the start pose"), std::string::npos) << why;
    LocalizationStart start;
    start.pose = far;
    EXPECT_FALSE(t.startLocalization(map, start, &why));
    EXPECT_NE(why.find("the start pose"), std::string::npos) << why;
    for (double time : {100.0, 101.0}) EXPECT_EQ(feed(&t, time).order, Order::kInOrder);
  }
  // An anchored start: odometry far from the anchor moves the first pose beyond the extent.
  MappingSession a(p);
  const Pose2 anchor(0.0, 0.0, 0.0);
  ASSERT_TRUE(a.startFromMap(map, Pose2(1.0, 0.0, 0.0), &why, &anchor)) << why;
  r = a.processScan(Pose2(1e12, 0.0, 0.0), roomScan(Pose2(), 100.0));
  EXPECT_EQ(r.order, Order::kRefused);
  EXPECT_NE(r.message.find("the pose its odometry gives"), std::string::npos) << r.message;
  EXPECT_EQ(a.processScan(Pose2(0.5, 0.0, 0.0), roomScan(Pose2(), 101.0)).order, Order::kInOrder);
}

// Ranges of 10^9 m are clipped at usable_range: the map stays the size of what the laser can
// map, not of what it claims.
TEST(MappingSession, HugeRangesAreClippedAtTheUsableRange) {
  Parameters p = smallConfig();
  MappingSession s(p);
  LaserScan far = roomScan(Pose2(), 100.0);
  far.max_range = 1e9f;
  for (float& z : far.ranges) z = 1e9f;
  std::fill(far.valid.begin(), far.valid.end(), 1);
  const SessionScanResult r = s.processScan(Pose2(), far);
  EXPECT_EQ(r.order, Order::kInOrder);
  const int reach = static_cast<int>((p.slam.sensor.usable_range + 1.0) / p.slam.resolution);
  const CellBox box = s.engine().bestMap().observedBox();
  ASSERT_FALSE(box.empty());
  EXPECT_LE(std::max(std::abs(box.min_x), std::abs(box.max_x)), reach);
  EXPECT_LE(std::max(std::abs(box.min_y), std::abs(box.max_y)), reach);
  EXPECT_GT(box.width(), reach);  // the rays did clear space out to about usable_range
}

// Localization mode: scans go to the Localizer on the given map, which no scan changes; the
// scan checks and the time-jump policy are the session's; a restart starts the particles as they
// started (nothing to save); startFromMap returns to SLAM mode.
TEST(MappingSession, LocalizationModeUsesTheLocalizerOnAFixedMap) {
  Parameters p = smallConfig();
  p.localization.max_particles = 200;
  MappingSession mapping(p);
  mapping.processScan(Pose2(), roomScan(Pose2(), 100.0));
  const EvidentialGridMap map = mapping.currentMap();
  ASSERT_FALSE(map.observedBox().empty());

  MappingSession s(p);
  s.setResetSaveRoot(test::scratchDir().string());
  LocalizationStart start;
  start.pose = Pose2(0.08, -0.05, 0.02);
  start.covariance.diagonal() << 1e-4, 1e-4, 1e-5;
  std::string why;
  ASSERT_TRUE(s.startLocalization(map, start, &why)) << why;
  ASSERT_TRUE(s.localizing());
  SessionScanResult r = s.processScan(Pose2(), roomScan(Pose2(), 100.0));
  EXPECT_EQ(r.order, Order::kInOrder);
  EXPECT_TRUE(r.processed());
  EXPECT_TRUE(r.localization.processed);
  EXPECT_FALSE(r.update.processed);
  EXPECT_EQ(s.engine().stats().scans_received, 0u);
  // The scan matcher pulls the cloud from the start to the true pose (the origin).
  const Pose2 estimate = s.localizer().estimate().mean;
  EXPECT_LT(std::hypot(estimate.x, estimate.y), 0.03) << estimate.x << ", " << estimate.y;

  // The session's checks apply: a scan with a non-finite stamp is refused.
  r = s.processScan(Pose2(), roomScan(Pose2(), std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(r.order, Order::kRefused);

  // The saved files hold the stored map, unchanged, and the estimate's path.
  const MapSave save = captureMapSave(s);
  EXPECT_EQ(save.info.metadata.at("mode"), "localization");
  EXPECT_EQ(save.trajectory.size(), 1u);
  EXPECT_EQ(save.map.allocatedTiles(), map.allocatedTiles());
  size_t differ = 0;
  const CellBox box = map.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& a = map.cell(x, y);
      const Cell& b = save.map.cell(x, y);
      differ += a.occupiedSteps() != b.occupiedSteps() || a.freeSteps() != b.freeSteps() ||
                a.lambdaBits() != b.lambdaBits();
    }
  }
  EXPECT_EQ(differ, 0u);

  // A looping log: three stamps back restart the particles as they started; nothing is saved.
  s.processScan(Pose2(), roomScan(Pose2(), 50.0));
  s.processScan(Pose2(), roomScan(Pose2(), 51.0));
  r = s.processScan(Pose2(), roomScan(Pose2(), 52.0));
  EXPECT_EQ(r.order, Order::kRestarted);
  EXPECT_NE(r.message.find("localization starts over"), std::string::npos) << r.message;
  EXPECT_TRUE(s.lastResetSave().empty());
  EXPECT_TRUE(s.localizing());

  // Global localization draws max_particles; startFromMap goes back to mapping.
  LocalizationStart global;
  global.global = true;
  ASSERT_TRUE(s.restartLocalization(global, &why)) << why;
  EXPECT_EQ(s.localizer().particles().size(), 200u);
  ASSERT_TRUE(s.startFromMap(map, Pose2(), &why)) << why;
  EXPECT_FALSE(s.localizing());
  r = s.processScan(Pose2(), roomScan(Pose2(), 200.0));
  EXPECT_TRUE(r.update.processed);
  EXPECT_FALSE(s.restartLocalization(global, &why));
  EXPECT_EQ(why, "not in localization mode");
}

// writeMapFiles, which the node's ~save_map and the offline --out both call, exports the saved
// anomaly with the masses in the OctoMap file.
TEST(MapFiles, TheOctomapExportCarriesTheAnomaly) {
  MapSave save;
  save.map = EvidentialGridMap(0.05);
  save.map.mutableCell(0, 0) = Cell::fromStored(0.0f, 0.75f, 0.0f);
  save.map.mutableCell(1, 0) = Cell::fromStored(0.5f, 0.25f, 0.5f);
  save.anomaly.add(1, 0, 2.5f);
  SessionConfig config;
  config.export_octomap = true;
  const fs::path dir = test::scratchDir();
  MapFilesReport report;
  std::string error;
  ASSERT_TRUE(writeMapFiles(dir.string(), save, config, &report, &error)) << error;
  ASSERT_TRUE(report.octomap.has_value());
  std::unique_ptr<io::EvidentialOcTree> tree;
  ASSERT_TRUE(io::readEvidentialOctree((dir / "octomap/map.evidential.ot").string(), &tree, &error))
      << error;
  EXPECT_EQ(tree->layout(), io::EvidentialLayout::kMassesAnomaly);
  const io::EvidentialOcTreeNode* wall = tree->search(octomap::OcTreeKey(32769, 32768, 32768));
  const io::EvidentialOcTreeNode* free_cell = tree->search(octomap::OcTreeKey(32768, 32768, 32768));
  ASSERT_NE(wall, nullptr);
  ASSERT_NE(free_cell, nullptr);
  EXPECT_EQ(wall->anomaly(), 2.5f);
  EXPECT_TRUE(wall->cell() == save.map.cell(1, 0));
  EXPECT_EQ(free_cell->anomaly(), 0.0f);
}

// Dense layers over an observed box of more than max_layer_cells are not written (the sparse map
// file is), and the report says what they would need: 750 m of travel once took 400 s and
// 1.2 GB here. A few cells 1 km apart make a 20,001-cell-wide box from a few observed tiles.
TEST(MapFiles, DenseLayersBeyondMaxLayerCellsAreNotWritten) {
  MapSave save;
  save.map = EvidentialGridMap(0.05);
  save.map.mutableCell(0, 0) = Cell::fromStored(0.0f, 0.75f, 0.0f);
  save.map.mutableCell(20000, 3) = Cell::fromStored(0.5f, 0.25f, 0.5f);
  SessionConfig config;  // max_layer_cells 2^23: 20001 x 4 cells fit
  const fs::path dir = test::scratchDir();
  MapFilesReport report;
  std::string error;
  ASSERT_TRUE(writeMapFiles((dir / "fits").string(), save, config, &report, &error)) << error;
  EXPECT_TRUE(report.layers_skipped.empty()) << report.layers_skipped;
  EXPECT_TRUE(fs::exists(dir / "fits/layers/occupied.npy"));

  save.map.mutableCell(0, 999) = Cell::fromStored(0.0f, 0.75f, 0.0f);  // 20001 x 1000 cells
  ASSERT_TRUE(writeMapFiles((dir / "big").string(), save, config, &report, &error)) << error;
  EXPECT_NE(report.layers_skipped.find("20001 x 1000 cells"), std::string::npos)
      << report.layers_skipped;
  EXPECT_NE(report.layers_skipped.find("max_layer_cells (8388608)"), std::string::npos);
  EXPECT_EQ(report.layers_skipped.find('\n'), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "big/layers"));
  EXPECT_TRUE(fs::exists(dir / "big/map.evmap"));
  EXPECT_EQ(report.map_width, 0);

  config.max_layer_cells = 0;  // no limit
  std::string why;
  EXPECT_TRUE(denseLayersFit(save.map, config, &why));
}

}  // namespace
}  // namespace evidential_slam
