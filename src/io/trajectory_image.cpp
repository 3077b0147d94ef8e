// trajectory.png. See trajectory_image.h.
#include "evidential_slam/io/trajectory_image.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <mrpt/img/CImage.h>
#include <mrpt/img/TColor.h>

#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/layer_writer.h"
#include "image_files.h"

namespace evidential_slam {
namespace io {
namespace {

const mrpt::img::TColor kPath(220, 20, 20);
const mrpt::img::TColor kReference(40, 90, 230);
const mrpt::img::TColor kStart(20, 170, 40);

void drawPath(mrpt::img::CImage* img, const LayerRaster& raster, const std::vector<Pose2>& path,
              const mrpt::img::TColor& color, unsigned width) {
  int c0 = 0, r0 = 0;
  for (size_t i = 0; i < path.size(); ++i) {
    int c = 0, r = 0;
    trajectoryPixel(raster, path[i].x, path[i].y, &c, &r);
    if (i > 0) img->line(c0, r0, c, r, color, width);  // OpenCV clips to the image
    c0 = c;
    r0 = r;
  }
}

}  // namespace

void trajectoryPixel(const LayerRaster& raster, double x, double y, int* column, int* row) {
  *column = static_cast<int>(std::floor((x - raster.origin_x) / raster.resolution));
  *row =
      raster.height - 1 - static_cast<int>(std::floor((y - raster.origin_y) / raster.resolution));
}

bool writeTrajectoryImage(const LayerRaster& raster, const TrajectoryImage& image,
                          const std::string& path, std::string* error, AtomicFiles* staged) {
  if (raster.width <= 0 || raster.height <= 0) {
    if (error != nullptr) *error = "cannot write '" + path + "': the map has no observed cell";
    return false;
  }
  AtomicFiles own;
  AtomicFiles* files = staged != nullptr ? staged : &own;
  const LayerImageScale betp{"", 0.0, 1.0, 0.0f, 1.0f};  // the pignistic layer's grey levels
  const std::vector<float>& v = raster.layer(Layer::kPignistic);
  std::vector<uint8_t> grey(static_cast<size_t>(raster.width) * raster.height, 128);
  for (int r = 0; r < raster.height; ++r) {
    for (int c = 0; c < raster.width; ++c) {
      const size_t i = static_cast<size_t>(r) * raster.width + c;
      if (i < v.size()) {
        grey[static_cast<size_t>(raster.height - 1 - r) * raster.width + c] =
            layerPixel(v[i], betp);
      }
    }
  }
  mrpt::img::CImage img;
  img.loadFromMemoryBuffer(raster.width, raster.height, raster.width, grey.data(), grey.data(),
                           grey.data());
  // Lines about 0.1 m wide, at least a pixel, so the path shows on large maps.
  const unsigned width =
      static_cast<unsigned>(std::max(1.0, std::round(0.1 / std::max(raster.resolution, 1e-6))));
  drawPath(&img, raster, image.reference, kReference, width);
  drawPath(&img, raster, image.path, kPath, width);
  if (!image.path.empty()) {
    int c = 0, r = 0;
    trajectoryPixel(raster, image.path.front().x, image.path.front().y, &c, &r);
    img.drawCircle(c, r, static_cast<int>(2 * width + 1), kStart, 2 * width);
    trajectoryPixel(raster, image.path.back().x, image.path.back().y, &c, &r);
    img.drawCircle(c, r, static_cast<int>(2 * width + 1), kPath, 2 * width);
  }
  if (!image.caption.empty()) {
    img.selectTextFont("6x13");
    const int w = 6 * static_cast<int>(image.caption.size()) + 6;
    img.filledRectangle(0, 0, w, 16, mrpt::img::TColor(255, 255, 255));
    img.textOut(3, 2, image.caption, mrpt::img::TColor(0, 0, 0));
  }
  if (!stageImage(img, path, files, error)) return false;
  return staged != nullptr || own.commit(error);
}

}  // namespace io
}  // namespace evidential_slam
