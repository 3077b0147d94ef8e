#include "evidential_slam/core/layers.h"

namespace evidential_slam {

LayerRaster extractLayers(const EvidentialGridMap& grid, int margin_cells,
                          const AnomalyGrid* anomaly, uint32_t layers) {
  CellBox box = grid.observedBox();
  if (box.empty()) return extractLayers(grid, box, anomaly, layers);
  box.min_x -= margin_cells;
  box.min_y -= margin_cells;
  box.max_x += margin_cells;
  box.max_y += margin_cells;
  return extractLayers(grid, box, anomaly, layers);
}

LayerRaster extractLayers(const EvidentialGridMap& grid, const CellBox& box,
                          const AnomalyGrid* anomaly, uint32_t layers) {
  LayerRaster r;
  r.resolution = grid.resolution();
  r.width = box.width();
  r.height = box.height();
  r.origin_x = box.empty() ? 0.0 : box.min_x * grid.resolution();
  r.origin_y = box.empty() ? 0.0 : box.min_y * grid.resolution();
  const size_t n = static_cast<size_t>(r.width) * r.height;
  // The layers a cell is read for (the anomaly is not the cell's: it comes from `anomaly`).
  std::vector<int> from_cells;
  for (int l = 0; l < kLayerCount; ++l) {
    if ((layers & layerBit(static_cast<Layer>(l))) == 0) continue;
    r.values[l].assign(n, 0.0f);
    if (static_cast<Layer>(l) != Layer::kAnomaly) from_cells.push_back(l);
  }
  r.observed.assign(n, 0);
  for (int row = 0; row < r.height; ++row) {
    for (int col = 0; col < r.width; ++col) {
      const Cell& c = grid.cell(box.min_x + col, box.min_y + row);
      const size_t i = static_cast<size_t>(row) * r.width + col;
      r.observed[i] = c.observed() ? 1 : 0;
      for (const int l : from_cells) {
        r.values[l][i] = static_cast<float>(layerValue(c, static_cast<Layer>(l)));
      }
    }
  }
  if (anomaly != nullptr && (layers & layerBit(Layer::kAnomaly)) != 0) {
    std::vector<float>& values = r.values[static_cast<int>(Layer::kAnomaly)];
    anomaly->forEach([&](int x, int y, float bits) {
      const int col = x - box.min_x, row = y - box.min_y;
      if (col < 0 || row < 0 || col >= r.width || row >= r.height) return;
      values[static_cast<size_t>(row) * r.width + col] = bits;
    });
  }
  return r;
}

}  // namespace evidential_slam
