// The map_fusion nodelet: finds robots by their EvidentialGrid topics (as m-explore's map_merge
// finds OccupancyGrid ones), places each robot's map by its initial pose in world_frame (given as
// map_merge's <robot>/map_merge/init_pose_* parameters, or estimated by fusion::alignMaps), fuses
// them by one combination rule (fusion::fuseMaps) on its own thread, and hands the fused map to a
// MapPublisher (as the SLAM nodelet does): `map`, `map_metadata`, ~grid and ~layers/<name>, the
// last two rendered only for their subscribers.
#pragma once

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <nodelet/nodelet.h>
#include <ros/ros.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/fusion/alignment_schedule.h"
#include "evidential_slam/core/fusion/combination.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/ros/map_fusion_params.h"
#include "evidential_slam/ros/map_publisher.h"
#include "evidential_slam/ros/map_wait.h"

namespace evidential_slam {
namespace ros_adapter {

class MapFusionNodelet : public nodelet::Nodelet {
 public:
  MapFusionNodelet() = default;
  ~MapFusionNodelet() override;

 private:
  struct Robot {
    std::string name;  // its namespace, e.g. /robot1
    ros::Subscriber sub;
    MapWait map_wait{5.0, 120.0};  // seconds; subscribing again to a map that does not arrive
    bool has_pose = false;         // known or estimated
    Pose2 pose;                    // its map frame in world_frame
    // Estimating (known_init_poses false): map_merge's init_pose_* when set, a prior that bounds
    // the search and breaks ties (AlignmentConfig::prior).
    bool has_prior = false;
    Pose2 prior;
    ros::WallTime estimated_at;                    // the last alignment attempt
    fusion::AlignmentInputs estimated;             // and what it aligned
    std::shared_ptr<const EvidentialGridMap> map;  // latest, null before the first message
    Pose2 grid_frame;  // the grid's frame in the robot's map frame (layer origin off the grid)
    uint64_t version = 0;
    double stamp = 0.0;
  };

  void onInit() override;
  void discover();
  // Subscribes to a robot's map; the robot must be in robots_ (onGrid drops unknown robots' maps).
  void subscribe(const std::string& robot, const std::string& topic);
  void onGrid(const std::string& robot, const EvidentialGrid::ConstPtr& msg);
  void run();
  bool fuseOnce();

  MapFusionParams params_;
  fusion::Rule rule_ = fusion::Rule::kCautious;
  ros::NodeHandle nh_, private_nh_;
  std::unique_ptr<MapPublisher> publisher_;
  std::mutex fused_mutex_;  // guards fused_ (the fusion thread writes it, the publisher reads it)
  MapSnapshot fused_;
  ros::WallTimer discovery_timer_, merging_timer_;

  std::mutex mutex_;  // guards robots_, wake_requested_, stop_
  std::condition_variable wake_;
  std::map<std::string, Robot> robots_;
  bool wake_requested_ = false;
  bool stop_ = false;
  uint64_t changes_ = 0;        // counts new maps and poses (guarded by mutex_)
  uint64_t fused_changes_ = 0;  // changes_ at the last fusion (fusion thread only)
  // Wall time of the fusion cycles so far (fusion thread only): logged every minute.
  struct CycleTimes {
    size_t cycles = 0, alignments = 0;
    double total_s = 0.0, align_s = 0.0, fuse_s = 0.0, max_s = 0.0;
  } times_;
  // Wall time of each robot's last "not aligned yet" warning (fusion thread only): throttled per
  // robot, so that one robot's refusals do not hide another's.
  std::map<std::string, double> refusal_warned_at_;
  std::thread thread_;
};

}  // namespace ros_adapter
}  // namespace evidential_slam
