// Tests of the SLAM worker thread (slam_worker.h): order, map snapshots, time jumps, a full
// queue, run-time parameters and tasks run between scans.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "evidential_slam/ros/slam_worker.h"
#include "test_support.h"
#include "test_util.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

using testing_room::roomScan;

Parameters smallConfig() {
  Parameters p;
  p.slam = testing_room::withoutRealRobotSettings(p.slam);
  p.slam.particles = 4;
  p.slam.threads = 1;
  p.session.time_jump_tolerance = 1.0;
  return p;
}

struct Recorder {
  std::mutex mutex;
  std::vector<double> stamps;
  std::vector<bool> processed;
  std::vector<std::string> warnings;
  int restarts = 0;
  SlamWorker::Callbacks callbacks() {
    SlamWorker::Callbacks c;
    c.on_scan = [this](const MappingSession&, const SessionScanResult& r) {
      std::lock_guard<std::mutex> lock(mutex);
      stamps.push_back(r.stamp);
      processed.push_back(r.update.processed);
    };
    c.on_warning = [this](const std::string& m, bool restarted) {
      std::lock_guard<std::mutex> lock(mutex);
      warnings.push_back(m);
      restarts += restarted ? 1 : 0;
    };
    return c;
  }
};

TEST(SlamWorker, HandlesScansInOrderAndSharesTheMap) {
  Recorder rec;
  SlamWorker worker(smallConfig(), 100, rec.callbacks());
  EXPECT_FALSE(worker.latestMap().grid);
  for (int i = 0; i < 4; ++i) {
    const Pose2 odom(0.3 * i, 0.0, 0.0);
    ASSERT_TRUE(worker.push(odom, roomScan(odom, 10.0 + i)));
  }
  worker.waitIdle();
  EXPECT_EQ(rec.stamps, (std::vector<double>{10, 11, 12, 13}));
  EXPECT_EQ(rec.processed, (std::vector<bool>{true, false, true, false}));  // 0.5 m gate
  const MapSnapshot map = worker.latestMap();
  ASSERT_TRUE(map.grid);
  EXPECT_EQ(map.version, 2u);
  EXPECT_DOUBLE_EQ(map.stamp, 12.0);
  EXPECT_FALSE(map.grid->observedBox().empty());
  uint64_t received = 0;
  worker.runOnWorker(
      [&](const MappingSession& s) { received = s.engine().stats().scans_received; });
  EXPECT_EQ(received, 4u);
}

// Localization mode: scans leave the stored map as it is, so its version stays (the publisher
// sends /map once) while the anomaly's moves on; localizing on another map changes the version.
TEST(SlamWorker, LocalizationScansChangeTheAnomalyNotTheMapVersion) {
  Recorder rec;
  SlamWorker worker(smallConfig(), 100, rec.callbacks());
  for (int i = 0; i < 3; ++i) {
    const Pose2 odom(0.6 * i, 0.0, 0.0);
    ASSERT_TRUE(worker.push(odom, roomScan(odom, 10.0 + i)));
  }
  worker.waitIdle();
  EvidentialGridMap map;
  worker.runOnWorker([&](const MappingSession& s) { map = s.currentMap(); });
  ASSERT_FALSE(map.observedBox().empty());
  auto localize = [&](const EvidentialGridMap& on) {
    bool ok = false;
    std::string why;
    LocalizationStart start;
    start.pose = Pose2(1.2, 0.0, 0.0);
    start.covariance.diagonal() << 0.01, 0.01, 0.003;
    worker.changeOnWorker([&](MappingSession& s) { ok = s.startLocalization(on, start, &why); },
                          true);
    ASSERT_TRUE(ok) << why;
  };
  localize(map);
  const MapSnapshot first = worker.latestMap();
  ASSERT_TRUE(first.grid);
  for (int i = 3; i < 7; ++i) {
    const Pose2 odom(1.2 + 0.6 * (i - 3), 0.0, 0.0);
    ASSERT_TRUE(worker.push(odom, roomScan(odom, 10.0 + i)));
  }
  worker.waitIdle();
  const MapSnapshot later = worker.latestMap();
  EXPECT_EQ(later.version, first.version);
  EXPECT_EQ(later.grid, first.grid);  // the same copy, not one per scan
  EXPECT_GE(later.anomaly_version, first.anomaly_version + 2);
  EXPECT_TRUE(later.anomaly_grid);
  // /initialpose: the map stays.
  std::string why;
  bool ok = false;
  LocalizationStart start;
  start.pose = Pose2(1.0, 0.1, 0.0);
  start.covariance.diagonal() << 0.01, 0.01, 0.003;
  worker.changeOnWorker([&](MappingSession& s) { ok = s.restartLocalization(start, &why); }, false);
  ASSERT_TRUE(ok) << why;
  const Pose2 odom(3.6, 0.0, 0.0);
  ASSERT_TRUE(worker.push(odom, roomScan(odom, 17.0)));
  worker.waitIdle();
  EXPECT_EQ(worker.latestMap().version, first.version);
  // Another map (equal cells, its own tiles): a new version.
  EvidentialGridMap other(map.resolution());
  const CellBox box = map.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      if (map.cell(x, y).observed()) other.mutableCell(x, y) = map.cell(x, y);
    }
  }
  localize(other);
  EXPECT_GT(worker.latestMap().version, first.version);
}

