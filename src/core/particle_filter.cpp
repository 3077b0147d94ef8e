#include "evidential_slam/core/particle_filter.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "evidential_slam/core/motion_model.h"
#include "evidential_slam/core/profile.h"
#include "evidential_slam/core/scan_matcher.h"
#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/core/sole_owner.h"
#include "evidential_slam/core/worker_pool.h"

namespace evidential_slam {
namespace {
// Below this odometry translation (m) the alternative starts of the wide-basin match (no
// translation, translation reversed) lie within ICP's capture of the prediction: not tried.
constexpr double kAlternativeStartsFrom = 0.15;
// -ln of the prior probability that the odometry's translation is missing or reversed (5 %;
// Freiburg 079 reverses unsigned in 3.5 % of its scans). Also the floor of the weights'
// along-track motion prior (alongTrackLogPrior).
constexpr double kTranslationFailureNats = 3.0;
// A nominal match whose log plausibility per beam is above this explains the scan: the wide search
// is skipped. The floor is log r = -1.6 (a random reading); measured on intel (250 scans, K = 30):
// -0.3 keeps the full search's accuracy (0.16 m) at 85 % of its time, -0.5 loses it (1.1 m).
constexpr double kExplainedLogPlausibilityPerBeam = -0.3;
}  // namespace

PathNode::~PathNode() {
  // Unlink the chain iteratively: a recursive release of thousands of nodes could overflow the
  // stack.
  std::shared_ptr<const PathNode> next = std::move(parent);
  while (isSoleOwner(next)) {
    std::shared_ptr<const PathNode> after = std::move(const_cast<PathNode&>(*next).parent);
    next = std::move(after);
  }
}

// The models for one sensor noise and step length: after a long step (SlamConfig::isLongStep)
// the matcher at long_step.beam_spacing and the forward model at long_step.forward_sigma, where
// those are set.
struct ParticleFilter::ScanModels {
  ScanModels(const SlamConfig& config, float range_sigma, bool long_step)
      : sensor(sensorConfig(config, long_step).forSensorNoise(range_sigma, config.resolution)),
        beam(sensor, config.resolution),
        matcher(matcherConfig(config, range_sigma, long_step), sensor, config.resolution) {}
  static SensorModelConfig sensorConfig(const SlamConfig& config, bool long_step) {
    SensorModelConfig c = config.sensor;
    if (long_step && config.long_step.forward_sigma > 0.0) {
      c.forward_sigma = config.long_step.forward_sigma;
    }
    return c;
  }
  ScanMatcherConfig matcherConfig(const SlamConfig& config, float range_sigma, bool long_step) {
    ScanMatcherConfig c = config.matcher;
    if (long_step && config.long_step.beam_spacing > 0.0) {
      c.beam_spacing = config.long_step.beam_spacing;
    }
    return c.forSensorNoise(range_sigma, beam.inverseMass(0.0).occupied, config.resolution);
  }
  SensorModelConfig sensor;  // the models' configuration for this sensor's declared noise
  BeamModel beam;
  ScanMatcher matcher;
};

const ParticleFilter::ScanModels& ParticleFilter::modelsFor(const LaserScan& scan, bool long_step) {
  const float sigma =
      std::isfinite(scan.range_sigma) && scan.range_sigma > 0.0f ? scan.range_sigma : 0.0f;
  for (const auto& m : models_) {
    if (m.range_sigma == sigma && m.long_step == long_step) return *m.models;
  }
  models_.push_back({sigma, long_step, std::make_unique<ScanModels>(config_, sigma, long_step)});
  return *models_.back().models;
}

struct ParticleFilter::Workspace {
  TracedScan traced;
  ScanAccumulator accumulator;
};

ParticleFilter::ParticleFilter(const SlamConfig& config)
    : config_(config), pool_(std::make_unique<WorkerPool>(config.threads)) {
  for (int i = 0; i < pool_->size(); ++i) workspaces_.push_back(std::make_unique<Workspace>());
}

ParticleFilter::~ParticleFilter() = default;

void ParticleFilter::reconfigure(const SlamConfig& config) {
  SlamConfig next = config;
  next.particles = config_.particles;
  next.resolution = config_.resolution;
  next.seed = config_.seed;
  next.threads = config_.threads;
  config_ = next;
  models_.clear();  // rebuilt from the new sensor and matcher parameters at the next scan
}

size_t ParticleFilter::bestIndex() const {
  size_t best = 0;
  for (size_t i = 1; i < particles_.size(); ++i) {
    if (particles_[i].cumulative_log_weight > particles_[best].cumulative_log_weight) best = i;
  }
  return best;
}

size_t ParticleFilter::mapMemoryBytes() const {
  std::unordered_set<const EvidentialGridMap::Tile*> seen;
  size_t bytes = 0;
  for (const Particle& p : particles_) bytes += p.map.accumulateUniqueTileBytes(&seen);
  return bytes;
}

std::vector<size_t> ParticleFilter::systematicResample(const std::vector<double>& weights,
                                                       double u0) {
  const size_t n = weights.size();
  std::vector<size_t> parents(n);
  double total = 0.0;
  for (double w : weights) total += w;
  double cumulative = 0.0;
  size_t j = 0;
  for (size_t i = 0; i < n; ++i) {
    const double u = (u0 + static_cast<double>(i)) / static_cast<double>(n) * total;
    while (j + 1 < n && (cumulative + weights[j] <= u || weights[j] <= 0.0)) {
      cumulative += weights[j];
      ++j;
    }
    parents[i] = j;
  }
  return parents;
}

FilterStepInfo ParticleFilter::initialize(const Pose2& pose, const LaserScan& scan, int step) {
  particles_.assign(static_cast<size_t>(config_.particles), Particle{});
  for (Particle& p : particles_) {
    p.pose = pose;
    p.map = EvidentialGridMap(config_.resolution);
  }
  // All particles would integrate the same scan at the same pose: do it once and share the tiles.
  Particle& first = particles_.front();
  Workspace& ws = *workspaces_.front();
  FilterStepInfo info;
  if (map_updates_) {
    const BeamModel* beam_model = &modelsFor(scan, false).beam;
    beam_model->traceScan(pose.compose(scan.sensor_pose), scan, &ws.traced);
    info.best_conflict_added_bits =
        beam_model->integrateScan(ws.traced, &first.map, &ws.accumulator, &info.best_conflict);
  }
  auto root = std::make_shared<PathNode>();
  root->pose = pose;
  root->step = step;
  first.path = std::move(root);
  first.map_id = next_map_id_++;
  for (size_t i = 1; i < particles_.size(); ++i) {
    particles_[i].map = first.map;
    particles_[i].map_id = first.map_id;
    particles_[i].path = first.path;
  }
  info.effective_sample_size = static_cast<double>(particles_.size());
  return info;
}

void ParticleFilter::startOnMap(const EvidentialGridMap& map, const Pose2& pose) {
  particles_.assign(static_cast<size_t>(config_.particles), Particle{});
  const uint64_t id = next_map_id_++;
  for (Particle& p : particles_) {
    p.pose = pose;
    p.map = map;  // copies the tile pointers only
    p.map_id = id;
  }
}

LaserScan ParticleFilter::hitBeamSubset(const LaserScan& scan, const SensorModelConfig& sensor,
                                        int stride) {
  LaserScan out;
  out.stamp = scan.stamp;
  out.sensor_pose = scan.sensor_pose;
  out.max_range = scan.max_range;
  out.range_sigma = scan.range_sigma;
  // BeamModel::traceScan's test for a hit: a valid, finite range in [min_range, usable_range) and
  // below the sensor's maximum.
  const double sensor_max = scan.max_range > 0.0f ? scan.max_range : sensor.usable_range;
  int k = 0;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const float z = scan.ranges[i];
    if (!scan.valid.empty() && scan.valid[i] == 0) continue;
    if (!std::isfinite(z) || z < 0.0f || z < sensor.min_range) continue;
    if (z >= sensor.usable_range || z >= sensor_max) continue;
    if (k++ % stride != 0) continue;
    out.ranges.push_back(z);
    out.bearings.push_back(scan.bearings[i]);
    out.valid.push_back(1);
  }
  return out;
}

