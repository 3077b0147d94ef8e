#include "evidential_slam/core/localization/localizer.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "evidential_slam/core/localization/beam_lookup.h"
#include "evidential_slam/core/localization/global_search.h"
#include "evidential_slam/core/localization/kld_sampling.h"
#include "evidential_slam/core/localization/likelihood_field.h"
#include "evidential_slam/core/localization/mixture_proposal.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/core/motion_model.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/particle_filter.h"
#include "evidential_slam/core/scan_matcher.h"
#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/core/worker_pool.h"

namespace evidential_slam {
namespace {

bool refuse(std::string* why, const std::string& what) {
  if (why != nullptr) *why = what;
  return false;
}

bool finite(const Pose2& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}

// Random streams of the localizer (Rng::forStream's first index), apart from the updates' (the
// update count).
constexpr uint64_t kDrawStream = 0x4C4F43414C495A45ull;
// The mixture proposal's draws (plus the update count), apart from both.
constexpr uint64_t kMixtureStream = 0x4D49585455524521ull;
// The short readings' rate is a running mean with this weight on the newest update (about the
// last ten updates: a crowd that comes or goes is followed within a few metres).
constexpr double kShortRateWeight = 0.1;
// Particles per hypothesis of a global search: the max_particles / 10 best regions are kept, each
// a particle on its refined pose and nine drawn around it (docs/decisions.md).
constexpr int kParticlesPerHypothesis = 10;
}  // namespace

// The models for one declared range noise (as the SLAM's, without its long-step settings).
struct Localizer::Models {
  Models(const SlamConfig& slam, float range_sigma, double resolution)
      : sigma(range_sigma),
        sensor(slam.sensor.forSensorNoise(range_sigma, resolution)),
        beam(sensor, resolution),
        matcher(
            slam.matcher.forSensorNoise(range_sigma, beam.inverseMass(0.0).occupied, resolution),
            sensor, resolution) {}
  float sigma;
  SensorModelConfig sensor;
  BeamModel beam;
  ScanMatcher matcher;
};

struct Localizer::Workspace {
  ScanAccumulator accumulator;
};

Localizer::Localizer(const LocalizationConfig& config, const SlamConfig& slam,
                     const ConflictAlarmConfig& alarm)
    : config_(config),
      slam_(slam),
      alarm_(alarm),
      kidnap_alarm_(config.kidnap_alarm_factor, config.kidnap_alarm_updates) {
  std::string why;
  if (!config_.isValid(&why) || !slam_.isValid(&why)) {
    throw std::invalid_argument("invalid localization configuration: " + why);
  }
  pool_ = std::make_unique<WorkerPool>(slam_.threads);
  for (int i = 0; i < pool_->size(); ++i) workspaces_.push_back(std::make_unique<Workspace>());
}

Localizer::~Localizer() = default;

bool Localizer::setMap(const EvidentialGridMap& map, std::string* why) {
  if (map.observedBox().empty()) return refuse(why, "the map has no observed cell");
  map_ = map;
  models_.clear();
  free_cells_.clear();
  free_cells_built_ = false;
  field_.reset();
  lookup_.reset();
  free_tiles_.reset();
  search_.reset();
  search_pending_ = false;
  short_rate_ = 0.0;
  particles_.clear();
  anomaly_.clear();
  resetAlarms();
  trajectory_.clear();
  stats_ = LocalizerStats{};
  restartFilter();
  return true;
}

void Localizer::restartFilter() {
  searching_ = false;
  search_pending_ = false;
  have_odometry_ = false;
  force_update_ = true;
  updates_since_resample_ = 0;
  w_slow_ = w_fast_ = 0.0;
  last_match_.reset();
  last_kidnap_ratio_ = 0.0;
}

void Localizer::resetAlarms() {
  alarm_.reset();
  kidnap_alarm_.reset();
  prediction_gate_.reset();
}

bool Localizer::reconfigure(const LocalizationConfig& config, const SlamConfig& slam,
                            std::string* why) {
  SlamConfig next = slam;
  next.seed = slam_.seed;
  next.threads = slam_.threads;
  if (!config.isValid(why) || !next.isValid(why)) return false;
  if (config.laser_likelihood_max_dist != config_.laser_likelihood_max_dist) field_.reset();
  config_ = config;
  slam_ = next;
  models_.clear();
  kidnap_alarm_.configure(config_.kidnap_alarm_factor, config_.kidnap_alarm_updates);
  return true;
}

const Localizer::Models& Localizer::modelsFor(const LaserScan& scan) {
  const float sigma =
      std::isfinite(scan.range_sigma) && scan.range_sigma > 0.0f ? scan.range_sigma : 0.0f;
  for (const auto& m : models_) {
    if (m->sigma == sigma) return *m;
  }
  models_.push_back(std::make_unique<Models>(slam_, sigma, map_.resolution()));
  return *models_.back();
}

template <typename Draw>
void Localizer::drawKld(size_t max, Draw&& draw) {
  const size_t min = std::min(max, static_cast<size_t>(config_.min_particles));
  KldBins bins(config_.kld_bin_xy, config_.kld_bin_angle);
  size_t limit = min;
  std::vector<LocalizationParticle> next;
  while (next.size() < std::max(limit, size_t{1})) {
    // `draw` gives a pose, or a particle (its odometry failure carried through a resampling).
    LocalizationParticle drawn;
    auto d = draw();
    if constexpr (std::is_same_v<decltype(d), LocalizationParticle>) {
      drawn = d;
    } else {
      drawn.pose = d;
    }
    next.push_back(drawn);
    const Pose2& pose = drawn.pose;
    if (bins.insert(pose)) {
      limit = std::min(max, kldSampleLimit(bins.count(), config_.kld_err, config_.kld_z, min, max));
    }
  }
  const double w = 1.0 / static_cast<double>(next.size());
  for (LocalizationParticle& p : next) p.weight = w;
  particles_ = std::move(next);
}

bool Localizer::resetAt(const Pose2& pose, std::string* why) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << config_.initial_cov_xx, config_.initial_cov_yy, config_.initial_cov_aa;
  return resetAt(pose, cov, why);
}

