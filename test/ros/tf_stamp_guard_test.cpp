// TfStampGuard (ros/tf_stamp_guard.h): the map -> odom stamps a tf listener would keep.
#include <gtest/gtest.h>

#include "evidential_slam/ros/tf_stamp_guard.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

constexpr int64_t kSecond = 1000000000;

TEST(TfStampGuard, AdmitsOutOfOrderStampsWithinTheCacheTime) {
  TfStampGuard guard(10 * kSecond);
  EXPECT_TRUE(guard.admit(20 * kSecond + 100000000));  // the timer's, post-dated to 20.1 s
  EXPECT_TRUE(guard.admit(19 * kSecond));              // a scan's, before it
  EXPECT_TRUE(guard.admit(10 * kSecond + 100000000));  // 10 s before the newest: kept by tf
  EXPECT_TRUE(guard.admit(21 * kSecond));
}

TEST(TfStampGuard, RefusesARepeatedStamp) {
  TfStampGuard guard(10 * kSecond);
  EXPECT_TRUE(guard.admit(5 * kSecond));
  EXPECT_TRUE(guard.admit(6 * kSecond));
  EXPECT_FALSE(guard.admit(5 * kSecond));  // TF_REPEATED_DATA
  EXPECT_FALSE(guard.admit(6 * kSecond));
  EXPECT_TRUE(guard.admit(6 * kSecond + 1));
}

TEST(TfStampGuard, RefusesAStampOlderThanTheCacheBeforeTheNewest) {
  TfStampGuard guard(10 * kSecond);
  EXPECT_TRUE(guard.admit(30 * kSecond));
  EXPECT_FALSE(guard.admit(20 * kSecond - 1));  // TF_OLD_DATA: a filter 10 s behind
  EXPECT_TRUE(guard.admit(20 * kSecond));       // exactly the cache time: tf keeps it
  // Stamps that fell out of the cache are forgotten: the newest moved on, so they stay refused.
  EXPECT_TRUE(guard.admit(45 * kSecond));
  EXPECT_FALSE(guard.admit(30 * kSecond));
  EXPECT_TRUE(guard.admit(35 * kSecond));
  EXPECT_FALSE(guard.admit(35 * kSecond));
}

TEST(TfStampGuard, ClearStartsOver) {
  TfStampGuard guard(10 * kSecond);
  EXPECT_TRUE(guard.admit(100 * kSecond));
  EXPECT_FALSE(guard.admit(5 * kSecond));
  guard.clear();  // time jumped back
  EXPECT_TRUE(guard.admit(5 * kSecond));
  EXPECT_TRUE(guard.admit(100 * kSecond));
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
