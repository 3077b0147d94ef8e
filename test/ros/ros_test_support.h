// Shared by the rostest nodes: waiting (wall time) for what the callbacks record.
#pragma once

#include <chrono>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>
#include <ros/ros.h>

namespace evidential_slam {
namespace testing_ros {

// Polls `ready()` under `mutex` every 50 ms until it holds (true) or `seconds` of wall time pass
// or ROS shuts down (false, after a last look).
template <typename F>
bool waitUntil(std::mutex& mutex, F&& ready, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline && ros::ok()) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (ready()) return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::lock_guard<std::mutex> lock(mutex);
  return ready();
}

// A rostest program's end: runs every test while `threads` spinner threads serve the callbacks,
// then shuts ROS down. Returns RUN_ALL_TESTS()'s result.
inline int runAllTestsSpinning(int threads = 2) {
  ros::AsyncSpinner spinner(threads);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}

}  // namespace testing_ros
}  // namespace evidential_slam
