#include "evidential_slam/core/layers.h"

namespace evidential_slam {

LayerRaster extractLayers(const EvidentialGridMap& grid, int margin_cells,
                          const AnomalyGrid* anomaly) {
  CellBox box = grid.observedBox();
  if (box.empty()) return extractLayers(grid, box, anomaly);
  box.min_x -= margin_cells;
  box.min_y -= margin_cells;
  box.max_x += margin_cells;
  box.max_y += margin_cells;
  return extractLayers(grid, box, anomaly);
}

LayerRaster extractLayers(const EvidentialGridMap& grid, const CellBox& box,
                          const AnomalyGrid* anomaly) {
  LayerRaster r;
  r.resolution = grid.resolution();
  r.width = box.width();
  r.height = box.height();
  r.origin_x = box.empty() ? 0.0 : box.min_x * grid.resolution();
  r.origin_y = box.empty() ? 0.0 : box.min_y * grid.resolution();
  const size_t n = static_cast<size_t>(r.width) * r.height;
  for (auto& v : r.values) v.assign(n, 0.0f);
  r.observed.assign(n, 0);
  for (int row = 0; row < r.height; ++row) {
    for (int col = 0; col < r.width; ++col) {
      const Cell& c = grid.cell(box.min_x + col, box.min_y + row);
      const size_t i = static_cast<size_t>(row) * r.width + col;
      r.observed[i] = c.observed() ? 1 : 0;
      for (int l = 0; l < kLayerCount; ++l) {
        r.values[l][i] = static_cast<float>(layerValue(c, static_cast<Layer>(l)));
      }
    }
  }
  if (anomaly != nullptr) {
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