// Back by less than the tolerance: the scan is dropped. Back by more: an outlier, unless
// time_jump_scans scans in a row are (a looping bag): then a restart, with a warning.
TEST(SlamWorker, TimeJumpsRestartOrDrop) {
  Recorder rec;
  SlamWorker worker(smallConfig(), 100, rec.callbacks());
  worker.push(Pose2(), roomScan(Pose2(), 100.0));
  worker.push(Pose2(), roomScan(Pose2(), 99.5));  // 0.5 s back: dropped
  worker.waitIdle();
  EXPECT_EQ(rec.stamps, (std::vector<double>{100.0}));
  ASSERT_EQ(rec.warnings.size(), 1u);
  EXPECT_NE(rec.warnings[0].find("older"), std::string::npos) << rec.warnings[0];
  EXPECT_EQ(rec.restarts, 0);
  const uint64_t version_before = worker.latestMap().version;

  worker.push(Pose2(), roomScan(Pose2(), 50.0));  // a looping bag: outliers until the third
  worker.push(Pose2(), roomScan(Pose2(), 50.5));
  worker.waitIdle();
  EXPECT_EQ(rec.restarts, 0);
  EXPECT_EQ(worker.stats().stamp_outliers, 2u);
  worker.push(Pose2(), roomScan(Pose2(), 51.0));
  worker.waitIdle();
  EXPECT_EQ(rec.restarts, 1);
  EXPECT_EQ(worker.resets(), 1u);
  EXPECT_NE(rec.warnings.back().find("time jumped back"), std::string::npos);
  EXPECT_EQ(rec.stamps.back(), 51.0);
  EXPECT_TRUE(rec.processed.back());  // the first scan of the new run
  EXPECT_GT(worker.latestMap().version, version_before);
  uint64_t received = 0;
  worker.runOnWorker(
      [&](const MappingSession& s) { received = s.engine().stats().scans_received; });
  EXPECT_EQ(received, 1u);  // the engine started over
  const WorkerStats stats = worker.stats();
  EXPECT_EQ(stats.handled, 5u);
  EXPECT_EQ(stats.dropped, 1u);
  EXPECT_EQ(stats.restarts, 1u);
  EXPECT_GE(stats.max_latency_s, stats.last_latency_s);
  EXPECT_GT(stats.last_latency_s, 0.0);
}

// A restart the front end asks for (its clock went back) comes after the scans already queued,
// saves the map first, and the next scan starts the new run.
TEST(SlamWorker, RequestedRestartSavesTheMapInOrder) {
  const std::filesystem::path root = test::scratchDir();
  Recorder rec;
  SlamWorker worker(smallConfig(), 100, rec.callbacks());
  worker.setResetSaveRoot(root.string());
  worker.push(Pose2(), roomScan(Pose2(), 100.0));
  worker.push(Pose2(0.6, 0, 0), roomScan(Pose2(), 101.0));
  worker.requestRestart("ROS time jumped back by 60 s");
  worker.push(Pose2(), roomScan(Pose2(), 41.0));
  worker.waitIdle();
  EXPECT_EQ(rec.restarts, 1);
  EXPECT_EQ(rec.stamps, (std::vector<double>{100.0, 101.0, 41.0}));
  const std::string& w = rec.warnings.back();
  EXPECT_NE(w.find("ROS time jumped back by 60 s: the SLAM starts over"), std::string::npos) << w;
  EXPECT_TRUE(std::filesystem::is_regular_file(root / "before_reset_101.000" / "trajectory.tum"))
      << w;
  EXPECT_EQ(worker.stats().last_reset_save, (root / "before_reset_101.000").string());
}