bool Localizer::resetAt(const Pose2& pose, const Eigen::Matrix3d& covariance, std::string* why) {
  if (map_.observedBox().empty()) return refuse(why, "no map to localize on");
  if (!finite(pose) || !covariance.allFinite()) return refuse(why, "the pose is not finite");
  if (!covariance.isApprox(covariance.transpose(), 1e-9)) {
    return refuse(why, "the covariance is not symmetric");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance);
  const Eigen::Vector3d values = eig.eigenvalues();
  if (values.minCoeff() < -1e-9 * std::max(1.0, values.maxCoeff())) {
    return refuse(why, "the covariance is not positive semi-definite");
  }
  const Eigen::Matrix3d root = eig.eigenvectors() * values.cwiseMax(0.0).cwiseSqrt().asDiagonal();
  restartFilter();
  resetAlarms();  // a new start: the scans before it (perhaps lost) are no baseline
  Rng rng = Rng::forStream(slam_.seed, kDrawStream, draws_++);
  drawKld(static_cast<size_t>(config_.max_particles), [&] {
    const Eigen::Vector3d d =
        root * Eigen::Vector3d(rng.gaussian(), rng.gaussian(), rng.gaussian());
    return Pose2(pose.x + d.x(), pose.y + d.y(), pose.theta + d.z());
  });
  computeEstimate();
  return true;
}

void Localizer::buildFreeCells() {
  if (free_cells_built_) return;
  map_.forEachTile([&](int tx, int ty, const EvidentialGridMap::Tile& tile) {
    for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) {
      const Cell& c = tile.cells[static_cast<size_t>(k)];
      if (!c.observed() || pignistic(c) >= kFreeSpaceBetP || nonSpecificity(c) >= kFreeSpaceNS) {
        continue;
      }
      // Negative tiles: multiply, do not shift left (a left shift of a negative value is UB).
      free_cells_.push_back(
          CellIndex{tx * EvidentialGridMap::kTileSize + (k & (EvidentialGridMap::kTileSize - 1)),
                    ty * EvidentialGridMap::kTileSize + (k >> EvidentialGridMap::kTileBits)});
    }
  });
  free_cells_built_ = true;
}

bool Localizer::globalLocalization(std::string* why) {
  if (map_.observedBox().empty()) return refuse(why, "no map to localize on");
  buildFreeCells();
  if (free_cells_.empty()) return refuse(why, "the map has no free space to spread particles on");
  resetAlarms();
  spreadOverFreeSpace();
  search_pending_ = config_.global_search;
  return true;
}

