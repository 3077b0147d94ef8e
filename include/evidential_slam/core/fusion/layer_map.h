// A map rebuilt from its layer rasters (extractLayers' output, a saved run's layers/*.npy, an
// EvidentialGrid message): the inverse of extractLayers up to the layers' float precision, so maps
// that were only published or saved as layers can be fused.
#pragma once

#include <string>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace fusion {

// Fills `map` (replaced; the raster's resolution) with the raster's observed cells: m̃ from the
// occupied, free and unknown layers normalised to sum 1, λ = EC · ln 2 from external_conflict
// (exact where m(∅) is too close to 1 for a float). Raster cell (col, row) becomes map cell
// (round(origin_x / resolution) + col, round(origin_y / resolution) + row); `offset` (may be null)
// gets what that rounding left out, the map's pose in the raster's frame (zero for a raster of
// extractLayers). False (and a one-line `why`) for a non-positive or non-finite resolution or
// origin, layers or `observed` not of width × height values, or an observed cell whose masses are
// negative, not finite or all zero.
bool mapFromLayers(const LayerRaster& raster, EvidentialGridMap* map, Pose2* offset,
                   std::string* why);

}  // namespace fusion
}  // namespace evidential_slam
