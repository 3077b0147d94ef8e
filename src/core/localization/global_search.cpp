#include "evidential_slam/core/localization/global_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "evidential_slam/core/localization/likelihood_field.h"

namespace evidential_slam {
namespace {

// The `count` best regions seen so far, each with its best leaf.
class BestRegions {
 public:
  struct Entry {
    uint64_t key;
    int score;
    int x, y, heading;
  };
  explicit BestRegions(size_t count) : count_(std::max<size_t>(count, 1)) {}
  bool full() const { return entries_.size() >= count_; }
  // A candidate must score above this to matter (when full).
  int threshold() const { return full() ? entries_[min_].score : -1; }
  void offer(const Entry& e) {
    const auto it = index_.find(e.key);
    if (it != index_.end()) {
      Entry& old = entries_[it->second];
      if (e.score > old.score) {
        old = e;
        if (it->second == min_) findMin();
      }
      return;
    }
    if (!full()) {
      index_.emplace(e.key, entries_.size());
      entries_.push_back(e);
      if (full()) findMin();
      return;
    }
    if (e.score <= entries_[min_].score) return;
    index_.erase(entries_[min_].key);
    entries_[min_] = e;
    index_.emplace(e.key, min_);
    findMin();
  }
  std::vector<Entry> sorted() const {
    std::vector<Entry> out = entries_;
    std::stable_sort(out.begin(), out.end(),
                     [](const Entry& a, const Entry& b) { return a.score > b.score; });
    return out;
  }

 private:
  void findMin() {
    min_ = 0;
    for (size_t i = 1; i < entries_.size(); ++i) {
      if (entries_[i].score < entries_[min_].score) min_ = i;
    }
  }
  size_t count_;
  std::vector<Entry> entries_;
  std::unordered_map<uint64_t, size_t> index_;
  size_t min_ = 0;
};

struct Node {
  int x, y;  // box cells of the square's lower-left corner
  int heading;
  int score;
};

// One level of a max pyramid over a width x height raster: each cell the largest of `below` at
// its own cell and the cells `half` to its right, above, and both (0 past the raster's edge).
void maxPool(const std::vector<uint8_t>& below, int width, int height, int half,
             std::vector<uint8_t>* level) {
  const auto get = [&](int x, int y) -> uint8_t {
    return x < width && y < height ? below[static_cast<size_t>(y) * width + x] : 0;
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      (*level)[static_cast<size_t>(y) * width + x] =
          std::max(std::max(get(x, y), get(x + half, y)),
                   std::max(get(x, y + half), get(x + half, y + half)));
    }
  }
}

}  // namespace

GlobalSearch::GlobalSearch(const EvidentialGridMap& map, double sigma,
                           const std::vector<CellIndex>& free_cells)
    : box_(map.observedBox()), resolution_(map.resolution()), sigma_(sigma) {
  if (box_.empty()) throw std::invalid_argument("GlobalSearch: the map has no observed cell");
  if (!(sigma > 0.0)) throw std::invalid_argument("GlobalSearch: sigma must be positive");
  const int w = box_.width(), h = box_.height();
  pad_ = (1 << (kLevels - 1)) - 1;
  width_ = w + pad_;
  height_ = h + pad_;
  // s = exp(-d² / 2σ²) up to 3σ, 0 beyond (and off the box, where the field holds its cap).
  const double cap = 3.0 * sigma;
  const LikelihoodField field(map, cap);
  levels_.assign(kLevels, std::vector<uint8_t>(static_cast<size_t>(width_) * height_, 0));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double d = field.distance((box_.min_x + x + 0.5) * resolution_,
                                      (box_.min_y + y + 0.5) * resolution_);
      if (d >= cap) continue;
      levels_[0][static_cast<size_t>(y + pad_) * width_ + (x + pad_)] =
          static_cast<uint8_t>(std::lround(255.0 * std::exp(-d * d / (2.0 * sigma * sigma))));
    }
  }
  free_.assign(kLevels, std::vector<uint8_t>(static_cast<size_t>(w) * h, 0));
  for (const CellIndex& c : free_cells) {
    const int x = c.x - box_.min_x, y = c.y - box_.min_y;
    if (x >= 0 && y >= 0 && x < w && y < h) free_[0][static_cast<size_t>(y) * w + x] = 1;
  }
  // Level k from level k - 1: the max over the four 2^(k-1) squares of its 2^k square (for the
  // free flags, 0 or 1, whether any of them holds a free cell).
  for (int k = 1; k < kLevels; ++k) {
    const int half = 1 << (k - 1);
    maxPool(levels_[static_cast<size_t>(k - 1)], width_, height_, half,
            &levels_[static_cast<size_t>(k)]);
    maxPool(free_[static_cast<size_t>(k - 1)], w, h, half, &free_[static_cast<size_t>(k)]);
  }
}

double GlobalSearch::headingStep(double resolution, double max_range) {
  if (!(max_range > resolution)) return M_PI / 4.0;
  return std::min(M_PI / 4.0,
                  std::acos(1.0 - resolution * resolution / (2.0 * max_range * max_range)));
}

int GlobalSearch::at(int level, int px, int py) const {
  if (px < 0 || py < 0 || px >= width_ || py >= height_) return 0;
  return levels_[static_cast<size_t>(level)][static_cast<size_t>(py) * width_ + px];
}

int GlobalSearch::sum(int level, int x, int y, const std::vector<Offset>& offsets) const {
  int total = 0;
  for (const Offset& o : offsets) total += at(level, x + o.x + pad_, y + o.y + pad_);
  return total;
}