bool Localizer::seedFromSearch(const LaserScan& scan, const Models& models) {
  // The beams searched: the weighed ones (at most laser_max_beams hits, evenly spread), their
  // endpoints in the robot frame.
  const LaserScan all_hits = ParticleFilter::hitBeamSubset(scan, models.sensor, 1);
  const int stride =
      std::max<int>(1, static_cast<int>(std::ceil(static_cast<double>(all_hits.ranges.size()) /
                                                  config_.laser_max_beams)));
  const LaserScan hits = ParticleFilter::hitBeamSubset(scan, models.sensor, stride);
  std::vector<Eigen::Vector2d> points;
  double range_sum = 0.0;
  for (size_t i = 0; i < hits.ranges.size(); ++i) {
    const double r = hits.ranges[i], b = hits.bearings[i];
    const Pose2 end = scan.sensor_pose.compose(Pose2(r * std::cos(b), r * std::sin(b), 0.0));
    points.emplace_back(end.x, end.y);
    range_sum += points.back().norm();
  }
  if (points.empty()) return false;
  const std::clock_t t0 = std::clock();
  // A beam's end is uncertain by the forward model's σ_f (the range noise and the cell) and by
  // the map's cell: the field's σ.
  const double sigma = std::max(models.sensor.forward_sigma, map_.resolution());
  if (!search_ || search_->sigma() != sigma) {
    search_ = std::make_unique<GlobalSearch>(map_, sigma, free_cells_);
  }
  GlobalSearch::Options options;
  options.count = static_cast<size_t>(std::max(1, config_.max_particles / kParticlesPerHypothesis));
  options.region_xy = config_.kld_bin_xy;
  options.region_angle = config_.kld_bin_angle;
  const std::vector<PoseHypothesis> found = search_->search(points, options);
  // Each hypothesis refined by the scan matcher (sub-cell, between the heading steps).
  std::vector<Pose2> refined(found.size());
  const std::vector<MatchPoint> endpoints =
      slam_.matcher.enabled ? models.matcher.endpoints(scan) : std::vector<MatchPoint>();
  pool_->run(found.size(), [&](size_t k, int) {
    refined[k] =
        endpoints.empty() ? found[k].pose : models.matcher.refine(map_, found[k].pose, endpoints);
  });
  stats_.global_search_s += static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
  ++stats_.global_searches;
  if (found.empty()) return false;
  // A particle on each refined hypothesis, the others drawn around them: within σ in position and
  // σ / (mean range) in heading, where the scan placed the hypothesis before the refinement.
  const double sigma_theta = sigma / std::max(range_sum / points.size(), map_.resolution());
  restartFilter();
  Rng rng = Rng::forStream(slam_.seed, kDrawStream, draws_++);
  const size_t n = static_cast<size_t>(config_.max_particles);
  particles_.assign(n, LocalizationParticle{Pose2(), 1.0 / static_cast<double>(n)});
  for (size_t i = 0; i < n; ++i) {
    const Pose2& h = refined[i % refined.size()];
    particles_[i].pose = i < refined.size()
                             ? h
                             : Pose2(h.x + sigma * rng.gaussian(), h.y + sigma * rng.gaussian(),
                                     normalizeAngle(h.theta + sigma_theta * rng.gaussian()));
  }
  computeEstimate();
  searching_ = true;
  seeded_ = true;
  return true;
}

void Localizer::spreadOverFreeSpace() {
  restartFilter();
  Rng rng = Rng::forStream(slam_.seed, kDrawStream, draws_++);
  const size_t n = static_cast<size_t>(config_.max_particles);
  particles_.assign(n, LocalizationParticle{Pose2(), 1.0 / static_cast<double>(n)});
  for (LocalizationParticle& p : particles_) p.pose = randomFreePose(&rng);
  computeEstimate();
  searching_ = true;
  seeded_ = false;
}

bool Localizer::onMappedFloor(const Pose2& pose) const {
  const Cell& c = map_.cell(map_.worldToCell(pose.x, pose.y));
  return c.observed() && pignistic(c) < 0.5 && nonSpecificity(c) < kFreeSpaceNS;
}

Pose2 Localizer::randomFreePose(Rng* rng) const {
  const size_t i =
      std::min(free_cells_.size() - 1, static_cast<size_t>(rng->uniform() * free_cells_.size()));
  const double res = map_.resolution();
  return Pose2((free_cells_[i].x + rng->uniform()) * res, (free_cells_[i].y + rng->uniform()) * res,
               (2.0 * rng->uniform() - 1.0) * M_PI);
}

