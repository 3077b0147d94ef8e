// The one SLAM entry point. The offline rawlog runner and the ROS nodelet both feed it
// (odometry pose, scan) pairs through processScan(); everything else is read back from it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/particle_filter.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {

struct SlamStats {
  uint64_t scans_received = 0;   // scans given to processScan
  uint64_t scans_processed = 0;  // scans that passed the motion gate and were integrated
  uint64_t scans_rejected = 0;   // scans refused (inconsistent sizes, no usable ray)
  uint64_t rays_total = 0;       // rays of processed scans
  uint64_t rays_bad = 0;         // NaN / inf / negative ranges, skipped
  uint64_t rays_no_return = 0;   // rays flagged as no return
  uint64_t resamplings = 0;
  uint64_t long_steps = 0;  // processed scans after a long step (SlamConfig::isLongStep)
  // Groups of particles weighed and updated, summed over the updates
  // (ParticleFilter::lastUpdateGroups).
  uint64_t group_updates = 0;
};

// The particle set at the latest scan, summarised: weighted mean and covariance of (x, y, θ)
// (θ's mean is circular; its deviations are wrapped around the mean).
struct PoseEstimate {
  Pose2 mean;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// What one call of processScan did.
struct ScanUpdate {
  bool processed = false;  // passed the motion gate and updated the particles
  bool rejected = false;   // the scan was unusable; `why` says why
  std::string why;
  Pose2 best_pose;                         // best particle's pose at this scan (map frame)
  double external_conflict_added = 0.0;    // sum of EC (bits) this scan added to the best map
  double conflict_mass_added = 0.0;        // sum of m(∅) it added there
  double open_space_conflict_added = 0.0;  // ... of which in the map's open space
  double contradiction_added = 0.0;        // what it contradicted (ΣK, anomaly.h): alarm input
};

class SlamEngine {
 public:
  explicit SlamEngine(const SlamConfig& config);
  ~SlamEngine();

  // `odometry` is the robot's odometry pose (odom frame) at the scan's time: absolute, not an
  // increment. Scans arriving before the robot moved far enough since the last processed scan
  // only advance the odometry (motion gate).
  ScanUpdate processScan(const Pose2& odometry, const LaserScan& scan);

  // Drops all particles, maps and the trajectory (e.g. when time jumps backwards) and starts
  // over: on the map startFromMap gave, if any (as it gave it), else on an empty map.
  void reset();

  // Starts over on `map` (e.g. read from a map file): every particle gets the map, all sharing
  // its tiles (a tile is copied only when a particle writes it), and the map pose `pose`. The
  // next processed scan's odometry pose is taken to be at `pose`; with `odometry` (the odometry
  // pose the robot had at `pose`, in the odom frame of the scans to come, e.g. when continuing a
  // log) the robot is at pose ⊕ (odometry⁻¹ ⊕ its odometry) instead. From that scan on, mapping
  // continues as usual (the scan is matched and integrated like any later one). The engine keeps
  // `map` for reset(). False (and `why`) when the map's resolution is not the configured one or a
  // pose is not finite; nothing changes then.
  bool startFromMap(const EvidentialGridMap& map, const Pose2& pose, std::string* why,
                    const Pose2* odometry = nullptr);
  // Forgets the map startFromMap gave (and the memory it holds): the next reset() starts on an
  // empty map. The particles are not touched.
  void clearStartMap() { start_.reset(); }
  bool hasStartMap() const { return start_ != nullptr; }
  // Before the first processed scan: the map pose of the robot at odometry pose `odometry`.
  Pose2 poseBeforeFirstScan(const Pose2& odometry) const;

  // Pauses or resumes mapping. While paused, every scan is processed as usual (motion gate,
  // proposal, scan matching, weights, resampling: the particles localize on their maps) but no
  // particle's map is changed (ParticleFilter::setMapUpdates). Kept across reset().
  void setMappingPaused(bool paused);
  bool mappingPaused() const { return mapping_paused_; }

  // Applies new parameters while running (dynamic_reconfigure). Everything but the start-up
  // parameters (particles, resolution, seed, threads, which keep their constructed values) takes
  // effect at the next scan; the particles and maps are kept. False (and `why`) when `config` is
  // invalid; nothing changes then.
  bool reconfigure(const SlamConfig& config, std::string* why);

  const SlamConfig& config() const { return config_; }
  const SlamStats& stats() const { return stats_; }
  const ParticleFilter& filter() const { return *filter_; }

  // Best particle (highest cumulative weight) and what it carries.
  const EvidentialGridMap& bestMap() const;
  // What the scans contradicted in the best particle's map, each before it was integrated
  // (anomaly.h); empty before the first processed scan.
  AnomalyGrid bestAnomaly() const;
  // The same as the best particle's lineage (cheap to copy; accumulateAnomaly sums it).
  std::shared_ptr<const AnomalyNode> bestAnomalyLineage() const;
  Pose2 bestPose() const;
  // The best particle's path, one pose per scan received (poses between processed scans are the
  // particle's pose at the last processed scan composed with the odometry since then).
  std::vector<StampedPose> bestTrajectory() const;
  // Every particle's pose at the latest scan (its pose at the last processed scan composed with
  // the odometry since), and its normalised weight (they sum to 1).
  void particlePoses(std::vector<Pose2>* poses, std::vector<double>* weights) const;
  PoseEstimate poseEstimate() const;
  // map -> odom correction for the latest scan (REP-105): map_T_odom = best ⊕ odometry⁻¹.
  Pose2 mapToOdom() const;
  // The odometry pose of the latest scan given to processScan (what bestPose() is at): a map file
  // saves it beside bestPose() for a run that continues the same odometry frame.
  const Pose2& lastOdometry() const { return last_odometry_; }

 private:
  SlamConfig config_;
  SlamStats stats_;
  std::unique_ptr<ParticleFilter> filter_;
  bool have_last_processed_ = false;
  Pose2 last_processed_odometry_;
  Pose2 last_odometry_;
  // Per scan received: its stamp, the index of the processed step it hangs off and its odometry.
  struct ScanRecord {
    double stamp;
    int step;
    Pose2 odometry;
  };
  std::vector<ScanRecord> scan_records_;
  std::vector<Pose2> step_odometry_;  // odometry at each processed step
  std::vector<double> step_stamps_;   // stamp of each processed step's scan
  // What startFromMap gave.
  struct MapStart {
    EvidentialGridMap map;
    Pose2 pose;
    bool anchored = false;  // `odometry` is the odometry pose at `pose`
    Pose2 odometry;
  };
  std::unique_ptr<const MapStart> start_;
  bool mapping_paused_ = false;
};

}  // namespace evidential_slam
