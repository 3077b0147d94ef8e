#include "evidential_slam/core/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "evidential_slam/core/motion_model.h"
#include "evidential_slam/core/scan_matcher.h"
#include "evidential_slam/core/sensor_model.h"
#include "evidential_slam/core/worker_pool.h"

namespace evidential_slam {

PathNode::~PathNode() {
  // Unlink the chain iteratively: a recursive release of thousands of nodes could overflow the
  // stack.
  std::shared_ptr<const PathNode> next = std::move(parent);
  while (next && next.use_count() == 1) {
    std::shared_ptr<const PathNode> after = std::move(const_cast<PathNode&>(*next).parent);
    next = std::move(after);
  }
}

struct ParticleFilter::ScanModels {
  ScanModels(const SlamConfig& config, float range_sigma)
      : beam(config.sensor.forSensorNoise(range_sigma, config.resolution), config.resolution),
        matcher(config.matcher.forSensorNoise(range_sigma, beam.inverseMass(0.0).occupied),
                config.sensor.forSensorNoise(range_sigma, config.resolution), config.resolution) {}
  BeamModel beam;
  ScanMatcher matcher;
};

const ParticleFilter::ScanModels& ParticleFilter::modelsFor(const LaserScan& scan) {
  const float sigma =
      std::isfinite(scan.range_sigma) && scan.range_sigma > 0.0f ? scan.range_sigma : 0.0f;
  for (const auto& m : models_) {
    if (m.first == sigma) return *m.second;
  }
  models_.emplace_back(sigma, std::make_unique<ScanModels>(config_, sigma));
  return *models_.back().second;
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
  const BeamModel* beam_model = &modelsFor(scan).beam;
  beam_model->traceScan(pose.compose(scan.sensor_pose), scan, &ws.traced);
  FilterStepInfo info;
  info.best_conflict_added_bits = beam_model->integrateScan(ws.traced, &first.map, &ws.accumulator,
                                                            &info.best_conflict_mass_added);
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

FilterStepInfo ParticleFilter::update(const Pose2& increment, const LaserScan& scan, int step) {
  const ScanModels& models = modelsFor(scan);
  const BeamModel* beam_model = &models.beam;
  const ScanMatcher* matcher = &models.matcher;
  const std::vector<MatchPoint> endpoints = matcher->endpoints(scan);
  const double exponent = 1.0 / config_.likelihood_temperature;
  const size_t n = particles_.size();

  // 1. Proposal: sample the motion model, refine against the particle's own map.
  std::vector<Pose2> proposed(n);
  pool_->run(n, [&](size_t k, int) {
    Rng rng = Rng::forStream(config_.seed, static_cast<uint64_t>(step), k);
    Pose2 pose = sampleMotion(particles_[k].pose, increment, config_.motion, &rng);
    if (config_.matcher.enabled && !endpoints.empty()) {
      pose = matcher->refine(particles_[k].map, pose, endpoints);
    }
    proposed[k] = pose;
  });

  // 2. Particles with the same map and (within the matcher's precision) the same pose are one
  //    hypothesis: weight and integrate the scan once for the group.
  std::vector<size_t> group_of(n);
  std::vector<size_t> leaders;
  for (size_t k = 0; k < n; ++k) {
    size_t g = leaders.size();
    for (size_t i = 0; i < leaders.size(); ++i) {
      const size_t l = leaders[i];
      if (particles_[l].map_id != particles_[k].map_id) continue;
      const Pose2 d = proposed[l].between(proposed[k]);
      if (std::hypot(d.x, d.y) <= config_.merge_distance &&
          std::abs(d.theta) <= config_.merge_angle) {
        g = i;
        break;
      }
    }
    if (g == leaders.size()) leaders.push_back(k);
    group_of[k] = g;
  }
  last_groups_ = leaders.size();

  // 3. Weight and map update, once per group.
  std::vector<double> log_pl(leaders.size(), 0.0), conflict_added(leaders.size(), 0.0);
  std::vector<double> conflict_mass(leaders.size(), 0.0);
  pool_->run(leaders.size(), [&](size_t g, int worker) {
    Particle& p = particles_[leaders[g]];
    Workspace& ws = *workspaces_[static_cast<size_t>(worker)];
    beam_model->traceScan(proposed[leaders[g]].compose(scan.sensor_pose), scan, &ws.traced);
    log_pl[g] =
        beam_model->scanLogPlausibility(p.map, ws.traced, config_.sensor.weight_beam_stride);
    conflict_added[g] =
        beam_model->integrateScan(ws.traced, &p.map, &ws.accumulator, &conflict_mass[g]);
  });

  // 4. Members take their leader's pose, map (shared tiles) and path node.
  std::vector<std::shared_ptr<const PathNode>> nodes(leaders.size());
  std::vector<uint64_t> ids(leaders.size());
  for (size_t g = 0; g < leaders.size(); ++g) {
    auto node = std::make_shared<PathNode>();
    node->pose = proposed[leaders[g]];
    node->step = step;
    node->parent = particles_[leaders[g]].path;
    nodes[g] = std::move(node);
    ids[g] = next_map_id_++;
  }
  for (size_t k = 0; k < n; ++k) {
    const size_t g = group_of[k];
    Particle& p = particles_[k];
    if (k != leaders[g]) p.map = particles_[leaders[g]].map;
    p.pose = proposed[leaders[g]];
    p.map_id = ids[g];
    p.path = nodes[g];
    p.log_weight += exponent * log_pl[g];
    p.cumulative_log_weight += exponent * log_pl[g];
  }

  FilterStepInfo info;
  info.best_conflict_added_bits = conflict_added[group_of[bestIndex()]];
  info.best_conflict_mass_added = conflict_mass[group_of[bestIndex()]];
  resampleIfNeeded(&info);
  return info;
}

void ParticleFilter::resampleIfNeeded(FilterStepInfo* info) {
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
  std::vector<Particle> next;
  next.reserve(particles_.size());
  for (size_t parent : parents) {
    next.push_back(particles_[parent]);  // the map copy shares every tile
    next.back().log_weight = 0.0;
  }
  particles_ = std::move(next);
  info->resampled = true;
}

}  // namespace evidential_slam
