#include "evidential_slam/io/occupancy_image.h"

#include <cmath>
#include <exception>
#include <filesystem>

#include <mrpt/img/CImage.h>

namespace evidential_slam {
namespace io {

bool OccupancyImageConfig::isValid(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!(resolution > 0.0)) return fail("resolution must be > 0");
  if (!std::isfinite(origin_x) || !std::isfinite(origin_y)) return fail("origin must be finite");
  if (!(free_threshold >= 0.0 && free_threshold < occupied_threshold &&
        occupied_threshold <= 1.0)) {
    return fail("thresholds must satisfy 0 <= free_threshold < occupied_threshold <= 1");
  }
  return true;
}

bool readOccupancyImage(const std::string& path, const OccupancyImageConfig& config,
                        fusion::OccupancyRaster* raster, std::string* error) {
  std::string reason;
  if (!config.isValid(&reason)) {
    *error = "ground-truth image '" + path + "': " + reason;
    return false;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    *error = "ground-truth image '" + path + "' does not exist or is not a file";
    return false;
  }
  mrpt::img::CImage image;
  bool ok = false;
  try {
    ok = image.loadFromFile(path, 0 /* grey */) && image.getWidth() > 0 && image.getHeight() > 0;
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok) {
    *error = "cannot read ground-truth image '" + path + "' (not an image MRPT can read)";
    return false;
  }
  fusion::OccupancyRaster r;
  r.resolution = config.resolution;
  r.width = static_cast<int>(image.getWidth());
  r.height = static_cast<int>(image.getHeight());
  r.origin_x = config.centered ? -0.5 * r.width * r.resolution : config.origin_x;
  r.origin_y = config.centered ? -0.5 * r.height * r.resolution : config.origin_y;
  r.cells.resize(static_cast<size_t>(r.width) * static_cast<size_t>(r.height));
  for (int row = 0; row < r.height; ++row) {
    // Image row 0 is the top: the raster's highest row.
    const unsigned image_row = static_cast<unsigned>(r.height - 1 - row);
    for (int col = 0; col < r.width; ++col) {
      const double p = 1.0 - image.at<uint8_t>(static_cast<unsigned>(col), image_row) / 255.0;
      fusion::CellClass c = fusion::CellClass::kUnknown;
      if (p >= config.occupied_threshold) c = fusion::CellClass::kOccupied;
      if (p <= config.free_threshold) c = fusion::CellClass::kFree;
      const size_t k = static_cast<size_t>(row) * static_cast<size_t>(r.width);
      r.cells[k + static_cast<size_t>(col)] = c;
    }
  }
  *raster = std::move(r);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
