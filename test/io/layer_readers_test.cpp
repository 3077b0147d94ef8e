// The readers of a layer folder (layers/<layer>.npy, observed.npy, map.yaml: evidential_slam_fuse
// --map DIR, evidential_octomap_info --compare-layers) on the inputs that once crashed, hung or
// were misread (the regression seeds of test/fuzz/corpus/layers/), and on good folders.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/io/layer_yaml.h"
#include "evidential_slam/io/map_input.h"
#include "evidential_slam/io/npy.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;
using io::NpyArray;

fs::path seed(const std::string& name) { return test::dataPath("../fuzz/corpus/layers/" + name); }

void expectOneLine(const std::string& error) {
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_LT(error.size(), 400u) << error;
}

// Every input that crashed (regex stack overflow, std::stoul, a wrapped element count), allocated
// gigabytes or was misread is refused with one line that names the file and the field.
TEST(NpyReader, RefusesHostileHeadersWithOneLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"regression_header_30kB.npy", "'shape'"},
      {"regression_header_30kB_descr.npy", "header"},
      {"regression_shape_2pow62.npy", "'shape' dimension exceeds"},
      {"regression_shape_overflow_digits.npy", "'shape' dimension exceeds"},
      {"regression_descr_overflow.npy", "'descr'"},
      {"regression_v3_2GiB_header_len.npy", "header length"},
      {"regression_fortran_3d.npy", "'fortran_order'"},
      {"regression_wrong_dtype.npy", "'descr': unsupported dtype '<f8'"},
  };
  for (const auto& [name, field] : cases) {
    NpyArray a;
    std::string error;
    EXPECT_FALSE(io::readNpy(seed(name).string(), &a, &error)) << name;
    expectOneLine(error);
    EXPECT_NE(error.find(name), std::string::npos) << error;
    EXPECT_NE(error.find(field), std::string::npos) << name << ": " << error;
  }
}

// shape x itemsize is checked against what the file holds, both ways.
TEST(NpyReader, PayloadMustMatchTheShape) {
  const fs::path dir = test::scratchDir();
  const std::vector<float> v = {1, 2, 3, 4, 5, 6};
  std::string error;
  ASSERT_TRUE(io::writeNpy((dir / "a.npy").string(), v.data(), 2, 3, &error)) << error;
  const std::string good = test::readText(dir / "a.npy");
  test::writeText(dir / "short.npy", good.substr(0, good.size() - 1));
  test::writeText(dir / "long.npy", good + "x");
  for (const char* name : {"short.npy", "long.npy"}) {
    NpyArray a;
    EXPECT_FALSE(io::readNpy((dir / name).string(), &a, &error)) << name;
    expectOneLine(error);
    EXPECT_NE(error.find("24 bytes of data expected"), std::string::npos) << error;
  }
  NpyArray a;
  ASSERT_TRUE(io::readNpy((dir / "a.npy").string(), &a, &error)) << error;
  EXPECT_EQ(a.asFloat32(), v);
}

// numpy's other spellings: versions 2 and 3, double quotes, no trailing comma, Fortran order
// (returned in C order).
TEST(NpyReader, ReadsWhatNumpyWrites) {
  NpyArray c, f, v2, v3, dq;
  std::string error;
  ASSERT_TRUE(io::readNpy(seed("float32_2x3.npy").string(), &c, &error)) << error;
  ASSERT_TRUE(io::readNpy(seed("fortran_2x3.npy").string(), &f, &error)) << error;
  EXPECT_EQ(f.shape, (std::vector<size_t>{2, 3}));
  EXPECT_FALSE(f.fortran_order);
  EXPECT_EQ(f.asFloat32(), c.asFloat32());
  ASSERT_TRUE(io::readNpy(seed("float32_v2.npy").string(), &v2, &error)) << error;
  ASSERT_TRUE(io::readNpy(seed("float32_v3_utf8.npy").string(), &v3, &error)) << error;
  EXPECT_EQ(v3.shape, (std::vector<size_t>{2, 1}));
  ASSERT_TRUE(io::readNpy(seed("double_quotes_no_trailing_comma.npy").string(), &dq, &error))
      << error;
  EXPECT_EQ(dq.asFloat32(), std::vector<float>{1.0f});
}

