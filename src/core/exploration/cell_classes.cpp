#include "evidential_slam/core/exploration/cell_classes.h"

#include <cmath>

#include "evidential_slam/core/parameter_rows.h"

namespace evidential_slam {
namespace exploration {

CellClassConfig::CellClassConfig() {
  ES_EXPLORER_CELL_PARAMETERS(ES_SET_PARAMETER_DEFAULT, (*this))
}

bool CellClassConfig::isValid(std::string* why) const {
  bool ok = true;
  ES_EXPLORER_CELL_PARAMETERS(ES_CHECK_PARAMETER_RANGE, (*this))
  if (ok && unknown_ns < free_ns) {
    if (why != nullptr) *why = "unknown_ns must not be below free_ns";
    return false;
  }
  return ok;
}

CellClass classifyCell(double betp, double ns, const CellClassConfig& c) {
  if (betp >= c.occupied_betp) return CellClass::kOccupied;
  if (ns >= c.unknown_ns) return CellClass::kUnknown;
  if (betp <= c.free_betp && ns <= c.free_ns) return CellClass::kFree;
  return CellClass::kUncertain;
}

GridGeometry GridGeometry::of(const LayerRaster& r) {
  GridGeometry g;
  g.resolution = r.resolution;
  g.origin_x = r.origin_x;
  g.origin_y = r.origin_y;
  g.width = r.width;
  g.height = r.height;
  return g;
}

void GridGeometry::cellOf(double x, double y, int* c, int* r) const {
  *c = static_cast<int>(std::floor((x - origin_x) / resolution));
  *r = static_cast<int>(std::floor((y - origin_y) / resolution));
}

int GridGeometry::indexOf(const Eigen::Vector2d& p) const {
  int c = 0, r = 0;
  cellOf(p.x(), p.y(), &c, &r);
  return inside(c, r) ? index(c, r) : -1;
}

Eigen::Vector2d GridGeometry::center(int i) const {
  return {origin_x + (col(i) + 0.5) * resolution, origin_y + (row(i) + 0.5) * resolution};
}

std::vector<CellClass> classifyCells(const LayerRaster& raster, const CellClassConfig& config) {
  const auto& betp = raster.layer(Layer::kPignistic);
  const auto& ns = raster.layer(Layer::kNonspecificity);
  std::vector<CellClass> classes(betp.size());
  for (size_t i = 0; i < betp.size(); ++i) classes[i] = classifyCell(betp[i], ns[i], config);
  return classes;
}

}  // namespace exploration
}  // namespace evidential_slam
