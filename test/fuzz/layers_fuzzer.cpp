// libFuzzer target for a layer folder's readers (evidential_slam_fuse --map DIR,
// evidential_octomap_info --compare-layers): the bytes as a .npy file (parseNpy) and as the text
// of its map.yaml (parseLayerMapYaml). Refusals give a one-line printable error; an accepted .npy
// holds exactly shape x itemsize bytes within the reader's bounds, and an accepted map.yaml a
// resolution and an origin within theirs.
#include <cmath>
#include <cstdint>
#include <string>

#include "evidential_slam/io/layer_yaml.h"
#include "evidential_slam/io/npy.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace io = evidential_slam::io;
  using evidential_slam::fuzz::checkErrorLine;
  using evidential_slam::fuzz::die;

  io::NpyArray array;
  std::string error;
  if (!io::parseNpy(data, size, &array, &error)) {
    checkErrorLine(error);
  } else {
    const size_t item = array.descr == "<f4" ? 4 : 1;
    if (array.fortran_order) die("fortran_order left set", "");
    if (array.shape.size() > io::kNpyMaxDimensions) die("too many dimensions", "");
    for (size_t d : array.shape) {
      if (d > io::kNpyMaxExtent) die("dimension over the limit", std::to_string(d));
    }
    if (array.bytes.size() != item * array.elementCount() || array.bytes.size() > size) {
      die("payload size differs from the shape", array.descr);
    }
    const size_t n = item == 4 ? array.asFloat32().size() : array.asUint8().size();
    if (n != array.elementCount()) die("typed view differs from the shape", array.descr);
  }

  const std::string text(reinterpret_cast<const char*>(data), size);
  double resolution = 0.0, x = 0.0, y = 0.0;
  error.clear();
  if (!io::parseLayerMapYaml(text, "map.yaml", &resolution, &x, &y, &error)) {
    checkErrorLine(error);
  } else if (!(resolution > 0.0) || !(std::abs(x) <= io::layerExtentLimit()) ||
             !(std::abs(y) <= io::layerExtentLimit())) {
    die("map.yaml accepted out of its bounds", text.substr(0, 200));
  }
  return 0;
}
