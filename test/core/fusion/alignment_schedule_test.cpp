// When map fusion aligns a robot's map again (alignment_schedule.h).
#include <gtest/gtest.h>

#include "evidential_slam/core/fusion/alignment_schedule.h"

namespace evidential_slam {
namespace fusion {
namespace {

constexpr double kInterval = 10.0;  // s between refreshes of an aligned robot

TEST(AlignmentSchedule, ARobotNeverTriedIsDue) {
  const AlignmentInputs never;
  EXPECT_TRUE(alignmentDue(false, never, 0.0, {1, "/robot1", 1}, 0.0, kInterval));
}

// A refused alignment is not repeated on the same two maps, however much time passed: it would be
// refused again.
TEST(AlignmentSchedule, ARefusedAlignmentWaitsForAChangedMap) {
  const AlignmentInputs tried{3, "/robot1", 5};
  EXPECT_FALSE(alignmentDue(false, tried, 100.0, {3, "/robot1", 5}, 1000.0, kInterval));
  EXPECT_TRUE(alignmentDue(false, tried, 100.0, {4, "/robot1", 5}, 100.0, kInterval));
  EXPECT_TRUE(alignmentDue(false, tried, 100.0, {3, "/robot1", 6}, 100.0, kInterval));
  EXPECT_TRUE(alignmentDue(false, tried, 100.0, {3, "/robot0", 5}, 100.0, kInterval));
}

TEST(AlignmentSchedule, AnAlignedRobotIsRefreshedWhenItsMapChangedAtTheRate) {
  const AlignmentInputs done{3, "/robot1", 5};
  // Own map unchanged: not again, even when the reference's changed.
  EXPECT_FALSE(alignmentDue(true, done, 100.0, {3, "/robot1", 9}, 1000.0, kInterval));
  // Changed: after the interval, not before.
  EXPECT_FALSE(alignmentDue(true, done, 100.0, {4, "/robot1", 5}, 109.9, kInterval));
  EXPECT_TRUE(alignmentDue(true, done, 100.0, {4, "/robot1", 5}, 110.0, kInterval));
}

// A robot whose pose is in another robot's frame (the reference changed, e.g. a robot whose name
// sorts first appeared) is aligned again at once.
TEST(AlignmentSchedule, AnAlignedRobotIsAlignedAgainOnANewReference) {
  const AlignmentInputs done{3, "/robot1", 5};
  EXPECT_TRUE(alignmentDue(true, done, 100.0, {3, "/robot0", 1}, 100.0, kInterval));
  // The former reference itself had no attempt: its identity pose was the reference's.
  EXPECT_TRUE(alignmentDue(true, AlignmentInputs(), 0.0, {7, "/robot0", 1}, 0.0, kInterval));
}

}  // namespace
}  // namespace fusion
}  // namespace evidential_slam