// map.yaml: a far origin (once a hang), duplicate keys, two documents, a quoted number and a
// rotation are refused with one line naming the field.
TEST(LayerMapYaml, RefusesWhatItCannotTrust) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"regression_map_origin_far.yaml", "'origin'"},
      {"regression_map_duplicate_key.yaml", "duplicate key 'resolution'"},
      {"regression_map_two_documents.yaml", "2 YAML documents"},
      {"regression_map_quoted_number.yaml", "'resolution' is '5', quoted text"},
      {"regression_map_rotated.yaml", "rotated"},
  };
  for (const auto& [name, field] : cases) {
    double res = 0, x = 0, y = 0;
    std::string error;
    EXPECT_FALSE(io::readLayerMapYaml(seed(name).string(), &res, &x, &y, &error)) << name;
    expectOneLine(error);
    EXPECT_NE(error.find(name), std::string::npos) << error;
    EXPECT_NE(error.find(field), std::string::npos) << name << ": " << error;
  }
  double res = 0, x = 0, y = 0;
  std::string error;
  // yaml-cpp's LoadAll never returns on these (found by layers_fuzzer): refused at once.
  for (const char* text : {",", ", a", "\"a\",", "resolution: 0.05\n---\nresolution: 1\n"}) {
    EXPECT_FALSE(io::parseLayerMapYaml(text, "map.yaml", &res, &x, &y, &error)) << text;
    expectOneLine(error);
  }
  EXPECT_TRUE(io::parseLayerMapYaml("---\nresolution: 0.05\norigin: [0, 0]\n...\n", "map.yaml",
                                    &res, &x, &y, &error))
      << error;
  ASSERT_TRUE(io::readLayerMapYaml(seed("map.yaml").string(), &res, &x, &y, &error)) << error;
  EXPECT_EQ(res, 0.05);
  EXPECT_EQ(x, -1.25);
  EXPECT_EQ(y, -2.5);
}

// A folder whose layers reach past the extent limit from a legal origin is refused before any
// map is built; one whose layers disagree in shape too.
TEST(LayerDirectory, RefusesRastersBeyondTheExtentLimitAndMixedShapes) {
  const fs::path dir = test::scratchDir();
  const int rows = 2, cols = 3;
  const std::vector<float> mass(rows * cols, 1.0f / 3.0f), zero(rows * cols, 0.0f);
  const std::vector<uint8_t> observed(rows * cols, 1);
  std::string error;
  for (const Layer l : {Layer::kOccupied, Layer::kFree, Layer::kUnknown}) {
    ASSERT_TRUE(
        io::writeNpy((dir / (layerName(l) + ".npy")).string(), mass.data(), rows, cols, &error));
  }
  ASSERT_TRUE(io::writeNpy((dir / (layerName(Layer::kExternalConflict) + ".npy")).string(),
                           zero.data(), rows, cols, &error));
  ASSERT_TRUE(io::writeNpy((dir / "observed.npy").string(), observed.data(), rows, cols, &error));
  test::writeText(dir / "map.yaml", "resolution: 0.05\norigin: [0.5, -0.25, 0]\n");
  LayerRaster raster;
  ASSERT_TRUE(io::readLayerDirectory(dir.string(), &raster, &error)) << error;
  EXPECT_EQ(raster.width, cols);

  const double edge = io::layerExtentLimit() - 0.05;  // the origin is legal, the far corner not
  test::writeText(dir / "map.yaml",
                  "resolution: 0.05\norigin: [" + std::to_string(edge) + ", 0, 0]\n");
  EXPECT_FALSE(io::readLayerDirectory(dir.string(), &raster, &error));
  expectOneLine(error);
  EXPECT_NE(error.find("reaches farther than"), std::string::npos) << error;

  test::writeText(dir / "map.yaml", "resolution: 0.05\norigin: [0, 0, 0]\n");
  ASSERT_TRUE(io::writeNpy((dir / "observed.npy").string(), observed.data(), cols, rows, &error));
  EXPECT_FALSE(io::readLayerDirectory(dir.string(), &raster, &error));
  expectOneLine(error);
  EXPECT_NE(error.find("observed.npy"), std::string::npos) << error;
}

}  // namespace
}  // namespace evidential_slam