TEST(SlamWorker, FullQueueRefusesScans) {
  Recorder rec;
  SlamWorker worker(smallConfig(), 2, rec.callbacks());
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<bool> task_running{false};
  std::thread blocker([&] {
    worker.runOnWorker([&](const MappingSession&) {
      task_running = true;
      released.wait();
    });
  });
  while (!task_running) std::this_thread::yield();
  EXPECT_TRUE(worker.push(Pose2(), roomScan(Pose2(), 1.0)));
  EXPECT_TRUE(worker.push(Pose2(), roomScan(Pose2(), 2.0)));
  EXPECT_FALSE(worker.push(Pose2(), roomScan(Pose2(), 3.0)));
  EXPECT_EQ(worker.queued(), 2u);
  release.set_value();
  blocker.join();
  worker.waitIdle();
  EXPECT_EQ(rec.stamps, (std::vector<double>{1.0, 2.0}));
}

// Live mode: scans that waited while the filter was busy are skipped for the newest, whose
// odometry spans the gap; a restart request is not skipped over. Without it, every scan in order.
TEST(SlamWorker, LiveModeSkipsToTheNewestScan) {
  for (const bool live : {true, false}) {
    Recorder rec;
    SlamWorker worker(smallConfig(), 100, rec.callbacks());
    worker.setLive(live);
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    std::atomic<bool> task_running{false};
    std::thread blocker([&] {
      worker.runOnWorker([&](const MappingSession&) {
        task_running = true;
        released.wait();
      });
    });
    while (!task_running) std::this_thread::yield();
    for (int i = 0; i < 5; ++i) {
      const Pose2 odom(0.1 * i, 0.0, 0.0);
      ASSERT_TRUE(worker.push(odom, roomScan(odom, 10.0 + i)));
    }
    release.set_value();
    blocker.join();
    worker.waitIdle();
    if (live) {
      EXPECT_EQ(rec.stamps, (std::vector<double>{14.0}));
      EXPECT_EQ(worker.stats().skipped, 4u);
      ASSERT_EQ(rec.processed.size(), 1u);
      EXPECT_TRUE(rec.processed[0]);  // the first scan of the SLAM
    } else {
      EXPECT_EQ(rec.stamps, (std::vector<double>{10.0, 11.0, 12.0, 13.0, 14.0}));
      EXPECT_EQ(worker.stats().skipped, 0u);
    }
    EXPECT_EQ(worker.stats().handled, live ? 1u : 5u);
  }
}

TEST(SlamWorker, LiveModeDoesNotSkipOverARestart) {
  Recorder rec;
  SlamWorker worker(smallConfig(), 100, rec.callbacks());
  worker.setLive(true);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<bool> task_running{false};
  std::thread blocker([&] {
    worker.runOnWorker([&](const MappingSession&) {
      task_running = true;
      released.wait();
    });
  });
  while (!task_running) std::this_thread::yield();
  ASSERT_TRUE(worker.push(Pose2(), roomScan(Pose2(), 10.0)));
  ASSERT_TRUE(worker.push(Pose2(), roomScan(Pose2(), 11.0)));
  worker.requestRestart("test");
  ASSERT_TRUE(worker.push(Pose2(), roomScan(Pose2(), 12.0)));
  ASSERT_TRUE(worker.push(Pose2(), roomScan(Pose2(), 13.0)));
  release.set_value();
  blocker.join();
  worker.waitIdle();
  EXPECT_EQ(rec.stamps, (std::vector<double>{11.0, 13.0}));
  EXPECT_EQ(rec.restarts, 1);
  EXPECT_EQ(worker.stats().skipped, 2u);
}

TEST(SlamWorker, ReconfigureAppliesBeforeTheNextScan) {
  Recorder rec;
  SlamWorker worker(smallConfig(), 100, rec.callbacks());
  Parameters bad = smallConfig();
  bad.slam.sensor.random_weight = 2.0;
  std::string why;
  EXPECT_FALSE(worker.reconfigure(bad, &why));
  EXPECT_FALSE(why.empty());
  Parameters gate = smallConfig();
  gate.slam.update_min_distance = 0.2;
  ASSERT_TRUE(worker.reconfigure(gate, &why)) << why;
  worker.push(Pose2(), roomScan(Pose2(), 1.0));
  worker.push(Pose2(0.3, 0, 0), roomScan(Pose2(0.3, 0, 0), 2.0));  // 0.3 m > 0.2 m
  worker.waitIdle();
  EXPECT_EQ(rec.processed, (std::vector<bool>{true, true}));
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
