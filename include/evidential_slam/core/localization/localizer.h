// Monte Carlo localization on a fixed evidential map (mode localization): particles carry a pose
// (and the share of their last move a failed odometry explains); each update samples the
// odometry's drift (odom_drift_*, a random walk: sampleDrift), mixed with samples around the
// scan-matched pose where the scan fits better there than at the odometry's prediction (Mixture
// MCL, mixture_proposal.h: odom_failure_*, scan_proposal_fraction; after a uniformly spread global
// localization, until the cloud has narrowed to the scan matcher's search radius, each sample is
// instead scan-matched), weighs the samples on at most laser_max_beams hit beams by
// laser_model_type's model: beam (the evidential forward model on a BeamLookup built once per map,
// tempered like the SLAM's weights), beam_traced (the same model ray traced, BeamModel) or
// likelihood_field (LikelihoodField, computed once per map; amcl's weight 1 + Σ p^3), and never
// writes the map. Every resample_interval updates (with selective_resampling, only when the
// effective sample size has dropped below half) the particles are resampled with KLD-sampling,
// which adapts their number to the spread of the cloud between min_particles and max_particles;
// with recovery_alpha_slow/_fast, random poses from the map's free space are added when the scans'
// plausibility drops (augmented MCL, as amcl). The pose estimate is the mean and covariance of the
// heaviest cluster of particles, its mean refined by one scan match (scan_matching). The anomaly of
// every processed scan at the estimate is accumulated against the map (anomaly.h): what changed
// since the map was made. The scan's log plausibility under the predicted cloud feeds the kidnap
// alarm (plausibility_alarm.h); when it fires (the scans far less plausible at every likely
// particle than while the filter tracked), kidnap_recovery draws the particles again, as a global
// localization. What the anomaly contradicts feeds the conflict alarm, reported only. With
// global_search (the default) both draw the particles around the poses where the scan fits best on
// the whole map (GlobalSearch, a correlative branch and bound) instead of uniformly: a uniform
// cloud rarely puts a sample in the scan matcher's basin around the truth.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/config.h"
#include "evidential_slam/core/conflict_alarm.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/laser_scan.h"
#include "evidential_slam/core/localization/localization_config.h"
#include "evidential_slam/core/localization/plausibility_alarm.h"
#include "evidential_slam/core/pose2.h"
#include "evidential_slam/core/slam_engine.h"

namespace evidential_slam {

class BeamLookup;
class GlobalSearch;
class LikelihoodField;
class Rng;
class WorkerPool;

struct LocalizationParticle {
  Pose2 pose;
  double weight = 0.0;  // normalised: the particles' weights sum to 1
  // The odometry failure's share of its last move (the mixture proposal's responsibility): a
  // failure persists (odom_failure_persistence).
  double odometry_failed = 0.0;
};

// What one call of processScan did.
struct LocalizationUpdate {
  bool processed = false;  // passed the motion gate: the particles moved and were weighed
  bool rejected = false;   // unusable scan or odometry, or no particles yet; `why` says why
  std::string why;
  bool resampled = false;
  size_t particles = 0;                // after this scan
  double mean_log_plausibility = 0.0;  // per weighed beam, over the particles (processed scans)
  // The scan's log plausibility under the predicted cloud, per weighed beam: (1 / beams) log Σ w
  // Pl(scan | particle), the particles' weights before this scan (the kidnap alarm's input).
  double log_evidence = 0.0;
  double effective_particles = 0.0;  // N_eff = 1 / Σ w² after the weighing (processed scans)
  double short_rate = 0.0;           // beam: the short readings' rate used for this scan
  size_t random_particles = 0;       // drawn from free space by the recovery at this scan
  size_t scan_samples = 0;           // drawn around the scan-matched pose by the mixture proposal
  double failure_share = 0.0;        // the odometry failure's share of the weight at this update
  double anomaly_added_bits = 0.0;   // the anomaly this scan added at the estimate
  double contradiction = 0.0;        // its Σ K (contradictionOf): the conflict alarm's input
  ConflictAlarmState alarm;          // the alarm's verdict (processed scans, not while searching)
  PlausibilityAlarmState kidnap_alarm;  // the plausibility alarm's (likewise)
  // kidnap_recovery drew the particles again after the kidnap alarm rose
  bool respread = false;
};

struct LocalizerStats {
  uint64_t scans_received = 0;
  uint64_t scans_processed = 0;
  uint64_t scans_rejected = 0;
  uint64_t resamplings = 0;
  uint64_t particle_updates = 0;  // Σ over processed scans of the particles updated
  uint64_t scan_matches = 0;      // scan matches of the estimate (one per processed scan at most)
  size_t max_particles_used = 0;
  size_t min_particles_used = 0;  // over the processed scans (0 before the first)
  size_t lookup_bytes = 0;        // the beam model's lookup (laser_model_type beam), once built
  double lookup_build_s = 0.0;    // its build time (process CPU s)
  uint64_t anomaly_traces = 0;    // updates whose scan was traced for the anomaly
  uint64_t recoveries = 0;        // kidnap_recovery's spreads over the free space
  uint64_t global_searches = 0;   // correlative searches of a scan over the map (global_search)
  double global_search_s = 0.0;   // their process CPU time, score grids' build included
  uint64_t scan_proposals = 0;    // updates whose samples were partly drawn from the scan
  uint64_t proposal_matches = 0;  // updates at which the mixture proposal matched the scan
};

class Localizer {
 public:
  // `slam` gives the sensor and matcher models, the motion noise floors, the likelihood
  // temperature, the seed and the threads (its particle count and resolution are not used: the map
  // has its own); `alarm` the conflict alarm (reported in each update). Throws
  // std::invalid_argument for an invalid configuration (check isValid first).
  Localizer(const LocalizationConfig& config, const SlamConfig& slam,
            const ConflictAlarmConfig& alarm = ConflictAlarmConfig());
  ~Localizer();
  Localizer(const Localizer&) = delete;
  Localizer& operator=(const Localizer&) = delete;

