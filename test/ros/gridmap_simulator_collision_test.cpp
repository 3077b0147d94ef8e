// rostest for gridmap_simulator's collisions (gridmap_simulator_collision.test): this node drives
// the robot at 0.3 m/s into the wall 0.85 m ahead of it and checks that ~collisions (latched)
// reads 0 before and 1 after, and that the true pose stops with the robot's disc (0.2 m) on the
// wall, 0.65 m from the start, however long the command pushes on.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <std_msgs/UInt32.h>

#include "ros_test_support.h"

namespace evidential_slam {
namespace {

struct Observed {
  std::mutex mutex;
  bool have_collisions = false;
  uint32_t collisions = 0;
  size_t collision_messages = 0;
  bool have_pose = false;
  double x = 0.0, y = 0.0;  // true pose in `map` (the start pose is the origin)
  double stamp = 0.0;
};

Observed* observed = nullptr;
ros::Publisher* cmd_vel = nullptr;

template <typename F>
bool waitFor(F&& ready, double seconds) {
  return testing_ros::waitUntil(observed->mutex, std::forward<F>(ready), seconds);
}

// Publishes (v, 0) every 50 ms of wall time for `seconds` of simulated time.
void drive(double v, double seconds) {
  geometry_msgs::Twist twist;
  twist.linear.x = v;
  const double until = ros::Time::now().toSec() + seconds;
  while (ros::ok() && ros::Time::now().toSec() < until) {
    cmd_vel->publish(twist);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

TEST(GridmapSimulatorCollision, StopsAtTheWallAndCountsOneCollision) {
  ASSERT_TRUE(waitFor([] { return observed->have_collisions && observed->have_pose; }, 60.0))
      << "no ~collisions or ground_truth_pose";
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    EXPECT_EQ(observed->collisions, 0u);
    EXPECT_NEAR(observed->x, 0.0, 1e-6);
  }
  // 0.3 m/s for 6 s would go 1.8 m; the wall stops it after 0.65 m (about 2.2 s).
  drive(0.3, 6.0);
  ASSERT_TRUE(waitFor([] { return observed->collisions >= 1; }, 10.0)) << "no collision seen";
  const double first_stamp = ros::Time::now().toSec();
  ASSERT_TRUE(waitFor([&] { return observed->stamp > first_stamp; }, 10.0));
  {
    std::lock_guard<std::mutex> lock(observed->mutex);
    EXPECT_EQ(observed->collisions, 1u);
    EXPECT_EQ(observed->collision_messages, 2u);  // the latched 0, then 1
    EXPECT_NEAR(observed->x, 0.65, 0.005);        // facing west: the map's x axis points west
    EXPECT_NEAR(observed->y, 0.0, 1e-6);
  }
  // Pushing on for 2 s more: still one collision, still at the wall.
  drive(0.3, 2.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  std::lock_guard<std::mutex> lock(observed->mutex);
  EXPECT_EQ(observed->collisions, 1u);
  EXPECT_NEAR(observed->x, 0.65, 0.005);
}

}  // namespace
}  // namespace evidential_slam

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "gridmap_simulator_collision_test");
  ros::NodeHandle nh;
  evidential_slam::Observed obs;
  evidential_slam::observed = &obs;
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("/cmd_vel", 10);
  evidential_slam::cmd_vel = &cmd_vel;
  auto collisions = evidential_slam::testing_ros::subscribeLocked<std_msgs::UInt32>(
      nh, "/gridmap_simulator/collisions", 10, obs.mutex, [&](const std_msgs::UInt32::ConstPtr& m) {
        obs.have_collisions = true;
        obs.collisions = m->data;
        ++obs.collision_messages;
      });
  auto pose = evidential_slam::testing_ros::subscribeLocked<geometry_msgs::PoseStamped>(
      nh, "/ground_truth_pose", 100, obs.mutex, [&](const geometry_msgs::PoseStamped::ConstPtr& m) {
        obs.have_pose = true;
        obs.x = m->pose.position.x;
        obs.y = m->pose.position.y;
        obs.stamp = m->header.stamp.toSec();
      });
  return evidential_slam::testing_ros::runAllTestsSpinning();
}