LocalizationUpdate Localizer::processScan(const Pose2& odometry, const LaserScan& scan) {
  LocalizationUpdate out;
  ++stats_.scans_received;
  out.particles = particles_.size();
  std::string why;
  if (!scan.isConsistent(&why) || !finite(odometry)) {
    ++stats_.scans_rejected;
    out.rejected = true;
    out.why = why.empty() ? "the odometry pose is not finite" : why;
    return out;
  }
  if (particles_.empty()) {
    ++stats_.scans_rejected;
    out.rejected = true;
    out.why = "no particles: give an initial pose or start a global localization";
    return out;
  }
  if (!have_odometry_) {
    last_update_odometry_ = odometry;
    have_odometry_ = true;
  }
  last_odometry_ = odometry;
  const Pose2 increment = last_update_odometry_.between(odometry);
  const bool moved = std::hypot(increment.x, increment.y) >= config_.update_min_d ||
                     std::abs(increment.theta) >= config_.update_min_a;
  if (!moved && !force_update_) {
    trajectory_.push_back(StampedPose{scan.stamp, estimate_.mean.compose(increment)});
    return out;
  }
  force_update_ = false;
  last_update_odometry_ = odometry;
  const uint64_t step = ++step_;

  const Models& models = modelsFor(scan);
  // A global localization's first scan: the particles are drawn where it fits best on the map.
  if (search_pending_) {
    search_pending_ = false;
    if (seedFromSearch(scan, models)) {
      force_update_ = false;
      have_odometry_ = true;
    }
  }
  // The weighed beams: at most laser_max_beams of the hits, evenly spread. The beam model's log
  // plausibility is scaled up to every hit beam's before the temperature (which is calibrated on
  // whole scans); the field weighs a pose as amcl does (likelihood_field.h), untempered.
  const LaserScan all_hits = ParticleFilter::hitBeamSubset(scan, models.sensor, 1);
  const size_t hits = all_hits.ranges.size();
  const int stride = std::max<int>(
      1, static_cast<int>(std::ceil(static_cast<double>(hits) / config_.laser_max_beams)));
  const LaserScan weighed = ParticleFilter::hitBeamSubset(scan, models.sensor, stride);
  const double used = static_cast<double>(weighed.ranges.size());
  const double exponent =
      used > 0.0 ? static_cast<double>(hits) / used / slam_.likelihood_temperature : 0.0;
  const std::vector<MatchPoint> endpoints =
      slam_.matcher.enabled ? models.matcher.endpoints(scan) : std::vector<MatchPoint>();
  const LikelihoodField* field = nullptr;
  const BeamLookup* lookup = nullptr;
  if (config_.likelihoodField()) {
    // Computed once per map (and cap): the map never changes while localizing.
    if (!field_) {
      field_ = std::make_unique<LikelihoodField>(map_, config_.laser_likelihood_max_dist);
    }
    field = field_.get();
  } else if (!config_.beamTraced()) {
    const bool conflict_as_unknown = models.sensor.forward_conflict_as_unknown;
    if (!lookup_ || lookup_->conflictAsUnknown() != conflict_as_unknown) {
      const std::clock_t t0 = std::clock();  // CPU time: the build is single-threaded
      lookup_ = std::make_unique<BeamLookup>(map_, conflict_as_unknown);
      stats_.lookup_build_s = static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
      stats_.lookup_bytes = lookup_->memoryBytes();
    }
    lookup = lookup_.get();
  }
  BeamLookup::Options lookup_options;
  lookup_options.short_rate = short_rate_;
  out.short_rate = short_rate_;

  // The proposal is the motion model alone (amcl's): a scan match per particle pulls the samples
  // onto the matcher's optimum and cost accuracy while tracking (docs/decisions.md). Only while a
  // uniformly spread global localization has not found the pose is each sample matched, so that a
  // cloud as sparse as max_particles over the whole floor reaches the matcher's basin around the
  // true pose.
  if (searching_) searching_ = cloudSpread() > slam_.matcher.search_radius;
  // While a global localization searches, the cloud covers unexplored space too, where ignorance
  // must not count as support: never-observed ends weigh r then (docs/decisions.md).
  lookup_options.unobserved_collects = !config_.laser_unobserved_random_only && !searching_;
  // A cloud drawn around a global search's refined hypotheses already sits where the scan fits:
  // the beam model's weights single the truth out without a match per sample. amcl's weight
  // 1 + Σ p³ (likelihood_field) is too flat near an optimum for that: its samples are matched,
  // which gathers them on the hypotheses' optima (docs/decisions.md).
  const bool match_each =
      searching_ && (!seeded_ || config_.likelihoodField()) && !endpoints.empty();
  // The proposal samples the raw odometry's drift (a random walk per metre and radian), not the
  // SLAM's alpha_*, sized for samples after a scan match; the SLAM's floors stay.
  OdometryDrift drift;
  drift.rot_rot = config_.odom_drift_rot_rot;
  drift.rot_trans = config_.odom_drift_rot_trans;
  drift.trans_trans = config_.odom_drift_trans_trans;
  drift.trans_rot = config_.odom_drift_trans_rot;
  drift.min_sigma_xy = slam_.motion.min_sigma_xy;
  drift.min_sigma_theta = slam_.motion.min_sigma_theta;
  const size_t n = particles_.size();
  // A pose's log plausibility per the model, and its log weight (tempered, or amcl's).
  const auto weigh = [&](const Pose2& pose, double* log_weight) {
    const Pose2 sensor = pose.compose(weighed.sensor_pose);
    if (field != nullptr) {
      const FieldScore score = field->score(sensor, weighed, config_.laser_sigma_hit,
                                            config_.laser_z_hit, config_.laser_z_rand);
      *log_weight = std::log(score.amcl_weight);
      return score.log_likelihood;
    }
    const double pl = lookup != nullptr
                          ? lookup->logPlausibility(models.beam, sensor, weighed, lookup_options)
                          : models.beam.logPlausibility(map_, sensor, weighed, 1);
    *log_weight = exponent * pl;
    return pl;
  };
  const bool mixture = moved && !match_each && !endpoints.empty() && used > 0.0 &&
                       config_.odom_failure_rate > 0.0 && config_.scan_proposal_fraction > 0.0;
  std::vector<Pose2> previous;
  if (mixture) {
    previous.reserve(n);
    for (const LocalizationParticle& p : particles_) previous.push_back(p.pose);
  }
  pool_->run(n, [&](size_t k, int) {
    Rng rng = Rng::forStream(slam_.seed, step, k);
    Pose2 pose =
        moved ? sampleDrift(particles_[k].pose, increment, drift, &rng) : particles_[k].pose;
    if (match_each) pose = models.matcher.refine(map_, pose, endpoints);
    particles_[k].pose = pose;
  });
  // Mixture MCL (mixture_proposal.h): the motion model is a mixture of the drift and a failed
  // increment, whose rate per particle follows the failure's share of its last move (failures
  // persist). Where the scan, matched from the odometry's prediction of the estimate or from the
  // last update's match, explains the scan better than the prediction, samples are drawn around
  // the matched pose too. Every sample is weighed by target over proposal.
  std::vector<double> log_factor, failure_share;
  if (mixture) {
    const Pose2 predicted = estimate_.mean.compose(increment);
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    rotation.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(estimate_.mean.theta).toRotationMatrix();
    // The scan-drawn samples' spread: the estimate's covariance plus one increment's drift.
    const Eigen::Matrix3d spread =
        estimate_.covariance +
        rotation * MixtureProposal::driftCovariance(increment, drift) * rotation.transpose();
    // The odometry's prediction explains the scan as well as at the recent updates (no worse than
    // the deepest of their falls below their median: prediction_gate_) and the last scan was as
    // plausible under the cloud as usual (the kidnap alarm's ratio at most 1): the odometry did
    // not fail, and the scan is not matched. Otherwise (or while the gate's baseline is short),
    // matched from the prediction and from where the last update's match put the robot (the
    // estimate after a reset), where a failed increment leaves it; the one that explains the scan
    // better.
    double w_predicted = 0.0;
    const double pl_predicted = weigh(predicted, &w_predicted) / used;
    const PlausibilityAlarmState gate =
        prediction_gate_.update(pl_predicted, cloudSpread() <= slam_.matcher.search_radius);
    Pose2 matched = predicted;
    bool failed = false;
    if (!gate.armed || gate.below || last_kidnap_ratio_ > 1.0) {
      matched = models.matcher.refine(map_, predicted, endpoints);
      const Pose2 unmoved =
          models.matcher.refine(map_, last_match_ ? *last_match_ : estimate_.mean, endpoints);
      double w_matched = 0.0, w_unmoved = 0.0;
      weigh(matched, &w_matched);
      weigh(unmoved, &w_unmoved);
      if (w_unmoved > w_matched) {
        matched = unmoved;
        w_matched = w_unmoved;
      }
      failed = w_matched > w_predicted;
      ++stats_.proposal_matches;
    }
    // A particle's odometry fails at odom_failure_rate, or at odom_failure_persistence after a
    // failure (its share of the particle's last move).
    const auto rate = [&](size_t k) {
      const double f = particles_[k].odometry_failed;
      return config_.odom_failure_persistence * f + config_.odom_failure_rate * (1.0 - f);
    };
    const MixtureProposal proposal(increment, drift, config_.update_min_d, matched, spread);
    log_factor.assign(n, 0.0);
    failure_share.assign(n, 0.0);
    std::vector<char> from_scan(n, 0);
    pool_->run(n, [&](size_t k, int) {
      // A particle whose odometry is believed failed draws from the scan at least that often.
      const double fraction = failed ? std::max(config_.scan_proposal_fraction, rate(k)) : 0.0;
      if (fraction > 0.0) {
        Rng rng = Rng::forStream(slam_.seed, kMixtureStream + step, k);
        if (rng.uniform() < fraction) {
          particles_[k].pose = proposal.sampleScan(&rng);
          from_scan[k] = 1;
        }
      }
      log_factor[k] = proposal.logWeightFactor(previous[k], particles_[k].pose, rate(k), fraction);
      failure_share[k] = proposal.failureShare(previous[k], particles_[k].pose, rate(k));
    });
    for (char f : from_scan) out.scan_samples += f != 0 ? 1 : 0;
    last_match_ = matched;
    if (failed) ++stats_.scan_proposals;
  }
  std::vector<double> log_pl(n, 0.0), log_weight(n, 0.0);
  std::vector<char> on_map(n, 0);
  pool_->run(n, [&](size_t k, int) {
    const Pose2& pose = particles_[k].pose;
    on_map[k] = onMappedFloor(pose) ? 1 : 0;
    if (used > 0.0) {
      log_pl[k] = weigh(pose, &log_weight[k]);
      if (!log_factor.empty()) log_weight[k] += log_factor[k];
    }
  });

  // Weights, and the running averages of the plausibility per beam for the recovery. A scan
  // contradicts nothing in unexplored space, so a particle off the map's floor would weigh the
  // most: such particles get no weight (unless no particle is on the floor).
  bool any_on_map = false;
  for (size_t k = 0; k < n; ++k) any_on_map = any_on_map || on_map[k] != 0;
  const auto counts = [&](size_t k) { return !any_on_map || on_map[k] != 0; };
  double max_log = -std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < n; ++k) {
    if (!counts(k)) continue;
    max_log = std::max(max_log, std::log(particles_[k].weight) + log_weight[k]);
  }
  // The scan's log evidence per beam: (1 / beams) log Σ w Pl over the predicted cloud (the weights
  // before this scan), the particles off the floor left out as in the weights below.
  double max_evidence = -std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < n; ++k) {
    if (counts(k))
      max_evidence = std::max(max_evidence, std::log(particles_[k].weight) + log_pl[k]);
  }
  if (used > 0.0 && std::isfinite(max_evidence)) {
    double sum_evidence = 0.0;
    for (size_t k = 0; k < n; ++k) {
      if (counts(k))
        sum_evidence += std::exp(std::log(particles_[k].weight) + log_pl[k] - max_evidence);
    }
    out.log_evidence = (max_evidence + std::log(sum_evidence)) / used;
  }
  double sum = 0.0, w_avg = 0.0, mean_pl = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double per_beam = used > 0.0 ? log_pl[k] / used : 0.0;
    w_avg += particles_[k].weight * std::exp(per_beam);
    mean_pl += particles_[k].weight * per_beam;
    particles_[k].weight =
        counts(k) ? std::exp(std::log(particles_[k].weight) + log_weight[k] - max_log) : 0.0;
    sum += particles_[k].weight;
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) {  // every weighed particle had lost its weight
    for (LocalizationParticle& p : particles_) p.weight = 1.0;
    sum = static_cast<double>(n);
  }
  double sum_sq = 0.0;
  for (LocalizationParticle& p : particles_) {
    p.weight /= sum;
    sum_sq += p.weight * p.weight;
  }
  // Each particle's failure share of its move: its failure rate at the next update follows it.
  if (!failure_share.empty()) {
    for (size_t k = 0; k < n; ++k) {
      particles_[k].odometry_failed = failure_share[k];
      out.failure_share += particles_[k].weight * failure_share[k];
    }
  }
  out.effective_particles = sum_sq > 0.0 ? 1.0 / sum_sq : 0.0;
  out.mean_log_plausibility = mean_pl;
  if (used > 0.0) {
    w_slow_ = w_slow_ == 0.0 ? w_avg : w_slow_ + config_.recovery_alpha_slow * (w_avg - w_slow_);
    w_fast_ = w_fast_ == 0.0 ? w_avg : w_fast_ + config_.recovery_alpha_fast * (w_avg - w_fast_);
  }

  ++stats_.scans_processed;
  stats_.particle_updates += n;
  out.processed = true;
  // amcl's selective resampling: the weights are kept while they still spread over at least half
  // the particles (resampling a cloud the scan did not single out only loses its diversity).
  if (++updates_since_resample_ >= config_.resample_interval &&
      (!config_.selective_resampling ||
       out.effective_particles < 0.5 * static_cast<double>(particles_.size()))) {
    updates_since_resample_ = 0;
    resample(&out);
  }
  computeEstimate();
  // The estimate: the cluster's mean refined by one scan match (the particles are not moved).
  if (!endpoints.empty() && used > 0.0) {
    estimate_.mean = models.matcher.refine(map_, estimate_.mean, endpoints);
    ++stats_.scan_matches;
  }
  // The short readings at the estimate: the rate the beam model gives them at the next update.
  if (lookup != nullptr && used > 0.0) {
    size_t shorts = 0;
    lookup->logPlausibility(models.beam, estimate_.mean.compose(weighed.sensor_pose), weighed,
                            lookup_options, &shorts);
    short_rate_ += kShortRateWeight * (static_cast<double>(shorts) / used - short_rate_);
  }
  out.particles = particles_.size();
  stats_.max_particles_used = std::max(stats_.max_particles_used, out.particles);
  stats_.min_particles_used = stats_.min_particles_used == 0
                                  ? out.particles
                                  : std::min(stats_.min_particles_used, out.particles);

  // What this scan contradicts in the map, at the estimate: its evidence on the cells that can
  // add to the anomaly only (the map's tiles believed free are built once per map).
  Workspace& ws = *workspaces_.front();
  if (!free_tiles_) free_tiles_ = std::make_unique<BelievedFreeTiles>(map_);
  models.beam.accumulateForAnomaly(estimate_.mean.compose(scan.sensor_pose), scan, *free_tiles_,
                                   &ws.accumulator);
  std::vector<AnomalyCell> cells;
  scanAnomaly(ws.accumulator, map_, models.beam.openSpaceRadius(), &cells);
  for (const AnomalyCell& c : cells) out.anomaly_added_bits += c.bits;
  anomaly_.add(cells);
  out.contradiction = contradictionOf(cells);
  // The alarms judge the scans at a cloud the filter tracks (not while a global localization
  // searches, when the estimate means nothing yet). A kidnap makes the scans far less plausible at
  // every likely particle than while tracking (the kidnap alarm, whose baseline grows from the
  // updates at which the cloud is narrower than the matcher's reach); the particles then search
  // the whole free space. The conflict alarm is reported, not acted on: a changed world contradicts
  // the map at the right pose too (docs/decisions.md#kidnap-recovery-on-the-scans-plausibility).
  // The baselines are kept: the map and the sensor are the same after the kidnap.
  if (!searching_) {
    out.alarm = alarm_.update(out.contradiction);
    if (used > 0.0) {
      out.kidnap_alarm =
          kidnap_alarm_.update(out.log_evidence, cloudSpread() <= slam_.matcher.search_radius);
    }
    last_kidnap_ratio_ = out.kidnap_alarm.ratio;
    if (out.kidnap_alarm.rising && config_.kidnap_recovery) {
      buildFreeCells();
      if (!free_cells_.empty()) {
        trajectory_.push_back(StampedPose{scan.stamp, estimate_.mean});
        // With global_search, the particles are drawn where this scan fits best and move on
        // from this odometry; else spread uniformly, the next scan weighed where they are.
        if (config_.global_search && seedFromSearch(scan, models)) {
          have_odometry_ = true;
          force_update_ = false;
        } else {
          spreadOverFreeSpace();
        }
        alarm_.rearm();
        kidnap_alarm_.rearm();
        ++stats_.recoveries;
        out.respread = true;
        return out;
      }
    }
  }

  trajectory_.push_back(StampedPose{scan.stamp, estimate_.mean});
  return out;
}

