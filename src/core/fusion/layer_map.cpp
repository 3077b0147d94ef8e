#include "evidential_slam/core/fusion/layer_map.h"

#include <array>
#include <cmath>
#include <sstream>

#include "evidential_slam/core/fusion/combination.h"

namespace evidential_slam {
namespace fusion {

bool mapFromLayers(const LayerRaster& raster, EvidentialGridMap* map, Pose2* offset,
                   std::string* why) {
  auto fail = [&](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!(std::isfinite(raster.resolution) && raster.resolution > 0.0)) {
    return fail("layer raster: resolution must be positive and finite");
  }
  if (!std::isfinite(raster.origin_x) || !std::isfinite(raster.origin_y)) {
    return fail("layer raster: origin is not finite");
  }
  if (raster.width < 0 || raster.height < 0) return fail("layer raster: negative size");
  const size_t cells = static_cast<size_t>(raster.width) * static_cast<size_t>(raster.height);
  for (const Layer l :
       {Layer::kOccupied, Layer::kFree, Layer::kUnknown, Layer::kExternalConflict}) {
    if (raster.layer(l).size() != cells) {
      std::ostringstream msg;
      msg << "layer raster: " << layerName(l) << " has " << raster.layer(l).size()
          << " values, not " << raster.width << " x " << raster.height;
      return fail(msg.str());
    }
  }
  if (raster.observed.size() != cells) {
    std::ostringstream msg;
    msg << "layer raster: observed has " << raster.observed.size() << " values, not "
        << raster.width << " x " << raster.height;
    return fail(msg.str());
  }
  const double gx = raster.origin_x / raster.resolution, gy = raster.origin_y / raster.resolution;
  if (std::abs(gx) > 1e9 || std::abs(gy) > 1e9) return fail("layer raster: origin out of range");
  const int x0 = static_cast<int>(std::lround(gx)), y0 = static_cast<int>(std::lround(gy));

  const std::vector<float>& occ = raster.layer(Layer::kOccupied);
  const std::vector<float>& fre = raster.layer(Layer::kFree);
  const std::vector<float>& unk = raster.layer(Layer::kUnknown);
  const std::vector<float>& ec = raster.layer(Layer::kExternalConflict);
  EvidentialGridMap out(raster.resolution);
  for (int row = 0; row < raster.height; ++row) {
    for (int col = 0; col < raster.width; ++col) {
      const size_t i =
          static_cast<size_t>(row) * static_cast<size_t>(raster.width) + static_cast<size_t>(col);
      if (raster.observed[i] == 0) continue;
      const double o = occ[i], e = fre[i], u = unk[i], bits = ec[i];
      const double sum = o + e + u;
      if (!(o >= 0.0 && e >= 0.0 && u >= 0.0 && bits >= 0.0 && std::isfinite(sum) && sum > 0.0 &&
            !std::isnan(bits))) {
        std::ostringstream msg;
        msg << "layer raster: cell (" << col << ", " << row << ") has masses " << o << ", " << e
            << ", " << u << " and EC " << bits << " bits: not a belief";
        return fail(msg.str());
      }
      Belief b;
      b.normal.occupied = o / sum;
      b.normal.free = e / sum;
      b.normal.unknown = u / sum;
      b.lambda = bits * std::log(2.0);
      const int cx = x0 + col, cy = y0 + row;
      EvidentialGridMap::Tile& tile =
          out.mutableTile(cx >> EvidentialGridMap::kTileBits, cy >> EvidentialGridMap::kTileBits);
      const int k = EvidentialGridMap::cellInTile(cx, cy);
      tile.cells[static_cast<size_t>(k)] = b.toCell();
      tile.cellWritten(k);
    }
  }
  if (offset != nullptr) {
    *offset = Pose2(raster.origin_x - x0 * raster.resolution,
                    raster.origin_y - y0 * raster.resolution, 0.0);
  }
  *map = std::move(out);
  return true;
}

}  // namespace fusion
}  // namespace evidential_slam