ParticleFilter::NominalMatch ParticleFilter::nominalMatch(
    const EvidentialGridMap& map, const Pose2& predicted, const std::vector<MatchPoint>& endpoints,
    const LaserScan& hits, const ScanModels& models, const ScanMatcher& matcher) const {
  NominalMatch m;
  m.icp = matcher.matchFrom(map, predicted, endpoints);
  m.pose = m.icp.pose;
  // No match from the prediction: the map does not explain the scan there (a new area); a start
  // nearer the mapped area would win for that reason alone.
  if (m.icp.score <= 0.0) {
    m.pose = predicted;
    m.settled = true;
    return m;
  }
  m.log_plausibility = wideLogPlausibility(map, m.pose, hits, models);
  const double used = static_cast<double>(hits.ranges.size());
  m.settled = used > 0.0 && m.log_plausibility / used > kExplainedLogPlausibilityPerBeam;
  return m;
}

double ParticleFilter::wideLogPlausibility(const EvidentialGridMap& map, const Pose2& pose,
                                           const LaserScan& hits, const ScanModels& models) const {
  return models.beam.logPlausibility(map, pose.compose(hits.sensor_pose), hits, 1);
}

std::vector<ParticleFilter::WideCandidate> ParticleFilter::wideCandidates(
    const EvidentialGridMap& map, const Pose2& previous, const Pose2& increment,
    const std::vector<MatchPoint>& endpoints, const ScanMatcher& matcher,
    const NominalMatch& nominal) const {
  const Pose2 predicted = previous.compose(increment);
  std::vector<WideCandidate> candidates;
  double s = 0.0;
  // A turned candidate is one the odometry's heading error makes common (prior 1/e); one without
  // or with reversed translation, an odometry failure (prior 5 %). The unturned start is the
  // nominal match's ICP.
  candidates.push_back(WideCandidate{
      matcher.search(map, predicted, endpoints, config_.matcher.heading_window, &s, &nominal.icp),
      1.0});
  if (std::hypot(increment.x, increment.y) > kAlternativeStartsFrom) {
    for (const double sign : {0.0, -1.0}) {  // no translation; translation reversed
      const Pose2 start =
          previous.compose(Pose2(sign * increment.x, sign * increment.y, increment.theta));
      candidates.push_back(
          WideCandidate{matcher.search(map, start, endpoints, 0.0, &s), kTranslationFailureNats});
    }
  }
  return candidates;
}