  // The map to localize on (its tiles shared, never written). Drops the particles, the trajectory
  // and the anomaly; false (and `why`) for a map without an observed cell.
  bool setMap(const EvidentialGridMap& map, std::string* why);
  const EvidentialGridMap& map() const { return map_; }

  // Draws particles from N(pose, covariance) (x, y, θ), as many as KLD-sampling asks for their
  // spread. The next scan is weighed where they are, without motion. The trajectory and the
  // anomaly go on. False (and `why`) without
  // a map, for a non-finite pose or a covariance that is not symmetric positive semi-definite.
  bool resetAt(const Pose2& pose, const Eigen::Matrix3d& covariance, std::string* why);
  // resetAt with the configured initial_cov_xx, _yy, _aa.
  bool resetAt(const Pose2& pose, std::string* why);
  // Spreads max_particles uniformly over the map's free space (observed cells with BetP(o) <
  // kFreeSpaceBetP and NS < kFreeSpaceNS) with uniform headings; with global_search, the next
  // scan is then searched for over that free space and the particles are drawn around where it
  // fits best before it is weighed. False (and `why`) when the map has no free space.
  bool globalLocalization(std::string* why);
  static constexpr double kFreeSpaceBetP = 0.25;
  static constexpr double kFreeSpaceNS = 0.5;

  // `odometry`: the robot's odometry pose (odom frame) at the scan's stamp. Updates once the
  // robot moved update_min_d or turned update_min_a since the last update (or at the first scan
  // after a reset).
  LocalizationUpdate processScan(const Pose2& odometry, const LaserScan& scan);

  // New run-time parameters (the seed and threads of `slam` keep their values); the particles
  // are kept. False (and `why`) when invalid; nothing changes then.
  bool reconfigure(const LocalizationConfig& config, const SlamConfig& slam, std::string* why);
  // The conflict alarm's new parameters (its baseline is kept).
  void setAlarmConfig(const ConflictAlarmConfig& alarm) { alarm_.setConfig(alarm); }

  bool initialized() const { return !particles_.empty(); }
  const std::vector<LocalizationParticle>& particles() const { return particles_; }
  // Mean and covariance of the heaviest cluster (particles in adjacent KLD bins) at the last
  // update, the mean refined by the scan match, moved by the odometry since.
  PoseEstimate estimate() const;
  // map -> odom for the latest scan (REP-105): estimate ⊕ odometry⁻¹.
  Pose2 mapToOdom() const;
  // The estimate's path: one pose per scan given to processScan.
  const std::vector<StampedPose>& trajectory() const { return trajectory_; }
  const AnomalyGrid& anomaly() const { return anomaly_; }
  const LocalizerStats& stats() const { return stats_; }
  const LocalizationConfig& config() const { return config_; }
  const SlamConfig& slamConfig() const { return slam_; }

