// MapWait: when the map fusion nodelet subscribes again to a robot's map that has not arrived.
#include <gtest/gtest.h>

#include "evidential_slam/ros/map_wait.h"

namespace evidential_slam {
namespace ros_adapter {
namespace {

TEST(MapWait, SubscribesAgainAfterAWaitThatDoublesUpToTheMaximum) {
  MapWait wait(5.0, 12.0);
  wait.subscribed(100.0);
  EXPECT_FALSE(wait.resubscribeDue(104.9, false));
  EXPECT_FALSE(wait.resubscribeDue(105.0, false));  // not more than the wait yet
  EXPECT_TRUE(wait.resubscribeDue(105.1, false));
  wait.subscribed(105.1);
  EXPECT_FALSE(wait.resubscribeDue(115.0, false));  // 9.9 s of 10
  EXPECT_TRUE(wait.resubscribeDue(115.2, false));
  wait.subscribed(115.2);
  EXPECT_FALSE(wait.resubscribeDue(127.1, false));  // 11.9 s: 20 capped at 12
  EXPECT_TRUE(wait.resubscribeDue(127.3, false));
  wait.subscribed(127.3);
  EXPECT_TRUE(wait.resubscribeDue(139.4, false));  // stays at 12
  EXPECT_NEAR(wait.waitedSince(139.4), 12.1, 1e-9);
}

TEST(MapWait, AMapThatArrivedIsNeverWaitedFor) {
  MapWait wait(5.0, 120.0);
  wait.subscribed(0.0);
  EXPECT_FALSE(wait.resubscribeDue(1000.0, true));
  EXPECT_TRUE(wait.resubscribeDue(1000.0, false));  // the wait did not double meanwhile
}

}  // namespace
}  // namespace ros_adapter
}  // namespace evidential_slam
