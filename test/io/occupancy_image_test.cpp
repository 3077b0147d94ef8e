// Ground-truth occupancy images into core's raster: size, placement, classes, and clear errors.
#include "evidential_slam/io/occupancy_image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

using fusion::CellClass;

size_t count(const fusion::OccupancyRaster& r, CellClass c) {
  return static_cast<size_t>(std::count(r.cells.begin(), r.cells.end(), c));
}

// test/data/sim_map.png: 320 x 240 pixels, walls 0 and free 255 only (5444 and 71356 of them, as
// counted by PIL); its top-left pixel is a wall, pixel (5, 5) from the top left is free.
TEST(OccupancyImage, ReadsTheFixtureCentredOnTheOrigin) {
  fusion::OccupancyRaster r;
  std::string error;
  ASSERT_TRUE(readOccupancyImage(std::string(ES_TEST_DATA_DIR) + "/sim_map.png",
                                 OccupancyImageConfig{}, &r, &error))
      << error;
  EXPECT_EQ(r.width, 320);
  EXPECT_EQ(r.height, 240);
  EXPECT_DOUBLE_EQ(r.resolution, 0.05);
  EXPECT_DOUBLE_EQ(r.origin_x, -8.0);
  EXPECT_DOUBLE_EQ(r.origin_y, -6.0);
  EXPECT_EQ(count(r, CellClass::kOccupied), 5444u);
  EXPECT_EQ(count(r, CellClass::kFree), 71356u);
  EXPECT_EQ(count(r, CellClass::kUnknown), 0u);
  EXPECT_EQ(r.at(0, 239), CellClass::kOccupied);  // image row 0 is the raster's top row
  EXPECT_EQ(r.at(5, 234), CellClass::kFree);
  std::string why;
  EXPECT_TRUE(r.isValid(&why)) << why;
}

TEST(OccupancyImage, PlacesAnUncentredImageAtItsOrigin) {
  OccupancyImageConfig config;
  config.centered = false;
  config.origin_x = 1.5;
  config.origin_y = -2.0;
  config.resolution = 0.1;
  fusion::OccupancyRaster r;
  std::string error;
  ASSERT_TRUE(
      readOccupancyImage(std::string(ES_TEST_DATA_DIR) + "/sim_map.png", config, &r, &error));
  EXPECT_DOUBLE_EQ(r.origin_x, 1.5);
  EXPECT_DOUBLE_EQ(r.origin_y, -2.0);
  EXPECT_DOUBLE_EQ(r.resolution, 0.1);
}

// MRPT's basic_map.png (0.2 m/pixel): grey 123 is unknown (p = 0.52). With p >= 0.65 occupied and
// p <= 0.35 free, PIL counts 32461 occupied, 76296 free and 147243 unknown pixels.
TEST(OccupancyImage, GreyIsUnknown) {
  const std::string path = "/usr/share/mrpt/datasets/graphslam-engine-demos/basic_map.png";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not installed";
  OccupancyImageConfig config;
  config.resolution = 0.2;
  fusion::OccupancyRaster r;
  std::string error;
  ASSERT_TRUE(readOccupancyImage(path, config, &r, &error)) << error;
  EXPECT_EQ(r.width, 640);
  EXPECT_EQ(r.height, 400);
  EXPECT_EQ(count(r, CellClass::kOccupied), 32461u);
  EXPECT_EQ(count(r, CellClass::kFree), 76296u);
  EXPECT_EQ(count(r, CellClass::kUnknown), 147243u);
}

TEST(OccupancyImage, RefusesMissingFilesNonImagesAndBadConfig) {
  fusion::OccupancyRaster r;
  std::string error;
  EXPECT_FALSE(readOccupancyImage("/nonexistent/map.png", OccupancyImageConfig{}, &r, &error));
  EXPECT_EQ(error, "ground-truth image '/nonexistent/map.png' does not exist or is not a file");
  const std::string text = std::string(ES_TEST_DATA_DIR) + "/sim.GT.txt";
  EXPECT_FALSE(readOccupancyImage(text, OccupancyImageConfig{}, &r, &error));
  EXPECT_EQ(error, "cannot read ground-truth image '" + text + "' (not an image MRPT can read)");
  OccupancyImageConfig config;
  config.free_threshold = 0.7;
  EXPECT_FALSE(readOccupancyImage(text, config, &r, &error));
  EXPECT_EQ(error, "ground-truth image '" + text +
                       "': thresholds must satisfy 0 <= free_threshold < occupied_threshold <= 1");
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
