// rawlog_to_bag: turns an MRPT rawlog (either format; io/rawlog_reader.h) into a rosbag as a
// robot would have recorded it, for rosbag.launch (`rosbag play --clock`):
//   /scan        sensor_msgs/LaserScan: the laser's angle_min/increment and range limits, +inf for
//                no return (REP-117)
//   /tf          odom -> base_link from the wheel odometry, at each scan's stamp
//   /tf_static   base_link -> laser from the laser's pose on the robot (latched, once)
// Every message is written at its header stamp, so `--clock` replays the log's own time. No ROS
// master is needed.
//   rawlog_to_bag IN.rawlog OUT.bag [--laser-label L] [--scan-topic /scan]
//                 [--odom-frame odom] [--base-frame base_link] [--laser-frame laser]
#include <cstdio>
#include <cstring>
#include <string>

#include <ros/time.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#include <boost/make_shared.hpp>

#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/ros/conversions.h"

namespace es = evidential_slam;

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: rawlog_to_bag IN.rawlog OUT.bag [--laser-label L] [--scan-topic /scan]\n"
               "       [--odom-frame odom] [--base-frame base_link] [--laser-frame laser]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string in, out, scan_topic = "/scan", odom_frame = "odom", base_frame = "base_link",
                       laser_frame = "laser";
  es::io::RawlogReaderConfig config;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](std::string* v) {
      if (i + 1 >= argc) return false;
      *v = argv[++i];
      return true;
    };
    bool ok = true;
    if (a == "--laser-label") {
      ok = value(&config.laser_label);
    } else if (a == "--scan-topic") {
      ok = value(&scan_topic);
    } else if (a == "--odom-frame") {
      ok = value(&odom_frame);
    } else if (a == "--base-frame") {
      ok = value(&base_frame);
    } else if (a == "--laser-frame") {
      ok = value(&laser_frame);
    } else if (!a.empty() && a[0] == '-') {
      ok = false;
    } else if (in.empty()) {
      in = a;
    } else if (out.empty()) {
      out = a;
    } else {
      ok = false;
    }
    if (!ok) return usage();
  }
  if (in.empty() || out.empty()) return usage();

  ros::Time::init();
  es::io::RawlogReader reader(config);
  std::string error;
  if (!reader.open(in, &error)) {
    std::fprintf(stderr, "rawlog_to_bag: %s\n", error.c_str());
    return 1;
  }
  rosbag::Bag bag;
  try {
    bag.open(out, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    std::fprintf(stderr, "rawlog_to_bag: %s: %s\n", out.c_str(), e.what());
    return 1;
  }
  // /tf_static is latched, as tf2's static broadcaster publishes it.
  // A connection header replaces the one rosbag would write: it names the type too.
  using TFMessageTraits = ros::message_traits::DataType<tf2_msgs::TFMessage>;
  auto latched = boost::make_shared<ros::M_string>();
  (*latched)["type"] = TFMessageTraits::value();
  (*latched)["md5sum"] = ros::message_traits::MD5Sum<tf2_msgs::TFMessage>::value();
  (*latched)["message_definition"] = ros::message_traits::Definition<tf2_msgs::TFMessage>::value();
  (*latched)["latching"] = "1";
  (*latched)["callerid"] = "/rawlog_to_bag";

  es::io::RawlogScan item;
  uint64_t written = 0, skipped = 0;
  double last_stamp = 0.0, range_sigma = 0.0;
  while (true) {
    const es::io::RawlogReader::Status status = reader.next(&item);
    if (status == es::io::RawlogReader::Status::kError) {
      std::fprintf(stderr, "rawlog_to_bag: %s: %s\n", in.c_str(), reader.message().c_str());
      bag.close();
      return 1;
    }
    if (status != es::io::RawlogReader::Status::kScan) {
      if (status == es::io::RawlogReader::Status::kTruncated) {
        std::fprintf(stderr, "rawlog_to_bag: warning: %s\n", reader.message().c_str());
      }
      break;
    }
    // A bag's times must be positive and, for --clock, not go back.
    if (!(item.scan.stamp > 0.0) || item.scan.stamp < last_stamp) {
      ++skipped;
      continue;
    }
    sensor_msgs::LaserScan scan;
    std::string why;
    if (!es::ros_adapter::scanToRos(item.scan, laser_frame, &scan, &why)) {
      std::fprintf(stderr, "rawlog_to_bag: scan at %.3f skipped: %s\n", item.scan.stamp,
                   why.c_str());
      ++skipped;
      continue;
    }
    const ros::Time stamp(item.scan.stamp);
    if (written == 0) {
      tf2_msgs::TFMessage mount;
      mount.transforms.push_back(es::ros_adapter::toTransformStamped(item.scan.sensor_pose, stamp,
                                                                     base_frame, laser_frame));
      bag.write("/tf_static", stamp, mount, latched);
      range_sigma = item.scan.range_sigma;
    }
    tf2_msgs::TFMessage odometry;
    odometry.transforms.push_back(
        es::ros_adapter::toTransformStamped(item.odometry, stamp, odom_frame, base_frame));
    bag.write("/tf", stamp, odometry);
    bag.write(scan_topic, stamp, scan);
    last_stamp = item.scan.stamp;
    ++written;
  }
  bag.close();
  for (const std::string& w : reader.warnings())
    std::fprintf(stderr, "rawlog_to_bag: %s\n", w.c_str());
  std::printf(
      "rawlog_to_bag: %lu scans written to %s (%s, %lu skipped: no positive or increasing "
      "stamp, or malformed)\n"
      "rawlog_to_bag: declared range noise %.4f m (a LaserScan carries none: give the SLAM "
      "laser_range_sigma:=%.4f for the offline runner's sensor model)\n",
      static_cast<unsigned long>(written), out.c_str(), toString(reader.format()),
      static_cast<unsigned long>(skipped), range_sigma, range_sigma);
  return written > 0 ? 0 : 1;
}
