// What exploration reads from a layer raster: each cell's class (free, occupied, not yet observed,
// or in between) from its pignistic probability BetP(o) and non-specificity NS = m(Θ), and the
// raster's geometry (cell index <-> map-frame position).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/parameter_fields/explorer_cell.h"

namespace evidential_slam {
namespace exploration {

// Occupied is checked first, then unknown (NS at or above unknown_ns), then free. A single free
// pass leaves NS = r = 0.2; the Θ gap the inverse model leaves in front of a hit holds 0.5-0.9
// until the wall has been seen a few times, which must not read as a frontier.
struct CellClassConfig {
  CellClassConfig();  // the table's defaults
  ES_EXPLORER_CELL_FIELDS

  bool isValid(std::string* why) const;
};

enum class CellClass : uint8_t {
  kFree,
  kOccupied,
  kUnknown,
  kUncertain,  // neither: thinly observed, or balanced evidence
};

CellClass classifyCell(double betp, double ns, const CellClassConfig& config);

// Cell index <-> position for a raster (LayerRaster's layout: row-major, row 0 = lowest y).
struct GridGeometry {
  double resolution = 0.05;
  double origin_x = 0.0;  // map position of the lower-left corner of cell (0, 0)
  double origin_y = 0.0;
  int width = 0;
  int height = 0;

  static GridGeometry of(const LayerRaster& raster);
  int size() const { return width * height; }
  bool inside(int col, int row) const {
    return col >= 0 && row >= 0 && col < width && row < height;
  }
  int index(int col, int row) const { return row * width + col; }
  int col(int index) const { return index % width; }
  int row(int index) const { return index / width; }
  // Column and row of the cell holding (x, y) (possibly outside the grid).
  void cellOf(double x, double y, int* col, int* row) const;
  // Index of the cell holding (x, y), -1 outside.
  int indexOf(const Eigen::Vector2d& p) const;
  Eigen::Vector2d center(int index) const;
};

// Classes of every cell of a raster.
std::vector<CellClass> classifyCells(const LayerRaster& raster, const CellClassConfig& config);

}  // namespace exploration
}  // namespace evidential_slam
