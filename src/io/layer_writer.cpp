// Layer images, arrays and map.yaml. See layer_writer.h.
#include "evidential_slam/io/layer_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include <mrpt/img/CImage.h>
#include <Eigen/Core>

#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/npy.h"
#include "image_files.h"

namespace evidential_slam {
namespace io {
namespace {

using ByteImage = Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Raster row r (row 0 = lowest y) becomes image row height-1-r: north-up.
template <typename F>
ByteImage northUp(const LayerRaster& raster, F&& pixel_of_index) {
  ByteImage img(raster.height, raster.width);
  for (int r = 0; r < raster.height; ++r) {
    for (int c = 0; c < raster.width; ++c) {
      img(raster.height - 1 - r, c) = pixel_of_index(static_cast<size_t>(r) * raster.width + c);
    }
  }
  return img;
}

// Scale of each layer's PNG. Masses, BetP, NS, IC and H live in [0, 1] (IC and H in bits over a
// two-element frame); EC and the anomaly are unbounded and are scaled by their maximum so their
// structure stays visible.
LayerImageScale scaleFor(Layer layer, float min_value, float max_value) {
  LayerImageScale s;
  s.name = layerName(layer);
  s.min_value = min_value;
  s.max_value = max_value;
  s.white = 0.0;
  s.black = 1.0;
  if (layer == Layer::kExternalConflict || layer == Layer::kAnomaly) {
    s.black = max_value > 0.0f ? max_value : 1.0;
  }
  return s;
}

// The scale of a layer over the whole raster (EC's depends on its maximum).
LayerImageScale scaleOf(const LayerRaster& raster, Layer layer) {
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  for (float x : raster.layer(layer)) {
    if (!std::isfinite(x)) continue;
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  if (lo > hi) lo = hi = 0.0f;
  return scaleFor(layer, lo, hi);
}

// False (and `error`) when the layers' sizes (of `layers`, layerBit) do not match the raster's.
bool checkSizes(const LayerRaster& raster, std::string* error, uint32_t layers = kAllLayers) {
  const size_t cells = static_cast<size_t>(raster.width) * raster.height;
  for (int l = 0; l < kLayerCount; ++l) {
    if ((layers & layerBit(static_cast<Layer>(l))) != 0 && raster.values[l].size() != cells) {
      if (error) {
        *error = "layer '" + layerNames()[l] + "' has " + std::to_string(raster.values[l].size()) +
                 " values for a " + std::to_string(raster.width) + "x" +
                 std::to_string(raster.height) + " raster";
      }
      return false;
    }
  }
  return true;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.9g", v);
  return buf;
}

}  // namespace

// True when the file at `path` is complete: a PNG ends with its IEND chunk (OpenCV does not report
// a failed final flush, which leaves the file cut short); other formats are decoded back.
static bool imageComplete(const std::string& path, const mrpt::img::CImage& written) {
  if (path.size() >= 4 && path.compare(path.size() - 4, 4, ".png") == 0) {
    static const char kIend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', '\xae', '\x42', '\x60', '\x82'};
    std::ifstream in(path, std::ios::binary);
    char tail[12];
    return in.seekg(-12, std::ios::end) && in.read(tail, 12) && std::equal(tail, tail + 12, kIend);
  }
  mrpt::img::CImage back;
  return back.loadFromFile(path) && back.getWidth() == written.getWidth() &&
         back.getHeight() == written.getHeight();
}

bool stageImage(const mrpt::img::CImage& img, const std::string& path, AtomicFiles* files,
                std::string* error) {
  if (img.getWidth() == 0 || img.getHeight() == 0) {
    if (error != nullptr) *error = "cannot write '" + path + "': the map has no observed cell";
    return false;
  }
  // MRPT reports some failures as exceptions with a call stack: one line instead.
  std::string thrown;
  const bool ok = files->addByPath(
      path,
      [&](const std::string& temp) {
        try {
          return img.saveToFile(temp);
        } catch (const std::exception& e) {
          thrown = oneLineMessage(e.what());
          return false;
        }
      },
      [&](const std::string& temp) { return imageComplete(temp, img); }, error);
  if (!ok && !thrown.empty() && error != nullptr) *error = "cannot write '" + path + "': " + thrown;
  return ok;
}

uint8_t layerPixel(float value, const LayerImageScale& scale) {
  if (!std::isfinite(value)) return value > 0 ? 0 : 255;  // +inf as black, NaN / -inf as white
  const double t = (value - scale.white) / (scale.black - scale.white);
  const double grey = 255.0 * (1.0 - std::clamp(t, 0.0, 1.0));
  return static_cast<uint8_t>(std::lround(grey));
}

namespace {

// Stages one layer's <name>.png and <name>.npy under `base`; their paths go to `written`.
bool stagePngAndNpy(const LayerRaster& raster, Layer layer, const LayerImageScale& scale,
                    const std::string& base, AtomicFiles* files, std::vector<std::string>* written,
                    std::string* error) {
  const std::vector<float>& v = raster.layer(layer);
  mrpt::img::CImage img;
  img.setFromMatrix(northUp(raster, [&](size_t i) { return layerPixel(v[i], scale); }), false);
  const std::string png = base + layerName(layer) + ".png";
  if (!stageImage(img, png, files, error)) return false;
  written->push_back(png);

  const std::string npy = base + layerName(layer) + ".npy";
  if (!files->add(
          npy,
          [&](std::ostream& out) { return writeNpy(out, v.data(), raster.height, raster.width); },
          error)) {
    return false;
  }
  written->push_back(npy);
  return true;
}

// Stages one layer's map_server pair <name>.pgm + <name>.yaml under `base` (writeMapServerLayers).
bool stageMapServerLayer(const LayerRaster& raster, Layer layer, const LayerImageScale& scale,
                         const std::string& base, const LayerWriterConfig& config, AtomicFiles* set,
                         std::vector<std::string>* written, std::string* error) {
  const std::vector<float>& v = raster.layer(layer);
  mrpt::img::CImage img;
  img.setFromMatrix(northUp(raster, [&](size_t i) { return layerPixel(v[i], scale); }), false);
  const std::string& name = layerName(layer);
  const std::string pgm = base + name + ".pgm";
  if (!stageImage(img, pgm, set, error)) return false;
  written->push_back(pgm);

  const bool pignistic = layer == Layer::kPignistic;
  const std::string yaml_path = base + name + ".yaml";
  const bool yaml_ok = set->add(
      yaml_path,
      [&](std::ostream& yaml) {
        yaml << "# evidential_slam layer '" << name << "' for map_server: dark = high value; "
             << "pixel black = " << fmt(scale.black) << ", white = " << fmt(scale.white) << "\n"
             << "image: " << name << ".pgm\n"
             << "resolution: " << fmt(raster.resolution) << "\n"
             << "origin: [" << fmt(raster.origin_x) << ", " << fmt(raster.origin_y) << ", 0.0]\n"
             << "negate: 0\n"
             << "mode: " << (pignistic ? "trinary" : "scale") << "\n"
             << "occupied_thresh: " << fmt(pignistic ? config.occupied_thresh : 1.0) << "\n"
             << "free_thresh: " << fmt(pignistic ? config.free_thresh : 0.0) << "\n";
        return static_cast<bool>(yaml);
      },
      error);
  if (!yaml_ok) return false;
  written->push_back(yaml_path);
  return true;
}

}  // namespace

bool writeLayers(const LayerRaster& raster, const std::string& dir, const LayerWriterConfig& config,
                 LayerWriteResult* result, std::string* error, AtomicFiles* staged) {
  *result = LayerWriteResult();
  if (!checkSizes(raster, error)) return false;
  AtomicFiles own;
  AtomicFiles* files = staged ? staged : &own;
  const size_t cells = static_cast<size_t>(raster.width) * raster.height;
  const std::string base = dir.empty() || dir.back() == '/' ? dir : dir + "/";

  for (int l = 0; l < kLayerCount; ++l) {
    const Layer layer = static_cast<Layer>(l);
    const LayerImageScale scale = scaleOf(raster, layer);
    result->scales[l] = scale;
    if (layer == Layer::kExternalConflict) result->external_conflict_scale = scale.black;
    if (!stagePngAndNpy(raster, layer, scale, base, files, &result->files, error)) return false;
  }

  // Composite: a mass in [0, 1] per channel. loadFromMemoryBuffer takes separate R, G, B planes
  // and stores them in OpenCV's channel order itself (setFromRGBMatrices would not: it writes
  // R, G, B into OpenCV's B, G, R slots).
  {
    const LayerImageScale direct{"", 1.0, 0.0, 0.0f, 1.0f};  // 0 -> 0 (dark), 1 -> 255
    auto plane = [&](Layer layer) {
      const auto& v = raster.layer(layer);
      return northUp(raster, [&](size_t i) { return layerPixel(v[i], direct); });
    };
    ByteImage red = plane(Layer::kOccupied);
    ByteImage green = plane(Layer::kFree);
    ByteImage blue = plane(Layer::kUnknown);
    mrpt::img::CImage img;
    img.loadFromMemoryBuffer(raster.width, raster.height, raster.width, red.data(), green.data(),
                             blue.data());
    const std::string png = base + "composite.png";
    if (!stageImage(img, png, files, error)) return false;
    result->files.push_back(png);
  }

  {
    std::vector<uint8_t> observed = raster.observed;
    if (observed.size() != cells) observed.assign(cells, 0);
    const std::string npy = base + "observed.npy";
    if (!files->add(
            npy,
            [&](std::ostream& out) {
              return writeNpy(out, observed.data(), raster.height, raster.width);
            },
            error)) {
      return false;
    }
    result->files.push_back(npy);
  }

  const std::string yaml_path = base + "map.yaml";
  const bool yaml_ok = files->add(
      yaml_path,
      [&](std::ostream& yaml) {
        yaml << "# map_server metadata: pignistic.png holds BetP(o), dark = occupied.\n"
             << "image: pignistic.png\n"
             << "resolution: " << fmt(raster.resolution) << "\n"
             << "origin: [" << fmt(raster.origin_x) << ", " << fmt(raster.origin_y) << ", 0.0]\n"
             << "negate: 0\n"
             << "occupied_thresh: " << fmt(config.occupied_thresh) << "\n"
             << "free_thresh: " << fmt(config.free_thresh) << "\n"
             << "# evidential_slam extras (map_server ignores them).\n"
             << "width: " << raster.width << "\n"
             << "height: " << raster.height << "\n"
             << "png_layout: \"north-up 8-bit grey (image row 0 = highest y); grey = 255 * (1 - "
                "clamp((v - png_white) / (png_black - png_white), 0, 1)), so png_black is drawn "
                "black\"\n"
             << "npy_layout: \"float32 '<f4', shape (height, width), C order, row 0 = lowest y, "
                "col 0 = lowest x (nav_msgs/OccupancyGrid order); observed.npy is uint8, 1 = "
                "cell has evidence\"\n"
             << "composite: {image: composite.png, red: occupied, green: free, blue: unknown}\n"
             << "external_conflict_scale: " << fmt(result->external_conflict_scale) << "\n"
             << "layers:\n";
        for (int l = 0; l < kLayerCount; ++l) {
          const LayerImageScale& s = result->scales[l];
          yaml << "  " << s.name << ": {image: " << s.name << ".png, npy: " << s.name
               << ".npy, png_white: " << fmt(s.white) << ", png_black: " << fmt(s.black)
               << ", min: " << fmt(s.min_value) << ", max: " << fmt(s.max_value) << "}\n";
        }
        return static_cast<bool>(yaml);
      },
      error);
  if (!yaml_ok) return false;
  result->files.push_back(yaml_path);
  return staged || own.commit(error);
}

bool writeMapServerLayers(const LayerRaster& raster, const std::string& dir,
                          const LayerWriterConfig& config, std::vector<std::string>* files,
                          std::string* error, AtomicFiles* staged) {
  if (!checkSizes(raster, error)) return false;
  AtomicFiles own;
  AtomicFiles* set = staged ? staged : &own;
  const std::string base = dir.empty() || dir.back() == '/' ? dir : dir + "/";
  std::vector<std::string> written;
  for (int l = 0; l < kLayerCount; ++l) {
    const Layer layer = static_cast<Layer>(l);
    if (!stageMapServerLayer(raster, layer, scaleOf(raster, layer), base, config, set, &written,
                             error)) {
      return false;
    }
  }
  if (!staged && !own.commit(error)) return false;
  files->insert(files->end(), written.begin(), written.end());
  return true;
}

bool writeLayerFiles(const LayerRaster& raster, Layer layer, const std::string& dir,
                     const LayerWriterConfig& config, std::vector<std::string>* files,
                     std::string* error, AtomicFiles* staged) {
  if (!checkSizes(raster, error, layerBit(layer))) return false;
  AtomicFiles own;
  AtomicFiles* set = staged ? staged : &own;
  const std::string base = dir.empty() || dir.back() == '/' ? dir : dir + "/";
  std::vector<std::string> written;
  const LayerImageScale scale = scaleOf(raster, layer);
  if (!stagePngAndNpy(raster, layer, scale, base, set, &written, error) ||
      !stageMapServerLayer(raster, layer, scale, base, config, set, &written, error)) {
    return false;
  }
  if (!staged && !own.commit(error)) return false;
  files->insert(files->end(), written.begin(), written.end());
  return true;
}

}  // namespace io
}  // namespace evidential_slam
