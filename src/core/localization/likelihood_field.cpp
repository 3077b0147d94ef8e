#include "evidential_slam/core/localization/likelihood_field.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "evidential_slam/core/localization/distance_transform.h"

namespace evidential_slam {

bool LikelihoodField::plausibleEnd(const Cell& cell) {
  return cell.observed() && cell.toMass().free <= 0.5;
}

LikelihoodField::LikelihoodField(const EvidentialGridMap& map, double max_dist)
    : box_(map.observedBox()), resolution_(map.resolution()), max_dist_(max_dist) {
  if (!(max_dist > 0.0)) {
    throw std::invalid_argument("LikelihoodField: the distance cap must be positive");
  }
  const int w = box_.width(), h = box_.height();
  std::vector<uint8_t> seeds(static_cast<size_t>(w) * static_cast<size_t>(h));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      seeds[static_cast<size_t>(y) * w + x] =
          plausibleEnd(map.cell(box_.min_x + x, box_.min_y + y)) ? 1 : 0;
    }
  }
  const std::vector<float> squared = squaredDistanceTransform(seeds, w, h);
  distance_.resize(squared.size());
  const float cap = static_cast<float>(max_dist_);
  for (size_t i = 0; i < squared.size(); ++i) {
    distance_[i] = std::min(cap, static_cast<float>(std::sqrt(squared[i]) * resolution_));
  }
}

double LikelihoodField::distance(double x, double y) const {
  const int cx = static_cast<int>(std::floor(x / resolution_)) - box_.min_x;
  const int cy = static_cast<int>(std::floor(y / resolution_)) - box_.min_y;
  if (cx < 0 || cy < 0 || cx >= box_.width() || cy >= box_.height()) return max_dist_;
  return distance_[static_cast<size_t>(cy) * box_.width() + cx];
}

double LikelihoodField::logLikelihood(const Pose2& sensor, const LaserScan& beams,
                                      double sigma_hit, double z_hit, double z_rand) const {
  return score(sensor, beams, sigma_hit, z_hit, z_rand).log_likelihood;
}

FieldScore LikelihoodField::score(const Pose2& sensor, const LaserScan& beams, double sigma_hit,
                                  double z_hit, double z_rand) const {
  const double denominator = 2.0 * sigma_hit * sigma_hit;
  const double uniform = beams.max_range > 0.0f ? z_rand / beams.max_range : 0.0;
  const double c = std::cos(sensor.theta), s = std::sin(sensor.theta);
  FieldScore out;
  for (size_t i = 0; i < beams.ranges.size(); ++i) {
    const double r = beams.ranges[i];
    const double a = beams.bearings[i];
    const double bx = r * std::cos(a), by = r * std::sin(a);
    const double d = distance(sensor.x + c * bx - s * by, sensor.y + s * bx + c * by);
    const double p = z_hit * std::exp(-d * d / denominator) + uniform;
    out.log_likelihood += std::log(std::max(p, std::numeric_limits<double>::min()));
    out.amcl_weight += p * p * p;
  }
  return out;
}

}  // namespace evidential_slam
