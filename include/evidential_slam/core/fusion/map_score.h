// Scoring a map against a ground-truth occupancy raster: each cell classified occupied, free or
// unknown by its pignistic probability BetP(o) and non-specificity NS, then compared with the
// truth where the truth knows the cell: accuracy and coverage.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace fusion {

enum class CellClass : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// A plain occupancy raster (io/ reads it from an image). Row-major from the origin like
// nav_msgs/OccupancyGrid: index = row * width + col, row 0 the lowest y, col 0 the lowest x.
struct OccupancyRaster {
  double resolution = 0.0;  // m per cell
  double origin_x = 0.0;    // frame position of the lower-left corner of cell (0, 0)
  double origin_y = 0.0;
  int width = 0;
  int height = 0;
  std::vector<CellClass> cells;

  CellClass at(int col, int row) const {
    return cells[static_cast<size_t>(row) * static_cast<size_t>(width) + static_cast<size_t>(col)];
  }
  bool isValid(std::string* why) const;
};

struct ClassifyConfig {
  double occupied_betp = 0.6;       // occupied: BetP(o) at least this ...
  double free_betp = 0.4;           // free: BetP(o) at most this ...
  double max_nonspecificity = 0.5;  // ... and, either way, NS = m(Θ) at most this
  bool isValid(std::string* why) const;
};

// Unobserved cells are unknown (their NS is 1).
CellClass classify(const Cell& cell, const ClassifyConfig& config);

struct MapScore {
  size_t known = 0;       // truth cells occupied or free
  size_t classified = 0;  // of those, the map says occupied or free
  size_t correct = 0;     // of those, it says what the truth says
  // [truth][map] cell counts, indexed by CellClass.
  std::array<std::array<size_t, 3>, 3> confusion{};
  double accuracy() const {
    return classified > 0 ? static_cast<double>(correct) / static_cast<double>(classified) : 0.0;
  }
  double coverage() const {
    return known > 0 ? static_cast<double>(classified) / static_cast<double>(known) : 0.0;
  }
};

// Scores `map`, placed in the truth's frame by `map_in_truth`, on the truth's cells. A truth cell
// takes the classes of the map cells whose centres fall in it: occupied if any is occupied (walls
// are thin next to a coarse truth cell), else free if any is free, else unknown; a truth cell that
// holds no map cell centre (a truth finer than the map) takes the class of the map cell under its
// centre. False (and `why`) for an invalid raster or config.
bool scoreMap(const EvidentialGridMap& map, const Pose2& map_in_truth, const OccupancyRaster& truth,
              const ClassifyConfig& config, MapScore* score, std::string* why);

}  // namespace fusion
}  // namespace evidential_slam
