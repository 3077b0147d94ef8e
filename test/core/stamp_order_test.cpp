// The stamp policy shared by the rawlog reader and the session (core/stamp_order.h).
#include "evidential_slam/core/stamp_order.h"

#include <gtest/gtest.h>

namespace evidential_slam {
namespace {

using V = StampOrder::Verdict;

TEST(StampOrder, OneFarStampIsAnOutlierAndTheStreamGoesOn) {
  StampOrder order(StampPolicy{1.0, 100.0, 3});
  EXPECT_EQ(order.next(10.0), V::kInOrder);
  EXPECT_EQ(order.next(11.0), V::kInOrder);
  EXPECT_EQ(order.next(10811.0), V::kOutlier);  // ahead by more than 100 s
  EXPECT_EQ(order.last(), 11.0);
  EXPECT_EQ(order.next(12.0), V::kInOrder);
  EXPECT_EQ(order.next(11.5), V::kDropped);  // a little older
  EXPECT_EQ(order.next(5.0), V::kOutlier);   // back by more than 1 s
  EXPECT_EQ(order.next(13.0), V::kInOrder);
  EXPECT_EQ(order.last(), 13.0);
}

TEST(StampOrder, AJumpIsBelievedAfterItsCountInARow) {
  StampOrder order(StampPolicy{1.0, 100.0, 3});
  order.next(10.0);
  EXPECT_EQ(order.next(1000.0), V::kOutlier);
  EXPECT_EQ(order.jumpsInARow(), 1);
  EXPECT_EQ(order.next(1001.0), V::kOutlier);
  EXPECT_EQ(order.next(1002.0), V::kJumpedAhead);
  EXPECT_EQ(order.last(), 1002.0);
  EXPECT_EQ(order.next(1.0), V::kOutlier);
  EXPECT_EQ(order.next(5000.0), V::kOutlier);  // the other way: the count starts again
  EXPECT_EQ(order.jumpsInARow(), 1);
  EXPECT_EQ(order.next(2.0), V::kOutlier);
  EXPECT_EQ(order.next(3.0), V::kOutlier);
  EXPECT_EQ(order.next(4.0), V::kJumpedBack);
  EXPECT_EQ(order.last(), 4.0);
  order.reset();
  EXPECT_FALSE(order.hasLast());
  EXPECT_EQ(order.next(-50.0), V::kInOrder);
}

}  // namespace
}  // namespace evidential_slam
