// Tests of the SLAM worker thread (slam_worker.h): order, map snapshots, time jumps, a full
// queue, run-time parameters and tasks run between scans.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "evidential_slam/ros/slam_worker.h"
#include "test_support.h"

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

// Back by more than the tolerance: restart (with a warning); back by less: the scan is dropped.
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

  worker.push(Pose2(), roomScan(Pose2(), 50.0));  // a looping bag
  worker.waitIdle();
  EXPECT_EQ(rec.restarts, 1);
  EXPECT_EQ(worker.resets(), 1u);
  EXPECT_NE(rec.warnings.back().find("time jumped back"), std::string::npos);
  EXPECT_EQ(rec.stamps.back(), 50.0);
  EXPECT_TRUE(rec.processed.back());  // the first scan of the new run
  EXPECT_GT(worker.latestMap().version, version_before);
  uint64_t received = 0;
  worker.runOnWorker(
      [&](const MappingSession& s) { received = s.engine().stats().scans_received; });
  EXPECT_EQ(received, 1u);  // the engine started over
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
