#include "evidential_slam/core/fusion/map_fusion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace evidential_slam {
namespace fusion {
namespace {

// A source seen from the fused map: fused cell (cx, cy) reads the source's cell containing the
// fused cell's centre. Resampling is nearest neighbour: every fused cell gets the belief of one
// source cell as that map holds it, never a blend of neighbours. Averaging masses is no evidential
// combination (it would mix a wall's cells with the free space beside it, and the cautious rule
// would then see evidence it cannot recognise as shared), and the position error it saves is at
// most half a cell's diagonal, the grid's own quantisation. A map fused with itself at the
// identity, or shifted by whole cells, reads each of its cells exactly once.
struct PlacedSource {
  const EvidentialGridMap* map = nullptr;
  double discount = 0.0;
  // Source cell coordinates (continuous, cell units) = rot · (cx + 0.5, cy + 0.5) + shift.
  double cos_t = 1.0, sin_t = 0.0, shift_x = 0.0, shift_y = 0.0;
  CellBox box;  // fused cells that can read an observed cell of this source

  const Cell& cellUnder(int cx, int cy) const {
    const double fx = cx + 0.5, fy = cy + 0.5;
    const double sx = cos_t * fx - sin_t * fy + shift_x;
    const double sy = sin_t * fx + cos_t * fy + shift_y;
    return map->cell(static_cast<int>(std::floor(sx)), static_cast<int>(std::floor(sy)));
  }
};

PlacedSource place(const FusionSource& source, double resolution) {
  PlacedSource p;
  p.map = source.map;
  p.discount = source.discount;
  // The fused frame into the source's: the inverse of the source's pose.
  const Pose2 to_source = source.pose.inverse();
  p.cos_t = std::cos(to_source.theta);
  p.sin_t = std::sin(to_source.theta);
  p.shift_x = to_source.x / resolution;
  p.shift_y = to_source.y / resolution;
  const CellBox observed = source.map->observedBox();
  if (observed.empty()) return p;  // p.box stays empty
  // The source's observed box in the fused frame: the bounding box of its corners, plus a cell.
  double min_x = std::numeric_limits<double>::max(), min_y = min_x;
  double max_x = std::numeric_limits<double>::lowest(), max_y = max_x;
  for (const int x : {observed.min_x, observed.max_x + 1}) {
    for (const int y : {observed.min_y, observed.max_y + 1}) {
      const Eigen::Vector2d q =
          source.pose.transformPoint(Eigen::Vector2d(x * resolution, y * resolution));
      min_x = std::min(min_x, q.x());
      max_x = std::max(max_x, q.x());
      min_y = std::min(min_y, q.y());
      max_y = std::max(max_y, q.y());
    }
  }
  p.box.min_x = static_cast<int>(std::floor(min_x / resolution)) - 1;
  p.box.min_y = static_cast<int>(std::floor(min_y / resolution)) - 1;
  p.box.max_x = static_cast<int>(std::floor(max_x / resolution)) + 1;
  p.box.max_y = static_cast<int>(std::floor(max_y / resolution)) + 1;
  return p;
}

bool inBox(const CellBox& b, int x, int y) {
  return x >= b.min_x && x <= b.max_x && y >= b.min_y && y <= b.max_y;
}

bool finitePose(const Pose2& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}

}  // namespace

bool FusionConfig::isValid(std::string* why) const {
  const int r = static_cast<int>(rule);
  if (r < 0 || r >= kRuleCount) {
    if (why != nullptr) *why = "fusion rule " + std::to_string(r) + " does not exist";
    return false;
  }
  return true;
}

bool fuseMaps(const std::vector<FusionSource>& sources, const FusionConfig& config,
              EvidentialGridMap* fused, FusionReport* report, std::string* why) {
  std::string reason;
  auto fail = [&](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!config.isValid(&reason)) return fail("invalid fusion config: " + reason);
  if (sources.empty()) return fail("no maps to fuse");
  for (size_t i = 0; i < sources.size(); ++i) {
    const FusionSource& s = sources[i];
    const std::string name = "map " + std::to_string(i + 1);
    if (s.map == nullptr) return fail(name + " is missing");
    if (!(s.discount >= 0.0 && s.discount <= 1.0)) {
      std::ostringstream msg;
      msg << name << ": discount " << s.discount << " is outside [0, 1]";
      return fail(msg.str());
    }
    if (!finitePose(s.pose)) return fail(name + ": its pose is not finite");
    const double r0 = sources.front().map->resolution(), r = s.map->resolution();
    if (std::abs(r - r0) > 1e-9 * r0) {
      std::ostringstream msg;
      msg << name << " has " << r << " m cells and map 1 " << r0
          << " m: fusion needs one resolution";
      return fail(msg.str());
    }
  }

  const double resolution = sources.front().map->resolution();
  std::vector<PlacedSource> placed;
  CellBox all;
  for (const FusionSource& s : sources) {
    placed.push_back(place(s, resolution));
    if (!placed.back().box.empty()) all.extend(placed.back().box);
  }

  FusionReport rep;
  rep.observed_cells.assign(sources.size(), 0);
  EvidentialGridMap out(resolution);
  double conflict_sum = 0.0, added_sum = 0.0;
  std::vector<Belief> beliefs;
  std::vector<size_t> from;  // which sources observed the cell
  constexpr int kBits = EvidentialGridMap::kTileBits, kSize = EvidentialGridMap::kTileSize;
  if (!all.empty()) {
    for (int ty = all.min_y >> kBits; ty <= all.max_y >> kBits; ++ty) {
      for (int tx = all.min_x >> kBits; tx <= all.max_x >> kBits; ++tx) {
        std::array<Cell, EvidentialGridMap::kTileCells> cells{};
        std::array<bool, EvidentialGridMap::kTileCells> written{};
        bool any = false;
        for (int j = 0; j < kSize; ++j) {
          for (int i = 0; i < kSize; ++i) {
            const int cx = tx * kSize + i, cy = ty * kSize + j;  // not << (tiles can be < 0)
            beliefs.clear();
            from.clear();
            const Cell* only = nullptr;
            for (size_t s = 0; s < placed.size(); ++s) {
              const PlacedSource& p = placed[s];
              if (p.discount >= 1.0 || !inBox(p.box, cx, cy)) continue;
              const Cell& c = p.cellUnder(cx, cy);
              if (!c.observed()) continue;
              only = &c;
              from.push_back(s);
              beliefs.push_back(discount(Belief::fromCell(c), p.discount));
            }
            if (from.empty()) continue;
            for (const size_t s : from) ++rep.observed_cells[s];
            ++rep.fused_cells;
            const size_t k = static_cast<size_t>(EvidentialGridMap::cellInTile(cx, cy));
            const bool as_is = from.size() == 1 && placed[from[0]].discount == 0.0 &&
                               config.rule != Rule::kDempster && config.rule != Rule::kYager;
            written[k] = true;
            any = true;
            if (as_is) {
              cells[k] = *only;
              continue;
            }
            const Belief result = combine(config.rule, beliefs);
            cells[k] = result.toCell();
            if (from.size() >= 2) {
              ++rep.overlap_cells;
              conflict_sum += conflictBetween(beliefs);
              double before = 0.0;
              for (const Belief& b : beliefs) before = std::max(before, b.conflict());
              added_sum += result.conflict() - before;
            }
          }
        }
        if (!any) continue;
        EvidentialGridMap::Tile& tile = out.mutableTile(tx, ty);
        for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) {
          if (!written[static_cast<size_t>(k)]) continue;
          tile.cells[static_cast<size_t>(k)] = cells[static_cast<size_t>(k)];
          tile.cellWritten(k);
        }
      }
    }
  }
  if (rep.overlap_cells > 0) {
    rep.mean_conflict = conflict_sum / rep.overlap_cells;
    rep.mean_conflict_added = added_sum / rep.overlap_cells;
  }
  *fused = std::move(out);
  if (report != nullptr) *report = rep;
  return true;
}

}  // namespace fusion
}  // namespace evidential_slam