Pose2 ParticleFilter::chooseCandidate(const EvidentialGridMap& map, const NominalMatch& nominal,
                                      const std::vector<WideCandidate>& candidates,
                                      const LaserScan& hits, const ScanModels& models) const {
  // Chosen by the forward model, the likelihood the weights use, tempered like the weights (T)
  // and with the candidate's prior.
  Pose2 best = nominal.pose;
  double best_pl = nominal.log_plausibility;
  for (const WideCandidate& c : candidates) {
    const Pose2 d = nominal.pose.between(c.pose);
    if (std::hypot(d.x, d.y) < 0.05 && std::abs(d.theta) < 0.02) continue;  // the nominal one
    const double pl = wideLogPlausibility(map, c.pose, hits, models) -
                      config_.likelihood_temperature * c.prior_nats;
    if (pl > best_pl) {
      best_pl = pl;
      best = c.pose;
    }
  }
  return best;
}

FilterStepInfo ParticleFilter::update(const Pose2& increment, const LaserScan& scan, int step) {
  // A long odometry step has its own beam spacing and forward model (config.h).
  const bool long_step = config_.isLongStep(std::hypot(increment.x, increment.y), increment.theta);
  const ScanModels& models = modelsFor(scan, long_step);
  const BeamModel* beam_model = &models.beam;
  const ScanMatcher* matcher = &models.matcher;
  const std::vector<MatchPoint> endpoints = matcher->endpoints(scan);
  const double exponent = 1.0 / config_.likelihood_temperature;
  const size_t n = particles_.size();

  // 1. Wide-basin match once per hypothesis (particles with one map id share map and pose): the
  //    correction from the odometry prediction to where the scan fits best. (Running its
  //    multi-start ICPs once per cluster of nearby poses instead, on the map of the cluster's
  //    best particle, was 2-4x cheaper but less accurate: aces K=100 0.63-2.5 m, against 0.36 m.)
  const bool search =
      config_.matcher.enabled && config_.matcher.heading_window > 0.0 && !endpoints.empty();
  // The constrained merge (config.h) for a laser matched point to line: a noisy laser's walls are
  // bands whose endpoints read as fixed both ways, and merging there cost accuracy
  // (range_030_bearing_015.rawlog seed 1: 0.565 m against 0.332).
  const bool measure_constraint = config_.constrained_merge_ratio > 0.0 &&
                                  config_.matcher.enabled && matcher->config().point_to_line &&
                                  !endpoints.empty();
  const auto fixesEveryWay = [&](const EvidentialGridMap& map, const Pose2& pose) {
    return matcher->translationConstraint(map, pose, endpoints) >= config_.constrained_merge_ratio;
  };
  // Hypotheses: particles with one map id share map and pose; firsts[h] is h's first particle.
  std::vector<size_t> hypothesis_of(n, 0);
  std::vector<size_t> firsts;
  if (search || measure_constraint) {
    for (size_t k = 0; k < n; ++k) {
      size_t h = 0;
      while (h < firsts.size() && particles_[firsts[h]].map_id != particles_[k].map_id) ++h;
      if (h == firsts.size()) firsts.push_back(k);
      hypothesis_of[k] = h;
    }
  }
  std::vector<Pose2> correction;
  // Per hypothesis: the scan fixes its position every way (constrained_merge_ratio).
  std::vector<char> constrained(firsts.size(), 0);
  last_wide_matches_ = 0;
  if (search) {
    // Candidates are weighed on the beams the matcher uses (half of a 1° laser's: half the cost,
    // the same ranking).
    const LaserScan hits = hitBeamSubset(scan, config_.sensor, matcher->matchStride(scan));
    correction.resize(firsts.size());
    std::vector<char> searched(firsts.size(), 0);
    pool_->run(firsts.size(), [&](size_t h, int) {
      const Particle& p = particles_[firsts[h]];
      const Pose2 predicted = p.pose.compose(increment);
      // ICP from the prediction; unless that explains the scan, also the multi-start search.
      const NominalMatch nominal =
          nominalMatch(p.map, predicted, endpoints, hits, models, *matcher);
      Pose2 chosen = nominal.pose;
      if (!nominal.settled) {
        searched[h] = 1;
        chosen = chooseCandidate(
            p.map, nominal, wideCandidates(p.map, p.pose, increment, endpoints, *matcher, nominal),
            hits, models);
      }
      correction[h] = predicted.between(chosen);
      constrained[h] = measure_constraint && fixesEveryWay(p.map, chosen);
    });
    for (const char s : searched) last_wide_matches_ += s != 0 ? 1 : 0;
  }

  // 2. Proposal: sample the motion model (around the hypothesis's match when searched), refine
  //    against the particle's own map.
  std::vector<Pose2> proposed(n);
  pool_->run(n, [&](size_t k, int) {
    Rng rng = Rng::forStream(config_.seed, static_cast<uint64_t>(step), k);
    Pose2 pose = sampleMotion(particles_[k].pose, increment, config_.motion, &rng);
    if (search) {
      // The sample's deviation from the prediction, applied to the matched pose.
      const Pose2 predicted = particles_[k].pose.compose(increment);
      pose = predicted.compose(correction[hypothesis_of[k]]).compose(predicted.between(pose));
    }
    if (config_.matcher.enabled && !endpoints.empty()) {
      pose = matcher->refine(particles_[k].map, pose, endpoints);
    }
    proposed[k] = pose;
  });

  // 3. Particles with the same map and (within the matcher's precision) the same pose are one
  //    hypothesis: weight and integrate the scan once for the group. Where the scan fixes the
  //    hypothesis's position every way, within the wider constrained_merge_distance / _angle:
  //    measured at the hypothesis's wide-basin match when that ran, else at its first
  //    particle's refined pose.
  if (measure_constraint && !search) {
    pool_->run(firsts.size(), [&](size_t h, int) {
      constrained[h] = fixesEveryWay(particles_[firsts[h]].map, proposed[firsts[h]]);
    });
  }
  std::vector<size_t> group_of(n);
  std::vector<size_t> leaders;
  for (size_t k = 0; k < n; ++k) {
    const bool wide = measure_constraint && constrained[hypothesis_of[k]] != 0;
    const double max_distance = wide ? config_.constrained_merge_distance : config_.merge_distance;
    const double max_angle = wide ? config_.constrained_merge_angle : config_.merge_angle;
    size_t g = leaders.size();
    for (size_t i = 0; i < leaders.size(); ++i) {
      const size_t l = leaders[i];
      if (particles_[l].map_id != particles_[k].map_id) continue;
      const Pose2 d = proposed[l].between(proposed[k]);
      if (std::hypot(d.x, d.y) <= max_distance && std::abs(d.theta) <= max_angle) {
        g = i;
        break;
      }
    }
    if (g == leaders.size()) leaders.push_back(k);
    group_of[k] = g;
  }
  last_groups_ = leaders.size();
  // A member takes its leader's map after the update (5.), so it lets go of its own now: the
  // last group writing a tile of their common map then writes it in place instead of cloning it,
  // and the old tile is not kept alive until 5.
  for (size_t k = 0; k < n; ++k) {
    if (k != leaders[group_of[k]]) {
      particles_[k].map = EvidentialGridMap(particles_[k].map.resolution());
    }
  }

  // 4a. Optionally the weights' motion prior, along the direction of travel only: a corridor
  //     leaves the scan likelihood flat along it (config.h, along_track_prior).
  std::vector<double> motion_log_prior(leaders.size(), 0.0);
  for (size_t g = 0; config_.along_track_prior && g < leaders.size(); ++g) {
    motion_log_prior[g] = alongTrackLogPrior(particles_[leaders[g]].pose, proposed[leaders[g]],
                                             increment, config_.motion, kTranslationFailureNats);
  }

  // 4b. Weight and map update (unless mapping is paused), once per group. Only the best particle's
  // conflict figures are
  //     reported, so a group whose highest new cumulative weight is already below another
  //     group's skips the open-space pass (the best group never does, whatever the order).
  std::vector<double> group_top(leaders.size(), -std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < n; ++k) {
    double& top = group_top[group_of[k]];
    if (!(particles_[k].cumulative_log_weight <= top)) top = particles_[k].cumulative_log_weight;
  }
  std::atomic<double> best_top(-std::numeric_limits<double>::infinity());
  std::vector<double> log_pl(leaders.size(), 0.0), conflict_added(leaders.size(), 0.0);
  std::vector<ScanConflict> conflict_stats(leaders.size());
  std::vector<std::vector<AnomalyCell>> anomaly(leaders.size());
  pool_->run(leaders.size(), [&](size_t g, int worker) {
    Particle& p = particles_[leaders[g]];
    if (!map_updates_) {  // paused mapping: weigh only
      log_pl[g] = beam_model->logPlausibility(p.map, proposed[leaders[g]].compose(scan.sensor_pose),
                                              scan, config_.sensor.weight_beam_stride);
      return;
    }
    Workspace& ws = *workspaces_[static_cast<size_t>(worker)];
    log_pl[g] =
        beam_model->weighAndAccumulate(proposed[leaders[g]].compose(scan.sensor_pose), scan, p.map,
                                       &ws.accumulator, config_.sensor.weight_beam_stride);
    // The same sum as 5.'s, so the comparison is exact (adding one number keeps the order).
    const double top = group_top[g] + (exponent * log_pl[g] + motion_log_prior[g]);
    double seen = best_top.load(std::memory_order_relaxed);
    while (top > seen && !best_top.compare_exchange_weak(seen, top, std::memory_order_relaxed)) {
    }
    const bool may_be_best = !(top < seen);
    // The anomaly against the map before the scan (anomaly.h), kept on the group's lineage.
    scanAnomaly(ws.accumulator, p.map, beam_model->openSpaceRadius(), &anomaly[g]);
    conflict_added[g] =
        beam_model->applyScan(ws.accumulator, &p.map, may_be_best ? &conflict_stats[g] : nullptr);
    conflict_stats[g].contradiction = contradictionOf(anomaly[g]);
  });
  Profiler* const profiler = Profiler::active();
  if (profiler != nullptr) {
    profiler->count(ProfileCounter::kUpdates);
    if (profiler->floor_enabled) replayFloor(profiler, *beam_model, scan, proposed, leaders);
  }

  // 5. Members take their leader's pose, map (shared tiles), path node and anomaly node.
  std::vector<std::shared_ptr<const PathNode>> nodes(leaders.size());
  std::vector<std::shared_ptr<const AnomalyNode>> anomaly_nodes(leaders.size());
  std::vector<uint64_t> ids(leaders.size());
  for (size_t g = 0; g < leaders.size(); ++g) {
    auto node = std::make_shared<PathNode>();
    node->pose = proposed[leaders[g]];
    node->step = step;
    node->parent = particles_[leaders[g]].path;
    nodes[g] = std::move(node);
    anomaly_nodes[g] = particles_[leaders[g]].anomaly;
    if (!anomaly[g].empty()) {
      auto added = std::make_shared<AnomalyNode>();
      added->cells = std::move(anomaly[g]);
      added->parent = std::move(anomaly_nodes[g]);
      anomaly_nodes[g] = std::move(added);
    }
    ids[g] = next_map_id_++;
  }
  for (size_t k = 0; k < n; ++k) {
    const size_t g = group_of[k];
    Particle& p = particles_[k];
    if (k != leaders[g]) p.map = particles_[leaders[g]].map;
    p.pose = proposed[leaders[g]];
    p.map_id = ids[g];
    p.path = nodes[g];
    p.anomaly = anomaly_nodes[g];
    const double log_weight = exponent * log_pl[g] + motion_log_prior[g];
    p.log_weight += log_weight;
    p.cumulative_log_weight += log_weight;
  }

  FilterStepInfo info;
  info.long_step = long_step;
  info.best_conflict_added_bits = conflict_added[group_of[bestIndex()]];
  info.best_conflict = conflict_stats[group_of[bestIndex()]];
  resampleIfNeeded(&info);
  return info;
}