bool GlobalSearch::freeAt(int level, int x, int y) const {
  const int w = box_.width();
  if (x < 0 || y < 0 || x >= w || y >= box_.height()) return false;
  return free_[static_cast<size_t>(level)][static_cast<size_t>(y) * w + x] != 0;
}

double GlobalSearch::cellScore(int cx, int cy) const {
  return at(0, cx - box_.min_x + pad_, cy - box_.min_y + pad_) / 255.0;
}

double GlobalSearch::score(const Pose2& pose, const std::vector<Eigen::Vector2d>& points) const {
  if (points.empty()) return 0.0;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  double total = 0.0;
  for (const Eigen::Vector2d& p : points) {
    const double x = pose.x + c * p.x() - s * p.y(), y = pose.y + s * p.x() + c * p.y();
    total += cellScore(static_cast<int>(std::floor(x / resolution_)),
                       static_cast<int>(std::floor(y / resolution_)));
  }
  return total / static_cast<double>(points.size());
}

std::vector<PoseHypothesis> GlobalSearch::search(const std::vector<Eigen::Vector2d>& points,
                                                 const Options& options, Stats* stats) const {
  std::vector<PoseHypothesis> out;
  if (points.empty()) return out;
  double max_range = 0.0;
  for (const Eigen::Vector2d& p : points) max_range = std::max(max_range, p.norm());
  const double step = headingStep(resolution_, max_range);
  const int headings = static_cast<int>(std::ceil(2.0 * M_PI / step - 1e-9));
  const double heading_step = 2.0 * M_PI / headings;
  // The endpoints' cells relative to the robot's, per heading (the robot at a cell's centre).
  std::vector<std::vector<Offset>> offsets(static_cast<size_t>(headings));
  for (int a = 0; a < headings; ++a) {
    const double theta = a * heading_step;
    const double c = std::cos(theta), s = std::sin(theta);
    for (const Eigen::Vector2d& p : points) {
      offsets[static_cast<size_t>(a)].push_back(
          Offset{static_cast<int>(std::floor(0.5 + (c * p.x() - s * p.y()) / resolution_)),
                 static_cast<int>(std::floor(0.5 + (s * p.x() + c * p.y()) / resolution_))});
    }
  }
  uint64_t evaluations = 0;
  const int top = kLevels - 1;
  const int side = 1 << top;
  std::vector<Node> roots;
  for (int y = 0; y < box_.height(); y += side) {
    for (int x = 0; x < box_.width(); x += side) {
      if (!freeAt(top, x, y)) continue;
      for (int a = 0; a < headings; ++a) {
        roots.push_back(Node{x, y, a, sum(top, x, y, offsets[static_cast<size_t>(a)])});
      }
    }
  }
  evaluations += roots.size();
  std::stable_sort(roots.begin(), roots.end(),
                   [](const Node& a, const Node& b) { return a.score > b.score; });

  BestRegions best(options.count);
  const auto region = [&](const Node& n) {
    const double x = (box_.min_x + n.x + 0.5) * resolution_;
    const double y = (box_.min_y + n.y + 0.5) * resolution_;
    const double theta = normalizeAngle(n.heading * heading_step);
    const int64_t ix = static_cast<int64_t>(std::floor(x / options.region_xy));
    const int64_t iy = static_cast<int64_t>(std::floor(y / options.region_xy));
    const int64_t ia = static_cast<int64_t>(std::floor((theta + M_PI) / options.region_angle));
    return (static_cast<uint64_t>(ix & 0x1FFFFF) << 42) |
           (static_cast<uint64_t>(iy & 0x1FFFFF) << 21) | static_cast<uint64_t>(ia & 0x1FFFFF);
  };
  // Depth first, the most promising square first (the best leaves come early and raise the
  // threshold that prunes the rest).
  const auto expand = [&](const auto& self, const Node& node, int level) -> void {
    if (level == 0) {
      best.offer(BestRegions::Entry{region(node), node.score, node.x, node.y, node.heading});
      return;
    }
    const int half = 1 << (level - 1);
    Node children[4];
    int n = 0;
    const std::vector<Offset>& o = offsets[static_cast<size_t>(node.heading)];
    for (int dy = 0; dy <= half; dy += half) {
      for (int dx = 0; dx <= half; dx += half) {
        const int x = node.x + dx, y = node.y + dy;
        if (!freeAt(level - 1, x, y)) continue;
        children[n++] = Node{x, y, node.heading, sum(level - 1, x, y, o)};
      }
    }
    evaluations += static_cast<uint64_t>(n);
    // At most four: an insertion sort, best first.
    for (int i = 1; i < n; ++i) {
      for (int j = i; j > 0 && children[j].score > children[j - 1].score; --j) {
        std::swap(children[j], children[j - 1]);
      }
    }
    for (int i = 0; i < n; ++i) {
      if (children[i].score <= best.threshold()) break;
      self(self, children[i], level - 1);
    }
  };
  for (const Node& root : roots) {
    if (root.score <= best.threshold()) break;
    expand(expand, root, top);
  }
  const double norm = 255.0 * static_cast<double>(points.size());
  for (const BestRegions::Entry& e : best.sorted()) {
    out.push_back(PoseHypothesis{
        Pose2((box_.min_x + e.x + 0.5) * resolution_, (box_.min_y + e.y + 0.5) * resolution_,
              normalizeAngle(e.heading * heading_step)),
        e.score / norm});
  }
  if (stats != nullptr) {
    stats->headings = static_cast<size_t>(headings);
    stats->evaluations = evaluations;
  }
  return out;
}

}  // namespace evidential_slam
