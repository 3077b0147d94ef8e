#include "evidential_slam/core/profile.h"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace evidential_slam {

std::atomic<Profiler*> Profiler::active_{nullptr};
thread_local ProfileTimer* ProfileTimer::current_ = nullptr;

const char* profileSectionName(ProfileSection s) {
  switch (s) {
    case ProfileSection::kWideMatchForward: return "wide-basin match: forward model";
    case ProfileSection::kIcp: return "ICP (wide match and refinement)";
    case ProfileSection::kHillClimb: return "hill climb (scan matcher score)";
    case ProfileSection::kConstraint: return "translation constraint (merge)";
    case ProfileSection::kWeighAccumulate: return "traversal: forward model + evidence";
    case ProfileSection::kOpenSpace: return "open-space conflict";
    case ProfileSection::kApplyScan: return "applying the scan to the map";
    case ProfileSection::kTileClone: return "tile clones (copy-on-write)";
    case ProfileSection::kResample: return "resampling";
    case ProfileSection::kCount: break;
  }
  return "?";
}

const char* profileCounterName(ProfileCounter c) {
  switch (c) {
    case ProfileCounter::kUpdates: return "updates";
    case ProfileCounter::kGroupsWeighed: return "groups_weighed";
    case ProfileCounter::kGroupsApplied: return "groups_applied";
    case ProfileCounter::kVisitedCells: return "visited_cells";
    case ProfileCounter::kAppliedCells: return "applied_cells";
    case ProfileCounter::kTileClones: return "tile_clones";
    case ProfileCounter::kFloorCells: return "floor_cells";
    case ProfileCounter::kCount: break;
  }
  return "?";
}

// A map of its own per group slot for the floor replay: 32 x 32-cell tiles of 8-byte cells (the
// size of ours), allocated on first use, the last tile kept at hand.
struct Profiler::FloorMap {
  static constexpr int kBits = 5;
  static constexpr int kSide = 1 << kBits;
  using Tile = std::array<double, kSide * kSide>;
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<std::unique_ptr<Tile>> tiles;

  Tile* tileAt(int tx, int ty) {
    if (tx < x0 || ty < y0 || tx >= x0 + w || ty >= y0 + h) grow(tx, ty);
    std::unique_ptr<Tile>& t = tiles[static_cast<size_t>(ty - y0) * w + (tx - x0)];
    if (!t) {
      t = std::make_unique<Tile>();
      t->fill(1.0);
    }
    return t.get();
  }
  void grow(int tx, int ty) {
    const int nx0 = w == 0 ? tx - 16 : std::min(x0, tx - 16);
    const int ny0 = h == 0 ? ty - 16 : std::min(y0, ty - 16);
    const int nx1 = w == 0 ? tx + 16 : std::max(x0 + w - 1, tx + 16);
    const int ny1 = h == 0 ? ty + 16 : std::max(y0 + h - 1, ty + 16);
    const int nw = nx1 - nx0 + 1, nh = ny1 - ny0 + 1;
    std::vector<std::unique_ptr<Tile>> grown(static_cast<size_t>(nw) * nh);
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        grown[static_cast<size_t>(j + y0 - ny0) * nw + (i + x0 - nx0)] =
            std::move(tiles[static_cast<size_t>(j) * w + i]);
      }
    }
    tiles = std::move(grown);
    x0 = nx0;
    y0 = ny0;
    w = nw;
    h = nh;
  }
};

Profiler::Profiler() = default;
Profiler::~Profiler() = default;

