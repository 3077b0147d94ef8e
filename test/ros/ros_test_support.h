// Shared by the rostest nodes: waiting (wall time) for what the callbacks record.
#pragma once

#include <chrono>
#include <deque>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>

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

// Subscribes to `topic` and hands each message to `record` under `mutex`: the lock every rostest
// takes around what its callbacks store for the test to read.
template <typename M, typename F>
ros::Subscriber subscribeLocked(ros::NodeHandle& nh, const std::string& topic, uint32_t queue_size,
                                std::mutex& mutex, F record) {
  return nh.subscribe<M>(topic, queue_size, [&mutex, record](const typename M::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    record(m);
  });
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

// The last `capacity` lines the other nodes logged on /rosout (rostest runs no rosout node to
// aggregate them), for a failure message: what the nodes said while the test waited.
class NodeLog {
 public:
  explicit NodeLog(ros::NodeHandle& nh, size_t capacity = 20) : capacity_(capacity) {
    sub_ = nh.subscribe<rosgraph_msgs::Log>("/rosout", 100,
                                            [this](const rosgraph_msgs::Log::ConstPtr& m) {
                                              if (m->name == ros::this_node::getName()) return;
                                              std::lock_guard<std::mutex> lock(mutex_);
                                              lines_.push_back(m->name + ": " + m->msg);
                                              if (lines_.size() > capacity_) lines_.pop_front();
                                            });
  }
  std::string str() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream out;
    out << "the other nodes logged " << (lines_.empty() ? "nothing" : "(last lines):");
    for (const std::string& line : lines_) out << "\n  " << line;
    return out.str();
  }

 private:
  size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<std::string> lines_;
  ros::Subscriber sub_;
};

}  // namespace testing_ros
}  // namespace evidential_slam
