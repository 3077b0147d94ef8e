#include "evidential_slam/ros/map_publisher.h"

#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>

#include "evidential_slam/EvidentialGrid.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/ros/conversions.h"

namespace evidential_slam {
namespace ros_adapter {

MapPublisher::MapPublisher(ros::NodeHandle nh, ros::NodeHandle private_nh, std::string map_frame,
                           std::function<MapSnapshot()> source)
    : map_frame_(std::move(map_frame)), source_(std::move(source)) {
  map_pub_ = nh.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  metadata_pub_ = nh.advertise<nav_msgs::MapMetaData>("map_metadata", 1, true);
  // A new ~grid subscriber gets the current map at once (it is not latched; in localization mode
  // the map may never change again).
  auto grid_connected = [this](const ros::SingleSubscriberPublisher&) {
    grid_wanted_ = true;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      update_requested_ = true;
    }
    wake_.notify_one();
  };
  grid_pub_ = private_nh.advertise<EvidentialGrid>("grid", 1, grid_connected);
  for (int l = 0; l < kLayerCount; ++l) {
    // A new subscriber gets the current layer at once (latched from then on).
    auto connected = [this, l](const ros::SingleSubscriberPublisher&) {
      layer_wanted_[l] = true;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        update_requested_ = true;
      }
      wake_.notify_one();
    };
    layer_pubs_[l] = private_nh.advertise<nav_msgs::OccupancyGrid>(
        "layers/" + layerNames()[l], 1, connected, ros::SubscriberStatusCallback(),
        ros::VoidConstPtr(), true);
  }
  thread_ = std::thread([this] { run(); });
}

MapPublisher::~MapPublisher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void MapPublisher::requestUpdate() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    update_requested_ = true;
  }
  wake_.notify_one();
}

void MapPublisher::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || update_requested_; });
    if (stop_) return;
    update_requested_ = false;
    lock.unlock();
    const MapSnapshot snapshot = source_();
    bool layer_request = grid_wanted_;
    for (const auto& wanted : layer_wanted_) layer_request = layer_request || wanted;
    const bool map_changed = snapshot.version != published_version_;
    // The anomaly layer alone is rendered only for its subscribers.
    const bool anomaly_changed =
        snapshot.anomaly_version != published_anomaly_version_ &&
        layer_pubs_[static_cast<int>(Layer::kAnomaly)].getNumSubscribers() > 0;
    if (snapshot.grid && (map_changed || anomaly_changed || layer_request)) {
      publish(snapshot, map_changed, anomaly_changed);
      published_version_ = snapshot.version;
      published_anomaly_version_ = snapshot.anomaly_version;
    }
    lock.lock();
  }
}

void MapPublisher::publish(const MapSnapshot& snapshot, bool map_changed, bool anomaly_changed) {
  const AnomalyGrid anomaly =
      snapshot.anomaly_grid ? *snapshot.anomaly_grid : accumulateAnomaly(snapshot.anomaly.get());
  const LayerRaster raster = extractLayers(*snapshot.grid, 10, &anomaly);
  std_msgs::Header header;
  header.stamp.fromSec(snapshot.stamp);
  header.frame_id = map_frame_;

  if (map_changed) {
    nav_msgs::OccupancyGrid map;
    toTrinaryOccupancyGrid(raster, occupied_thresh_.load(), free_thresh_.load(), header, &map);
    map_pub_.publish(map);
    metadata_pub_.publish(map.info);
  }
  if (grid_wanted_.exchange(false) || (map_changed && grid_pub_.getNumSubscribers() > 0)) {
    EvidentialGrid grid;
    toEvidentialGridMsg(raster, header, &grid);
    grid_pub_.publish(grid);
  }
  for (int l = 0; l < kLayerCount; ++l) {
    const bool wanted = layer_wanted_[l].exchange(false);
    const bool changed = map_changed || (anomaly_changed && l == static_cast<int>(Layer::kAnomaly));
    if (!wanted && !(changed && layer_pubs_[l].getNumSubscribers() > 0)) continue;
    nav_msgs::OccupancyGrid layer;
    toOccupancyGrid(raster, static_cast<Layer>(l),
                    layerRendering(static_cast<Layer>(l), ec_display_max_.load()), header, &layer);
    layer_pubs_[l].publish(layer);
  }
}

}  // namespace ros_adapter
}  // namespace evidential_slam
