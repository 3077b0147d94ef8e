// Tests of the update's profiler (profile.h): nothing is recorded without an active profiler, a
// section's time excludes the sections timed inside it, counters add up, and the floor replay
// counts every cell it is given.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/profile.h"

namespace evidential_slam {
namespace {

// Makes a profiler active for one test and inactive again after it.
class Activated {
 public:
  explicit Activated(Profiler* p) { Profiler::setActive(p); }
  ~Activated() { Profiler::setActive(nullptr); }
};

TEST(ProfilerTest, NothingIsRecordedWithoutAnActiveProfiler) {
  Profiler profiler;
  ASSERT_EQ(Profiler::active(), nullptr);
  { const ProfileTimer timer(ProfileSection::kApplyScan); }
  EXPECT_EQ(profiler.nanoseconds(ProfileSection::kApplyScan), 0);
}

// An outer section that only waits for an inner one of 30 ms of CPU is charged (almost) nothing:
// the inner one's time is the inner section's.
TEST(ProfilerTest, NestedSectionsAreExclusive) {
  Profiler profiler;
  Activated on(&profiler);
  {
    const ProfileTimer outer(ProfileSection::kWeighAccumulate);
    const ProfileTimer inner(ProfileSection::kTileClone);
    const int64_t until = ProfileTimer::threadCpuNs() + 30'000'000;
    while (ProfileTimer::threadCpuNs() < until) {
    }
  }
  EXPECT_GE(profiler.nanoseconds(ProfileSection::kTileClone), 30'000'000);
  EXPECT_LT(profiler.nanoseconds(ProfileSection::kWeighAccumulate),
            profiler.nanoseconds(ProfileSection::kTileClone) / 2);
}

TEST(ProfilerTest, CountersAndFloorReplayAddUp) {
  Profiler profiler;
  profiler.floor_enabled = true;
  profiler.count(ProfileCounter::kUpdates, 2);
  profiler.count(ProfileCounter::kVisitedCells, 5);
  profiler.count(ProfileCounter::kVisitedCells, 7);
  EXPECT_EQ(profiler.counter(ProfileCounter::kVisitedCells), 12u);
  // Two groups' cells on maps of their own, across tile borders and at negative coordinates.
  const std::vector<std::pair<int, int>> cells = {{0, 0}, {31, 0}, {32, 0}, {-1, -1}, {-40, 70}};
  profiler.floorReplay(0, cells);
  profiler.floorReplay(1, cells);
  profiler.floorReplay(0, {{0, 0}});
  EXPECT_EQ(profiler.counter(ProfileCounter::kFloorCells), 11u);
  EXPECT_GE(profiler.floorNanoseconds(), 0);
  const std::string report = profiler.report();
  EXPECT_NE(report.find("floor:"), std::string::npos) << report;
  EXPECT_NE(report.find("visited_cells 12 (6.0 per update)"), std::string::npos) << report;
}

}  // namespace
}  // namespace evidential_slam