 private:
  struct Models;
  const Models& modelsFor(const LaserScan& scan);
  // Draws particles one by one from `draw` until KLD-sampling has enough (at most `max`).
  template <typename Draw>
  void drawKld(size_t max, Draw&& draw);
  void resample(LocalizationUpdate* update);
  void computeEstimate();
  // The standard deviation of the particles' positions along the cloud's widest axis (m).
  double cloudSpread() const;
  void buildFreeCells();
  Pose2 randomFreePose(Rng* rng) const;
  // The pose's cell is observed, not believed occupied (BetP(o) < 1/2) and NS < kFreeSpaceNS.
  bool onMappedFloor(const Pose2& pose) const;
  // Forgets the odometry and the recovery's averages: the next scan is weighed where the
  // particles are.
  void restartFilter();
  // Forgets the conflict alarm's, the kidnap alarm's and the prediction gate's baselines.
  void resetAlarms();
  // max_particles poses drawn uniformly from the free space (buildFreeCells first; not empty).
  void spreadOverFreeSpace();
  // max_particles poses drawn around the best hypotheses of a GlobalSearch of `scan`'s hit beams
  // (buildFreeCells first; not empty), a Gaussian each; false (nothing changes) when the scan
  // has no hit beam to search with.
  bool seedFromSearch(const LaserScan& scan, const Models& models);

  LocalizationConfig config_;
  SlamConfig slam_;
  EvidentialGridMap map_;
  std::vector<CellIndex> free_cells_;  // built for the first global localization or recovery
  bool free_cells_built_ = false;
  std::vector<LocalizationParticle> particles_;
  std::vector<std::unique_ptr<Models>> models_;
  std::unique_ptr<LikelihoodField> field_;         // built at the first likelihood_field update
  std::unique_ptr<BeamLookup> lookup_;             // built at the first beam update
  std::unique_ptr<BelievedFreeTiles> free_tiles_;  // for the anomaly, built at the first update
  std::unique_ptr<GlobalSearch> search_;  // built at the first search (per end uncertainty)
  // globalLocalization with global_search: the next scan is searched for before it is weighed.
  bool search_pending_ = false;
  // The rate of short readings (unexpected obstacles) at the estimate, a running mean over
  // updates: the beam model's plausibility of a short reading.
  double short_rate_ = 0.0;
  std::unique_ptr<WorkerPool> pool_;
  struct Workspace;
  std::vector<std::unique_ptr<Workspace>> workspaces_;
  bool have_odometry_ = false;  // an update happened since the last reset
  // A global localization whose cloud is still wider than the matcher's search radius: each
  // sample is matched.
  bool searching_ = false;
  // The searching cloud was drawn around a GlobalSearch's hypotheses (not matched per sample).
  bool seeded_ = false;
  bool force_update_ = false;
  Pose2 last_update_odometry_;
  Pose2 last_odometry_;
  PoseEstimate estimate_;  // at the last update (or reset)
  int updates_since_resample_ = 0;
  uint64_t step_ = 0;  // random streams: one per update and particle
  uint64_t draws_ = 0;
  double w_slow_ = 0.0, w_fast_ = 0.0;
  // Where the last update's mixture proposal matched the scan (none after a reset).
  std::optional<Pose2> last_match_;
  AnomalyGrid anomaly_;
  // Fed with what each scan at the estimate contradicts in the map while the filter tracks;
  // reported (LocalizationUpdate::alarm), not acted on: a changed world contradicts the map too.
  ConflictAlarm alarm_;
  // Fed with each tracking update's log evidence (kidnap_alarm_*): a kidnap or a lost filter makes
  // the scans less plausible at the particles than while the filter tracked.
  PlausibilityAlarm kidnap_alarm_;
  // The mixture proposal's gate: the plausibility per beam at the odometry's prediction of the
  // estimate, against its own recent updates (an envelope, one update); only a prediction below
  // them is checked by the two scan matches.
  PlausibilityAlarm prediction_gate_{1.0, 1};
  double last_kidnap_ratio_ = 0.0;  // the kidnap alarm's ratio at the last update
  std::vector<StampedPose> trajectory_;
  LocalizerStats stats_;
};

}  // namespace evidential_slam
