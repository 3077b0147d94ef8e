// rawlog_to_bag (src/ros/rawlog_to_bag_main.cpp) on test/data/sim.rawlog: the bag holds one
// /scan and one /tf per scan the reader returns, at the scans' stamps, with the laser's angles
// and range limits and +inf for no return, the odometry as odom -> base_link, and one latched
// /tf_static base_link -> laser at the laser's pose.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/ros/conversions.h"

namespace evidential_slam {
namespace {

TEST(RawlogToBag, WritesScansOdometryAndTheMount) {
  const std::string rawlog = std::string(ES_TEST_DATA_DIR) + "/sim.rawlog";
  std::filesystem::create_directories(ES_TEST_TMP_DIR);
  const std::string out = std::string(ES_TEST_TMP_DIR) + "/rawlog_to_bag_sim.bag";
  std::filesystem::remove(out);
  const std::string cmd =
      std::string(ES_RAWLOG_TO_BAG_BIN) + " '" + rawlog + "' '" + out + "' > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  std::vector<io::RawlogScan> expected;
  io::RawlogReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(rawlog, &error)) << error;
  io::RawlogScan item;
  while (reader.next(&item) == io::RawlogReader::Status::kScan) expected.push_back(item);
  ASSERT_GT(expected.size(), 10u);

  rosbag::Bag bag(out, rosbag::bagmode::Read);
  std::vector<sensor_msgs::LaserScan::ConstPtr> scans;
  std::vector<tf2_msgs::TFMessage::ConstPtr> tfs, statics;
  std::vector<ros::Time> scan_times;
  bool static_latched = false;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (m.getTopic() == "/scan") {
      scans.push_back(m.instantiate<sensor_msgs::LaserScan>());
      scan_times.push_back(m.getTime());
    } else if (m.getTopic() == "/tf") {
      tfs.push_back(m.instantiate<tf2_msgs::TFMessage>());
    } else if (m.getTopic() == "/tf_static") {
      statics.push_back(m.instantiate<tf2_msgs::TFMessage>());
      const auto header = m.getConnectionHeader();
      static_latched = header && header->count("latching") && header->at("latching") == "1";
    }
  }
  ASSERT_EQ(scans.size(), expected.size());
  ASSERT_EQ(tfs.size(), expected.size());
  ASSERT_EQ(statics.size(), 1u);
  EXPECT_TRUE(static_latched);

  const geometry_msgs::TransformStamped& mount = statics[0]->transforms.at(0);
  EXPECT_EQ(mount.header.frame_id, "base_link");
  EXPECT_EQ(mount.child_frame_id, "laser");
  const Pose2 mount_pose = ros_adapter::pose2FromTransform(mount.transform);
  EXPECT_NEAR(mount_pose.x, expected[0].scan.sensor_pose.x, 1e-9);
  EXPECT_NEAR(mount_pose.theta, expected[0].scan.sensor_pose.theta, 1e-9);

  size_t no_return = 0;
  for (size_t i = 0; i < scans.size(); ++i) {
    const sensor_msgs::LaserScan& s = *scans[i];
    const LaserScan& e = expected[i].scan;
    EXPECT_NEAR(s.header.stamp.toSec(), e.stamp, 1e-6);
    EXPECT_EQ(scan_times[i], s.header.stamp);  // --clock replays the log's own time
    EXPECT_EQ(s.header.frame_id, "laser");
    ASSERT_EQ(s.ranges.size(), e.ranges.size());
    EXPECT_NEAR(s.angle_min, e.bearings.front(), 1e-5);
    EXPECT_NEAR(s.angle_increment, (e.bearings.back() - e.bearings.front()) / (e.size() - 1), 1e-5);
    EXPECT_FLOAT_EQ(s.range_max, e.max_range);
    for (size_t k = 0; k < e.ranges.size(); ++k) {
      if (!e.valid.empty() && e.valid[k] == 0) {
        EXPECT_TRUE(std::isinf(s.ranges[k]) && s.ranges[k] > 0);
        ++no_return;
      } else {
        EXPECT_FLOAT_EQ(s.ranges[k], e.ranges[k]);
      }
    }
    const geometry_msgs::TransformStamped& odom = tfs[i]->transforms.at(0);
    EXPECT_EQ(odom.header.frame_id, "odom");
    EXPECT_EQ(odom.child_frame_id, "base_link");
    EXPECT_EQ(odom.header.stamp, s.header.stamp);
    const Pose2 p = ros_adapter::pose2FromTransform(odom.transform);
    EXPECT_NEAR(p.x, expected[i].odometry.x, 1e-9);
    EXPECT_NEAR(p.y, expected[i].odometry.y, 1e-9);
    EXPECT_NEAR(p.theta, expected[i].odometry.theta, 1e-9);
  }
  RecordProperty("no_return_rays", static_cast<int>(no_return));
}

TEST(RawlogToBag, AMissingRawlogIsOneLineAndAFailure) {
  const std::string out = std::string(ES_TEST_TMP_DIR) + "/rawlog_to_bag_missing.bag";
  const std::string cmd =
      std::string(ES_RAWLOG_TO_BAG_BIN) + " /nonexistent.rawlog '" + out + "' 2> /dev/null";
  EXPECT_NE(std::system(cmd.c_str()), 0);
}

}  // namespace
}  // namespace evidential_slam
