// Ground-truth occupancy images (PNG, PGM...: black = occupied, white = free, grey = unknown, as
// MRPT's and map_server's maps) read into core's plain raster, for scoring maps
// (core/fusion/map_score.h).
#pragma once

#include <string>

#include "evidential_slam/core/fusion/map_score.h"

namespace evidential_slam {
namespace io {

struct OccupancyImageConfig {
  double resolution = 0.05;  // m per pixel
  bool centered = true;      // the image's centre at the frame's origin (else origin_x/origin_y)
  double origin_x = 0.0;     // m, frame position of the image's lower-left corner
  double origin_y = 0.0;     // (map_server convention; used when !centered)
  // A pixel of grey value v has occupancy p = 1 - v/255 (MRPT's and map_server's reading):
  // occupied when p >= occupied_threshold, free when p <= free_threshold, else unknown.
  double occupied_threshold = 0.65;
  double free_threshold = 0.35;
  bool isValid(std::string* why) const;
};

// Reads `path` (MRPT's image loading, as the simulator's map). False (and a one-line `error`
// naming the file) when the file is missing or not an image MRPT can read, or the config invalid.
bool readOccupancyImage(const std::string& path, const OccupancyImageConfig& config,
                        fusion::OccupancyRaster* raster, std::string* error);

}  // namespace io
}  // namespace evidential_slam
