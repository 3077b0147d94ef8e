// trajectory.png: the path over the pignistic map (BetP(o), dark = occupied), what a user looks at
// first after a run. The estimate is drawn in red from a green start dot to a red end dot; a
// reference path (ground truth brought into the map frame) in blue underneath; a caption (e.g. the
// ATE) in the top-left corner. Poses outside the raster are clipped.
#pragma once

#include <string>
#include <vector>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace io {

class AtomicFiles;

struct TrajectoryImage {
  std::vector<Pose2> path;       // map frame
  std::vector<Pose2> reference;  // map frame; empty: none drawn
  std::string caption;           // empty: none
};

// Pixel (column, row of a north-up image) of the map-frame point (x, y) on `raster`.
void trajectoryPixel(const LayerRaster& raster, double x, double y, int* column, int* row);

// Writes `image` over `raster`'s pignistic layer as an RGB PNG at `path` (staged into `files` when
// given, else written at once). False (and a one-line `error`) when it cannot be written.
bool writeTrajectoryImage(const LayerRaster& raster, const TrajectoryImage& image,
                          const std::string& path, std::string* error,
                          AtomicFiles* files = nullptr);

}  // namespace io
}  // namespace evidential_slam
