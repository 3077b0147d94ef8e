// Extraction of the layers of a grid (and of its anomaly, anomaly.h) into dense float rasters.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/measures.h"

namespace evidential_slam {

// Dense rasters of every layer over a box of cells. Row-major from the origin like
// nav_msgs/OccupancyGrid: index = row * width + col, row 0 is the lowest y, col 0 the lowest x.
struct LayerRaster {
  double resolution = 0.0;
  double origin_x = 0.0;  // map-frame position of the lower-left corner of cell (0, 0)
  double origin_y = 0.0;
  int width = 0;
  int height = 0;
  std::array<std::vector<float>, kLayerCount> values;
  std::vector<uint8_t> observed;  // 1 where the cell holds any evidence

  const std::vector<float>& layer(Layer l) const { return values[static_cast<int>(l)]; }
};

// A set of layers: a bit per Layer.
constexpr uint32_t layerBit(Layer layer) { return uint32_t{1} << static_cast<int>(layer); }
constexpr uint32_t kAllLayers = (uint32_t{1} << kLayerCount) - 1;

// Rasterises the observed part of `grid` plus `margin_cells` of vacuous border on each side. The
// anomaly layer comes from `anomaly` (0 everywhere without it). Only the layers in `layers` are
// computed; the others' rasters are left empty.
LayerRaster extractLayers(const EvidentialGridMap& grid, int margin_cells = 10,
                          const AnomalyGrid* anomaly = nullptr, uint32_t layers = kAllLayers);
// Rasterises an explicit box.
LayerRaster extractLayers(const EvidentialGridMap& grid, const CellBox& box,
                          const AnomalyGrid* anomaly = nullptr, uint32_t layers = kAllLayers);

}  // namespace evidential_slam