void Profiler::floorReplay(size_t slot, const std::vector<std::pair<int, int>>& cells) {
  while (floor_maps_.size() <= slot) floor_maps_.push_back(std::make_unique<FloorMap>());
  FloorMap& map = *floor_maps_[slot];
  // Tiles are allocated before the clock starts: the floor is the cells' work, not allocation.
  for (const auto& [x, y] : cells) map.tileAt(x >> FloorMap::kBits, y >> FloorMap::kBits);
  const int64_t start = ProfileTimer::threadCpuNs();
  int last_tx = std::numeric_limits<int>::min(), last_ty = 0;
  FloorMap::Tile* tile = nullptr;
  for (const auto& [x, y] : cells) {
    const int tx = x >> FloorMap::kBits, ty = y >> FloorMap::kBits;
    if (tx != last_tx || ty != last_ty) {
      last_tx = tx;
      last_ty = ty;
      tile = map.tiles[static_cast<size_t>(ty - map.y0) * map.w + (tx - map.x0)].get();
    }
    double& c = (*tile)[static_cast<size_t>(((y & (FloorMap::kSide - 1)) << FloorMap::kBits) |
                                            (x & (FloorMap::kSide - 1)))];
    c = c * -1.0;  // one read, one multiply, one write (the sign flips: no denormals)
  }
  floor_ns_ += ProfileTimer::threadCpuNs() - start;
  count(ProfileCounter::kFloorCells, cells.size());
}

std::string Profiler::report() const {
  const double updates = std::max<double>(1.0, static_cast<double>(counter(ProfileCounter::kUpdates)));
  int64_t total = 0;
  for (int s = 0; s < static_cast<int>(ProfileSection::kCount); ++s) {
    total += nanoseconds(static_cast<ProfileSection>(s));
  }
  std::string out;
  char line[200];
  std::snprintf(line, sizeof(line), "%-40s %12s %7s\n", "section (CPU time, exclusive)",
                "ms/update", "share");
  out += line;
  for (int s = 0; s < static_cast<int>(ProfileSection::kCount); ++s) {
    const auto section = static_cast<ProfileSection>(s);
    const double ns = static_cast<double>(nanoseconds(section));
    std::snprintf(line, sizeof(line), "%-40s %12.2f %6.1f%%\n", profileSectionName(section),
                  ns / updates * 1e-6, total > 0 ? 100.0 * ns / static_cast<double>(total) : 0.0);
    out += line;
  }
  std::snprintf(line, sizeof(line), "%-40s %12.2f %6.1f%%\n", "sum", total / updates * 1e-6,
                100.0);
  out += line;
  const double visited = static_cast<double>(counter(ProfileCounter::kVisitedCells));
  const double map_ns = static_cast<double>(nanoseconds(ProfileSection::kWeighAccumulate) +
                                            nanoseconds(ProfileSection::kOpenSpace) +
                                            nanoseconds(ProfileSection::kApplyScan) +
                                            nanoseconds(ProfileSection::kTileClone));
  if (visited > 0) {
    std::snprintf(line, sizeof(line),
                  "ns per visited cell: %.2f weigh-and-integrate, %.2f whole update\n",
                  map_ns / visited, static_cast<double>(total) / visited);
    out += line;
  }
  if (floor_enabled && counter(ProfileCounter::kFloorCells) > 0) {
    std::snprintf(line, sizeof(line),
                  "floor: %.2f ms/update (%.2f ns per cell); weigh-and-integrate %.2fx, whole "
                  "update %.2fx the floor\n",
                  static_cast<double>(floor_ns_) / updates * 1e-6,
                  static_cast<double>(floor_ns_) /
                      static_cast<double>(counter(ProfileCounter::kFloorCells)),
                  map_ns / static_cast<double>(floor_ns_),
                  static_cast<double>(total) / static_cast<double>(floor_ns_));
    out += line;
  }
  for (int c = 0; c < static_cast<int>(ProfileCounter::kCount); ++c) {
    const auto counter_id = static_cast<ProfileCounter>(c);
    std::snprintf(line, sizeof(line), "%s %llu (%.1f per update)\n", profileCounterName(counter_id),
                  static_cast<unsigned long long>(counter(counter_id)),
                  static_cast<double>(counter(counter_id)) / updates);
    out += line;
  }
  return out;
}

}  // namespace evidential_slam
