// What the SLAM node tells after each scan: ~pose, ~particles (while subscribed), ~path, the
// conflict alarm (~conflict_added, ~open_space_conflict_added, a status on /diagnostics and a
// warning when an alarm rises), and map -> odom: stamped with each handled scan's stamp (a lookup
// at a scan's stamp gets that scan's correction), and on a timer post-dated like gmapping's
// (lookups at the present).
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "evidential_slam/core/pose2.h"
#include "evidential_slam/ros/guarded_params.h"
#include "evidential_slam/ros/tf_stamp_guard.h"
#include "evidential_slam/session/session.h"

namespace evidential_slam {
namespace ros_adapter {

class SlamOutputs {
 public:
  // `name`: the nodelet's, for the log and the diagnostics status.
  SlamOutputs(std::string name, ros::NodeHandle& nh, ros::NodeHandle& private_nh,
              GuardedParams& params);
  ~SlamOutputs() { tf_timer_.stop(); }

  // Every handled scan (the worker's thread): map -> odom, the estimate, the path, the alarm.
  void onScanHandled(const MappingSession& session, const SessionScanResult& result);
  // ~pose and ~particles (while subscribed) from the session's estimate, stamped `stamp`.
  void publishEstimate(const MappingSession& session, const ros::Time& stamp);
  // map -> odom from now on; forgotten (not broadcast) until the next handled scan.
  void setMapToOdom(const Pose2& map_to_odom);
  void forgetMapToOdom();

 private:
  void reportConflict(const SessionScanResult& result, const ros::Time& stamp);
  void publishTransform(const ros::TimerEvent&);
  // map -> odom stamped `stamp`, unless a listener would drop it (TfStampGuard).
  void sendMapToOdom(const Pose2& map_to_odom, const ros::Time& stamp);

  const std::string name_;
  GuardedParams& params_;
  ros::Publisher pose_pub_, particles_pub_, path_pub_;
  ros::Publisher conflict_pub_, open_space_conflict_pub_, diagnostics_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Timer tf_timer_;

  std::mutex transform_mutex_;
  bool have_transform_ = false;
  Pose2 map_to_odom_;
  std::mutex tf_mutex_;                    // the timer's and the worker's broadcasts
  ros::Time last_timer_now_;               // tf timer thread only
  std::atomic<bool> scan_stamped_{false};  // map -> odom also went at a scan's stamp
  TfStampGuard tf_guard_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