void Localizer::resample(LocalizationUpdate* update) {
  // Augmented MCL: random poses while the fast average of the plausibility is below the slow one.
  double random_fraction = 0.0;
  if (config_.recovery_alpha_slow > 0.0 && config_.recovery_alpha_fast > 0.0 && w_slow_ > 0.0) {
    random_fraction = std::max(0.0, 1.0 - w_fast_ / w_slow_);
  }
  if (random_fraction > 0.0) {
    buildFreeCells();
    if (free_cells_.empty()) random_fraction = 0.0;
  }
  std::vector<double> cumulative(particles_.size());
  double total = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    total += particles_[i].weight;
    cumulative[i] = total;
  }
  Rng rng = Rng::forStream(slam_.seed, kDrawStream + 1, step_);
  const std::vector<LocalizationParticle> previous = std::move(particles_);
  size_t random = 0;
  drawKld(static_cast<size_t>(config_.max_particles), [&] {
    if (random_fraction > 0.0 && rng.uniform() < random_fraction) {
      ++random;
      LocalizationParticle p;
      p.pose = randomFreePose(&rng);
      return p;
    }
    const double u = rng.uniform() * total;
    const size_t i = static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                                         cumulative.begin());
    return previous[std::min(i, previous.size() - 1)];
  });
  if (random_fraction > 0.0) w_slow_ = w_fast_ = 0.0;  // as amcl: do not spiral into randomness
  ++stats_.resamplings;
  update->resampled = true;
  update->random_particles = random;
}

