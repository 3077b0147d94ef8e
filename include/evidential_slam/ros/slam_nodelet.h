// The SLAM nodelet: LaserScan (through a tf2 MessageFilter) + odometry from tf in; map->odom tf,
// ~pose, ~particles, ~path and the map topics (MapPublisher) out; /initialpose and the services
// that save, load, pause and reset the map. With mode localization the same node localizes on
// map_file's map (the session's Localizer) and offers ~global_localization. Thin by design:
// conversions live in conversions.h, parameters in params.h, map files in session/map_files.h, the
// filter runs on SlamWorker's thread.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <message_filters/subscriber.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/GetMap.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include "evidential_slam/EvidentialSlamConfig.h"
#include "evidential_slam/LoadMap.h"
#include "evidential_slam/SaveMap.h"
#include "evidential_slam/core/stamp_order.h"
#include "evidential_slam/ros/map_publisher.h"
#include "evidential_slam/ros/params.h"
#include "evidential_slam/ros/slam_worker.h"

namespace evidential_slam {
namespace ros_adapter {

class SlamNodelet : public nodelet::Nodelet {
 public:
  SlamNodelet();
  ~SlamNodelet() override;

 private:
  void onInit() override;
  void onScan(const sensor_msgs::LaserScan::ConstPtr& msg);
  // One line each: gmapping names read, shadowed by ours, without a counterpart, refused.
  void logGmappingReport(const GmappingReport& report);
  // Asks the map publisher for the latest map (map_update_interval, on ROS or wall time).
  void requestMapUpdate();
  void onScanWithoutTransform(const sensor_msgs::LaserScan::ConstPtr& msg,
                              tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void onRawScan(const sensor_msgs::LaserScan::ConstPtr& msg);
  void checkWaitingScans(const ros::WallTimerEvent&);
  void onScanHandled(const MappingSession& session, const SessionScanResult& result);
  void onReconfigure(EvidentialSlamConfig& config, uint32_t level);
  void publishTransform(const ros::TimerEvent&);
  void reportConflict(const SessionScanResult& result, const ros::Time& stamp);
  // ~pose and ~particles (while subscribed) from the session's engine, stamped `stamp`.
  void publishEstimate(const MappingSession& session, const ros::Time& stamp);
  bool saveMap(SaveMap::Request& request, SaveMap::Response& response);
  bool getMap(nav_msgs::GetMap::Request& request, nav_msgs::GetMap::Response& response);
  bool loadMap(LoadMap::Request& request, LoadMap::Response& response);
  // Empties the tf buffer (a reset, a loaded map, a jump of the stamps) and forgets the stamps.
  void clearTransforms();
  bool pauseMapping(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  bool resetSlam(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool globalLocalization(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  // Localization mode: localizes on `map` from `start`. False and `why` when refused.
  bool localizeOn(const EvidentialGridMap& map, const LocalizationStart& start, std::string* why);
  // Localization mode: the particles start again as `start` says on the same map.
  bool restartLocalization(const LocalizationStart& start, std::string* why);
  // Localization mode: `pose` with the initial_cov_* variances.
  LocalizationStart startAt(const Pose2& pose);
  bool localizationMode() const { return localization_mode_; }
  void onInitialPose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg);
  // Restarts the SLAM on `map` at `pose` (map frame). With the odometry pose at that moment
  // (`odometry`, from tf) the scans to come are placed by the odometry since; map -> odom is
  // then known at once. False and `why` when the session refuses.
  bool startOnMap(const EvidentialGridMap& map, const Pose2& pose, const Pose2* odometry,
                  std::string* why);
  // At start-up: on map_file's map (at its saved pose or initial_pose_*), or with no map at
  // initial_pose_* when given. False and `why` when the map cannot be used.
  bool startFromParameters(std::string* why);
  // The latest odom -> base pose from tf, if there is one.
  bool currentOdometry(Pose2* odometry);
  void heartbeat(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, private_nh_;
  std::mutex params_mutex_;
  NodeParams params_;
  bool localization_mode_ = false;  // mode: localization (a start-up parameter)

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  std::unique_ptr<message_filters::Subscriber<sensor_msgs::LaserScan>> scan_sub_;
  std::unique_ptr<tf2_ros::MessageFilter<sensor_msgs::LaserScan>> scan_filter_;

  ros::Publisher pose_pub_, particles_pub_, path_pub_;
  // Conflict alarm: per processed scan, the conflict it added (~conflict_added), the part in the
  // map's open space that the alarm watches (~open_space_conflict_added) and a diagnostic_msgs
  // status on /diagnostics; a warning when a new alarm rises.
  ros::Publisher conflict_pub_, open_space_conflict_pub_, diagnostics_pub_;
  ros::ServiceServer save_map_srv_, get_map_srv_, load_map_srv_, pause_srv_, reset_srv_,
      global_localization_srv_;
  ros::Subscriber initial_pose_sub_;
  ros::Timer map_timer_, tf_timer_;
  ros::WallTimer map_wall_timer_;                  // the map also when ROS time stands still
  std::atomic<ros::WallTime> last_map_request_{};  // by either timer
  // The filter holds a scan until its tf arrives and says nothing meanwhile: this watchdog warns,
  // naming the missing transform, when scans arrive but none has passed for a while.
  ros::WallTimer tf_watchdog_;
  std::mutex watchdog_mutex_;
  sensor_msgs::LaserScan::ConstPtr last_raw_scan_;
  ros::WallTime last_raw_arrival_, last_passed_arrival_;
  // Scans inside the filter, by arrival: one still there when newer ones have gone through is
  // reported as lost (the filter itself would only drop it silently, much later).
  std::map<sensor_msgs::LaserScan::ConstPtr, ros::WallTime> in_filter_;
  std::unique_ptr<dynamic_reconfigure::Server<EvidentialSlamConfig>> reconfigure_server_;
  boost::recursive_mutex reconfigure_mutex_;

  // The heartbeat on /diagnostics (once a second, wall time: also while nothing moves): scan
  // rate, queue, latency, every kind of drop, restarts and the conflict alarm.
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::WallTimer heartbeat_timer_;
  std::atomic<uint64_t> scans_received_{0};   // every LaserScan that arrived
  std::atomic<uint64_t> scans_malformed_{0};  // refused by checkLaserScan
  std::atomic<uint64_t> scans_without_tf_{0};
  uint64_t heartbeat_received_ = 0;  // scans_received_ at the last heartbeat
  ros::WallTime heartbeat_time_;
  // ROS time of the last scan's arrival: when it goes back (the /clock of a looping bag) the SLAM
  // starts over at once (watchdog_mutex_).
  ros::Time last_arrival_ros_time_;
  StampOrder scan_stamps_;  // the raw scans' stamps (onRawScan), under watchdog_mutex_

  std::unique_ptr<SlamWorker> worker_;
  std::unique_ptr<MapPublisher> map_publisher_;

  std::mutex transform_mutex_;
  bool have_transform_ = false;
  Pose2 map_to_odom_;
  ros::Time last_tf_stamp_;  // of the last map -> odom broadcast (tf timer thread only)
};

}  // namespace ros_adapter
}  // namespace evidential_slam