void ParticleFilter::replayFloor(Profiler* profiler, const BeamModel& beam_model,
                                 const LaserScan& scan, const std::vector<Pose2>& proposed,
                                 const std::vector<size_t>& leaders) {
  Workspace& ws = *workspaces_.front();
  std::vector<std::pair<int, int>> cells;
  for (size_t g = 0; g < leaders.size(); ++g) {
    beam_model.traceScan(proposed[leaders[g]].compose(scan.sensor_pose), scan, &ws.traced);
    cells.clear();
    for (const RayCell& c : ws.traced.cells) cells.emplace_back(c.x, c.y);
    profiler->floorReplay(g, cells);
  }
}

void ParticleFilter::resampleIfNeeded(FilterStepInfo* info) {
  const ProfileTimer timer(ProfileSection::kResample);
  double max_log = -std::numeric_limits<double>::infinity();
  for (const Particle& p : particles_) max_log = std::max(max_log, p.log_weight);
  std::vector<double> w(particles_.size());
  double sum = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].log_weight -= max_log;  // keep the log weights near 0
    w[i] = std::exp(particles_[i].log_weight);
    sum += w[i];
  }
  double sum_sq = 0.0;
  for (double& x : w) {
    x /= sum;
    sum_sq += x * x;
  }
  info->effective_sample_size = 1.0 / sum_sq;
  if (info->effective_sample_size >=
      config_.resample_threshold * static_cast<double>(particles_.size())) {
    return;
  }
  Rng rng = Rng::forStream(config_.seed, 0xA5A5A5A5ull, resample_counter_++);
  const std::vector<size_t> parents = systematicResample(w, rng.uniform());
  // A child copies its parent (the map copy shares every tile); a parent's last child takes it
  // over instead, sparing a copy of the tile pointers and their reference counts.
  std::vector<size_t> last_child(particles_.size(), 0);
  for (size_t i = 0; i < parents.size(); ++i) last_child[parents[i]] = i;
  std::vector<Particle> next;
  next.reserve(particles_.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    Particle& parent = particles_[parents[i]];
    if (last_child[parents[i]] == i) {
      next.push_back(std::move(parent));
    } else {
      next.push_back(parent);
    }
    next.back().log_weight = 0.0;
  }
  particles_ = std::move(next);
  info->resampled = true;
}

}  // namespace evidential_slam