double Localizer::cloudSpread() const {
  double w = 0.0, x = 0.0, y = 0.0;
  for (const LocalizationParticle& p : particles_) {
    w += p.weight;
    x += p.weight * p.pose.x;
    y += p.weight * p.pose.y;
  }
  if (!(w > 0.0)) return 0.0;
  x /= w;
  y /= w;
  double xx = 0.0, xy = 0.0, yy = 0.0;
  for (const LocalizationParticle& p : particles_) {
    xx += p.weight * (p.pose.x - x) * (p.pose.x - x);
    xy += p.weight * (p.pose.x - x) * (p.pose.y - y);
    yy += p.weight * (p.pose.y - y) * (p.pose.y - y);
  }
  Eigen::Matrix2d cov;
  cov << xx / w, xy / w, xy / w, yy / w;
  return std::sqrt(
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvalues().maxCoeff()));
}

void Localizer::computeEstimate() {
  // Clusters: particles in bins that touch (x, y and heading, the heading index wrapping round).
  KldBins bins(config_.kld_bin_xy, config_.kld_bin_angle);
  const int angle_bins = static_cast<int>(std::ceil(2.0 * M_PI / config_.kld_bin_angle));
  struct Bin {
    int64_t ix, iy, ia;
    double weight = 0.0;
    int cluster = -1;
  };
  std::unordered_map<uint64_t, size_t> index;
  std::vector<Bin> cells;
  std::vector<size_t> bin_of(particles_.size());
  const auto indices = [&](const Pose2& p, int64_t* ix, int64_t* iy, int64_t* ia) {
    *ix = static_cast<int64_t>(std::floor(p.x / config_.kld_bin_xy));
    *iy = static_cast<int64_t>(std::floor(p.y / config_.kld_bin_xy));
    *ia =
        static_cast<int64_t>(std::floor((normalizeAngle(p.theta) + M_PI) / config_.kld_bin_angle));
  };
  const auto keyOf = [&](int64_t ix, int64_t iy, int64_t ia) {
    ia = ((ia % angle_bins) + angle_bins) % angle_bins;
    return (static_cast<uint64_t>(ix & 0x1FFFFF) << 42) |
           (static_cast<uint64_t>(iy & 0x1FFFFF) << 21) | static_cast<uint64_t>(ia);
  };
  for (size_t i = 0; i < particles_.size(); ++i) {
    int64_t ix, iy, ia;
    indices(particles_[i].pose, &ix, &iy, &ia);
    const uint64_t key = keyOf(ix, iy, ia);
    auto it = index.find(key);
    if (it == index.end()) {
      it = index.emplace(key, cells.size()).first;
      cells.push_back(Bin{ix, iy, ((ia % angle_bins) + angle_bins) % angle_bins});
    }
    cells[it->second].weight += particles_[i].weight;
    bin_of[i] = it->second;
  }
  std::vector<double> cluster_weight;
  std::vector<size_t> stack;
  for (size_t b = 0; b < cells.size(); ++b) {
    if (cells[b].cluster >= 0) continue;
    const int id = static_cast<int>(cluster_weight.size());
    cluster_weight.push_back(0.0);
    cells[b].cluster = id;
    stack.push_back(b);
    while (!stack.empty()) {
      const Bin bin = cells[stack.back()];
      stack.pop_back();
      cluster_weight[static_cast<size_t>(id)] += bin.weight;
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int da = -1; da <= 1; ++da) {
            const auto it = index.find(keyOf(bin.ix + dx, bin.iy + dy, bin.ia + da));
            if (it == index.end() || cells[it->second].cluster >= 0) continue;
            cells[it->second].cluster = id;
            stack.push_back(it->second);
          }
        }
      }
    }
  }
  const int best = static_cast<int>(std::max_element(cluster_weight.begin(), cluster_weight.end()) -
                                    cluster_weight.begin());
  double w = 0.0, x = 0.0, y = 0.0, s = 0.0, c = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    if (cells[bin_of[i]].cluster != best) continue;
    const LocalizationParticle& p = particles_[i];
    w += p.weight;
    x += p.weight * p.pose.x;
    y += p.weight * p.pose.y;
    s += p.weight * std::sin(p.pose.theta);
    c += p.weight * std::cos(p.pose.theta);
  }
  PoseEstimate e;
  if (w <= 0.0) {
    estimate_ = e;
    return;
  }
  e.mean = Pose2(x / w, y / w, std::atan2(s, c));
  for (size_t i = 0; i < particles_.size(); ++i) {
    if (cells[bin_of[i]].cluster != best) continue;
    const LocalizationParticle& p = particles_[i];
    const Eigen::Vector3d d(p.pose.x - e.mean.x, p.pose.y - e.mean.y,
                            normalizeAngle(p.pose.theta - e.mean.theta));
    e.covariance += (p.weight / w) * d * d.transpose();
  }
  estimate_ = e;
}

PoseEstimate Localizer::estimate() const {
  PoseEstimate e = estimate_;
  if (have_odometry_) e.mean = e.mean.compose(last_update_odometry_.between(last_odometry_));
  return e;
}

Pose2 Localizer::mapToOdom() const { return estimate().mean.compose(last_odometry_.inverse()); }

}  // namespace evidential_slam
