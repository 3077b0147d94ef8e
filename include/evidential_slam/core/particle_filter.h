// Rao-Blackwellized particle filter of evidential FastSLAM (paper §3.3, algorithm.md §5):
// odometry proposal refined by scan matching, forward-model weights tempered in the log domain,
// N_eff-selective systematic resampling, maps shared between particles copy-on-write.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/config.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/core/scan_matcher.h"
#include "evidential_slam/core/sensor_model.h"

namespace evidential_slam {

class BeamModel;
class Profiler;
class WorkerPool;
struct TracedScan;

// One node of a particle's path; children share their ancestors' nodes.
struct PathNode {
  Pose2 pose;
  int step = 0;
  std::shared_ptr<const PathNode> parent;
  ~PathNode();  // releases long chains iteratively (no deep recursion)
};

struct Particle {
  Pose2 pose;
  double log_weight = 0.0;             // since the last resampling, normalised so the max is 0
  double cumulative_log_weight = 0.0;  // over the whole history (paper §5: output selection)
  EvidentialGridMap map;
  uint64_t map_id = 0;  // equal ids: identical maps (copies not written since)
  std::shared_ptr<const PathNode> path;
  // What the scans contradicted in this particle's map before each was integrated (anomaly.h).
  std::shared_ptr<const AnomalyNode> anomaly;
};

struct FilterStepInfo {
  bool resampled = false;
  double effective_sample_size = 0.0;
  double best_conflict_added_bits = 0.0;
  ScanConflict best_conflict;  // what the scan did to the best map's conflict
  bool long_step = false;      // a long odometry step (SlamConfig::isLongStep)
};

class ParticleFilter {
 public:
  explicit ParticleFilter(const SlamConfig& config);
  ~ParticleFilter();

  // First scan: every particle starts at `pose` and integrates the scan.
  FilterStepInfo initialize(const Pose2& pose, const LaserScan& scan, int step);
  // Places every particle at `pose` on `map` (all of them sharing its tiles, copied only when
  // written) without a scan: the next update() moves them from there. `map` must have the
  // configured resolution (SlamEngine::startFromMap checks it).
  void startOnMap(const EvidentialGridMap& map, const Pose2& pose);
  // Later scans: sample from the motion model for the odometry increment, refine, weight,
  // integrate, resample if needed.
  FilterStepInfo update(const Pose2& odometry_increment, const LaserScan& scan, int step);

  // Replaces the parameters that may change while running (sensor model, motion model, matcher,
  // weighting, resampling, merging). The particle count, resolution, seed and threads stay as
  // constructed: they shape the particles and maps that exist.
  void reconfigure(const SlamConfig& config);
  const SlamConfig& config() const { return config_; }
  // With map updates off, scans still move, refine and weigh the particles (and resampling runs),
  // against their maps as they are; no map is written. The weights are the ones an update would
  // give: those read the map before the scan either way.
  void setMapUpdates(bool enabled) { map_updates_ = enabled; }
  bool mapUpdates() const { return map_updates_; }

  const std::vector<Particle>& particles() const { return particles_; }
  size_t bestIndex() const;
  const Particle& best() const { return particles_[bestIndex()]; }
  // Bytes held by distinct map tiles over all particles.
  size_t mapMemoryBytes() const;
  // Distinct hypotheses (map, pose) whose scan was integrated at the last update.
  size_t lastUpdateGroups() const { return last_groups_; }
  // Hypotheses whose wide-basin match ran its multi-start search at the last update (0 when the
  // search is off or every hypothesis was explained from its prediction).
  size_t lastWideMatches() const { return last_wide_matches_; }

  // Systematic (low-variance) resampling of normalised weights; returns the chosen parent of
  // each new particle. Exposed for tests.
  static std::vector<size_t> systematicResample(const std::vector<double>& weights, double u0);
  // The beams of `scan` that BeamModel::traceScan makes hits, every `stride`-th of them, as a scan
  // of their own: its traced log plausibility (stride 1) equals the whole scan's at `stride`
  // without tracing the other beams. Exposed for tests.
  static LaserScan hitBeamSubset(const LaserScan& scan, const SensorModelConfig& sensor,
                                 int stride);

 private:
  struct Workspace;
  struct ScanModels;
  void resampleIfNeeded(FilterStepInfo* info);
  // The profiler's floor replay (profile.h) of every group's beams at this update.
  void replayFloor(Profiler* profiler, const BeamModel& beam_model, const LaserScan& scan,
                   const std::vector<Pose2>& proposed, const std::vector<size_t>& leaders);
  // Wide-basin match (matcher.heading_window > 0), in three parts. nominalMatch: ICP from the
  // odometry prediction on a hypothesis's map, the forward model's log plausibility there (the
  // beams of `hits`), and whether that settles it (it explains the scan, or nothing matched from
  // the prediction, which then stands).
  struct NominalMatch {
    Pose2 pose;
    double log_plausibility = 0.0;
    bool settled = false;
    ScanMatcher::Match icp;  // the ICP from the prediction (the wide search's unturned start)
  };
  NominalMatch nominalMatch(const EvidentialGridMap& map, const Pose2& predicted,
                            const std::vector<MatchPoint>& endpoints, const LaserScan& hits,
                            const ScanModels& models, const ScanMatcher& matcher) const;
  // Σ log pl of the beams of `hits` (hitBeamSubset) from `pose` on `map`.
  double wideLogPlausibility(const EvidentialGridMap& map, const Pose2& pose, const LaserScan& hits,
                             const ScanModels& models) const;
  // wideCandidates: ICP from the prediction turned by up to ±heading_window (the best score
  // of those starts) and from no and from reversed translation, with their prior (nats).
  struct WideCandidate {
    Pose2 pose;
    double prior_nats = 0.0;
  };
  std::vector<WideCandidate> wideCandidates(const EvidentialGridMap& map, const Pose2& previous,
                                            const Pose2& increment,
                                            const std::vector<MatchPoint>& endpoints,
                                            const ScanMatcher& matcher,
                                            const NominalMatch& nominal) const;
  // chooseCandidate: the nominal pose or a candidate, by log plausibility on `map` (the beams of
  // `hits`) minus T · prior.
  Pose2 chooseCandidate(const EvidentialGridMap& map, const NominalMatch& nominal,
                        const std::vector<WideCandidate>& candidates, const LaserScan& hits,
                        const ScanModels& models) const;

  SlamConfig config_;
  std::vector<Particle> particles_;
  // Sensor and matcher models per declared range noise (a log has one or a few lasers) and step
  // length.
  const ScanModels& modelsFor(const LaserScan& scan, bool long_step);
  struct CachedModels {
    float range_sigma;
    bool long_step;
    std::unique_ptr<ScanModels> models;
  };
  std::vector<CachedModels> models_;
  std::unique_ptr<WorkerPool> pool_;
  std::vector<std::unique_ptr<Workspace>> workspaces_;  // one per worker thread
  uint64_t resample_counter_ = 0;
  uint64_t next_map_id_ = 1;
  size_t last_groups_ = 0;  // distinct (map, pose) hypotheses integrated at the last update
  size_t last_wide_matches_ = 0;
  bool map_updates_ = true;
};

}  // namespace evidential_slam
