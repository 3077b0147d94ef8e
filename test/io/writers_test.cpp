// Output writers read back: TUM trajectory, .npy arrays, layer PNGs (decoded here with zlib, not
// with the library that wrote them, so orientation, grey mapping and channel order are checked
// independently), map.yaml, summary.json and the progress line.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "child_process.h"
#include "evidential_slam/io/layer_writer.h"
#include "evidential_slam/io/npy.h"
#include "evidential_slam/io/progress.h"
#include "evidential_slam/io/summary.h"
#include "evidential_slam/io/trajectory_image.h"
#include "evidential_slam/io/trajectory_io.h"
#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

// --- a minimal PNG decoder (8-bit grey or RGB, not interlaced) ----------------------------------
struct Png {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;  // row-major, top row first
  const uint8_t* at(int row, int col) const { return &pixels[(row * width + col) * channels]; }
};

uint32_t be32(const uint8_t* p) { return (p[0] << 24) | (p[1] << 16) | (p[2] << 8) | p[3]; }

bool decodePng(const std::string& path, Png* png) {
  const std::string data = test::readText(path);
  const auto* p = reinterpret_cast<const uint8_t*>(data.data());
  if (data.size() < 8 || std::memcmp(p, "\x89PNG\r\n\x1a\n", 8) != 0) return false;
  std::vector<uint8_t> idat;
  int color_type = -1;
  for (size_t off = 8; off + 12 <= data.size();) {
    const uint32_t len = be32(p + off);
    const std::string type(data.data() + off + 4, 4);
    const uint8_t* body = p + off + 8;
    if (type == "IHDR") {
      png->width = static_cast<int>(be32(body));
      png->height = static_cast<int>(be32(body + 4));
      if (body[8] != 8 || body[12] != 0) return false;  // 8 bit, not interlaced
      color_type = body[9];
    } else if (type == "IDAT") {
      idat.insert(idat.end(), body, body + len);
    }
    off += 12 + len;
  }
  png->channels = color_type == 0 ? 1 : color_type == 2 ? 3 : 0;
  if (png->channels == 0) return false;
  const size_t stride = static_cast<size_t>(png->width) * png->channels;
  std::vector<uint8_t> raw((stride + 1) * png->height);
  uLongf raw_len = raw.size();
  if (uncompress(raw.data(), &raw_len, idat.data(), idat.size()) != Z_OK) return false;
  png->pixels.assign(stride * png->height, 0);
  const int bpp = png->channels;
  for (int r = 0; r < png->height; ++r) {
    const uint8_t filter = raw[r * (stride + 1)];
    const uint8_t* in = &raw[r * (stride + 1) + 1];
    uint8_t* out = &png->pixels[r * stride];
    const uint8_t* up = r > 0 ? &png->pixels[(r - 1) * stride] : nullptr;
    for (size_t i = 0; i < stride; ++i) {
      const int a = i >= static_cast<size_t>(bpp) ? out[i - bpp] : 0;
      const int b = up ? up[i] : 0;
      const int c = (up && i >= static_cast<size_t>(bpp)) ? up[i - bpp] : 0;
      int pred = 0;
      switch (filter) {
        case 0:
          pred = 0;
          break;
        case 1:
          pred = a;
          break;
        case 2:
          pred = b;
          break;
        case 3:
          pred = (a + b) / 2;
          break;
        case 4: {
          const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
          pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
          break;
        }
        default:
          return false;
      }
      out[i] = static_cast<uint8_t>(in[i] + pred);
    }
  }
  return true;
}

// --- TUM ----------------------------------------------------------------------------------------

TEST(TumTrajectory, WritesOneLinePerPoseAndReadsBack) {
  const auto path = (test::scratchDir() / "traj.tum").string();
  std::vector<StampedPose> poses = {{1000.0, Pose2(0, 0, 0)},
                                    {1000.25, Pose2(1.5, -2.0, M_PI / 2)},
                                    {1000.5, Pose2(-3.0, 4.0, -3.0)},
                                    {1001.0, Pose2(0.1, 0.2, M_PI)}};
  std::string error;
  ASSERT_TRUE(writeTumTrajectory(path, poses, &error)) << error;
  // Format: 8 columns, z = 0, unit yaw quaternion.
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::vector<double> v;
    double x;
    while (ss >> x) v.push_back(x);
    ASSERT_EQ(v.size(), 8u) << line;
    EXPECT_EQ(v[3], 0.0);
    EXPECT_EQ(v[4], 0.0);
    EXPECT_EQ(v[5], 0.0);
    EXPECT_NEAR(v[6] * v[6] + v[7] * v[7], 1.0, 1e-8);
    ++lines;
  }
  EXPECT_EQ(lines, 4);
  std::vector<StampedPose> back;
  ASSERT_TRUE(readTumTrajectory(path, &back, &error)) << error;
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(back[i].stamp, poses[i].stamp, 1e-6);
    EXPECT_NEAR(back[i].pose.x, poses[i].pose.x, 1e-6);
    EXPECT_NEAR(back[i].pose.y, poses[i].pose.y, 1e-6);
    EXPECT_NEAR(std::remainder(back[i].pose.theta - poses[i].pose.theta, 2 * M_PI), 0.0, 1e-8);
  }
  EXPECT_FALSE(writeTumTrajectory("/nonexistent/dir/t.tum", poses, &error));
}

// --- npy ----------------------------------------------------------------------------------------

TEST(Npy, Float32RoundTripWithAlignedHeader) {
  const auto path = (test::scratchDir() / "a.npy").string();
  std::vector<float> values(3 * 5);
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.5f * static_cast<float>(i) - 2.0f;
  values[7] = std::numeric_limits<float>::infinity();
  std::string error;
  ASSERT_TRUE(writeNpy(path, values.data(), 3, 5, &error)) << error;
  const std::string bytes = test::readText(path);
  ASSERT_GE(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const size_t header_len = static_cast<uint8_t>(bytes[8]) | (static_cast<uint8_t>(bytes[9]) << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u);
  EXPECT_EQ(bytes[10 + header_len - 1], '\n');
  EXPECT_NE(bytes.find("'descr': '<f4', 'fortran_order': False, 'shape': (3, 5)"),
            std::string::npos);
  EXPECT_EQ(bytes.size(), 10 + header_len + 4 * values.size());

  NpyArray array;
  ASSERT_TRUE(readNpy(path, &array, &error)) << error;
  EXPECT_EQ(array.descr, "<f4");
  EXPECT_FALSE(array.fortran_order);
  EXPECT_EQ(array.shape, (std::vector<size_t>{3, 5}));
  EXPECT_EQ(array.asFloat32(), values);
  EXPECT_TRUE(array.asUint8().empty());
}

TEST(Npy, Uint8RoundTripAndBadFiles) {
  const auto dir = test::scratchDir();
  const std::vector<uint8_t> values = {0, 1, 1, 0, 255, 7};
  std::string error;
  ASSERT_TRUE(writeNpy((dir / "u.npy").string(), values.data(), 2, 3, &error)) << error;
  NpyArray array;
  ASSERT_TRUE(readNpy((dir / "u.npy").string(), &array, &error)) << error;
  EXPECT_EQ(array.descr, "|u1");
  EXPECT_EQ(array.shape, (std::vector<size_t>{2, 3}));
  EXPECT_EQ(array.asUint8(), values);

  test::writeText(dir / "bad.npy", "not numpy");
  EXPECT_FALSE(readNpy((dir / "bad.npy").string(), &array, &error));
  std::string truncated = test::readText(dir / "u.npy");
  truncated.pop_back();
  test::writeText(dir / "short.npy", truncated);
  EXPECT_FALSE(readNpy((dir / "short.npy").string(), &array, &error));
}

// --- layers -------------------------------------------------------------------------------------

// A 4 x 3 raster whose cells hold pure masses, so every layer value is known.
LayerRaster syntheticRaster() {
  LayerRaster r;
  r.resolution = 0.05;
  r.origin_x = -1.25;
  r.origin_y = 2.5;
  r.width = 4;
  r.height = 3;
  const size_t n = 12;
  for (auto& v : r.values) v.assign(n, 0.0f);
  r.observed.assign(n, 1);
  auto set = [&](int row, int col, float occ, float fre, float unk, float conf, float ec) {
    const size_t i = static_cast<size_t>(row) * r.width + col;
    r.values[static_cast<int>(Layer::kOccupied)][i] = occ;
    r.values[static_cast<int>(Layer::kFree)][i] = fre;
    r.values[static_cast<int>(Layer::kUnknown)][i] = unk;
    r.values[static_cast<int>(Layer::kConflict)][i] = conf;
    r.values[static_cast<int>(Layer::kPignistic)][i] = occ + 0.5f * unk;
    r.values[static_cast<int>(Layer::kNonspecificity)][i] = unk;
    r.values[static_cast<int>(Layer::kExternalConflict)][i] = ec;
  };
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) set(row, col, 0, 0, 1, 0, 0);
  }
  for (size_t i = 0; i < n; ++i) r.observed[i] = 0;
  r.values[static_cast<int>(Layer::kAnomaly)][1] = 6.0f;          // row 0 (bottom), col 1
  r.values[static_cast<int>(Layer::kAnomaly)][1 * 4 + 2] = 1.5f;  // row 1, col 2
  set(0, 0, 1, 0, 0, 0, 0);                                       // lowest y, lowest x: occupied
  r.observed[0] = 1;
  set(0, 1, 0, 1, 0, 0, 0);  // free
  r.observed[1] = 1;
  set(2, 3, 0, 0, 0, 1, 4.0f);  // highest y, highest x: total conflict, EC max
  r.observed[11] = 1;
  set(1, 2, 0.25f, 0.25f, 0.25f, 0.25f, 2.0f);
  r.observed[6] = 1;
  return r;
}

TEST(LayerWriter, PixelMapping) {
  LayerImageScale unit{"x", 0.0, 1.0, 0.0f, 1.0f};
  EXPECT_EQ(layerPixel(0.0f, unit), 255);
  EXPECT_EQ(layerPixel(1.0f, unit), 0);
  EXPECT_EQ(layerPixel(0.5f, unit), 128);
  EXPECT_EQ(layerPixel(-3.0f, unit), 255);
  EXPECT_EQ(layerPixel(7.0f, unit), 0);
  EXPECT_EQ(layerPixel(std::numeric_limits<float>::quiet_NaN(), unit), 255);
  LayerImageScale ec{"ec", 0.0, 4.0, 0.0f, 4.0f};
  EXPECT_EQ(layerPixel(2.0f, ec), 128);
}

TEST(LayerWriter, WritesAllFilesNorthUpDarkIsHigh) {
  const auto dir = test::scratchDir();
  const LayerRaster raster = syntheticRaster();
  LayerWriteResult result;
  std::string error;
  ASSERT_TRUE(writeLayers(raster, dir.string(), LayerWriterConfig(), &result, &error)) << error;
  EXPECT_EQ(result.files.size(), kLayerCount * 2u + 1 + 1 + 1);
  EXPECT_DOUBLE_EQ(result.external_conflict_scale, 4.0);

  for (int l = 0; l < kLayerCount; ++l) {
    const std::string name = layerNames()[l];
    NpyArray array;
    ASSERT_TRUE(readNpy((dir / (name + ".npy")).string(), &array, &error)) << error;
    EXPECT_EQ(array.shape, (std::vector<size_t>{3, 4})) << name;
    EXPECT_EQ(array.asFloat32(), raster.values[l]) << name;
    Png png;
    ASSERT_TRUE(decodePng((dir / (name + ".png")).string(), &png)) << name;
    EXPECT_EQ(png.width, 4);
    EXPECT_EQ(png.height, 3);
    EXPECT_EQ(png.channels, 1);
  }
  NpyArray observed;
  ASSERT_TRUE(readNpy((dir / "observed.npy").string(), &observed, &error)) << error;
  EXPECT_EQ(observed.asUint8(), raster.observed);

  // North-up: raster row 0 (lowest y) is the bottom image row. Dark = high.
  Png occ;
  ASSERT_TRUE(decodePng((dir / "occupied.png").string(), &occ));
  EXPECT_EQ(occ.at(2, 0)[0], 0);    // the occupied cell, bottom left
  EXPECT_EQ(occ.at(0, 0)[0], 255);  // top left: nothing
  Png ec;
  ASSERT_TRUE(decodePng((dir / "external_conflict.png").string(), &ec));
  EXPECT_EQ(ec.at(0, 3)[0], 0);    // EC = max, top right
  EXPECT_EQ(ec.at(1, 2)[0], 128);  // EC = max / 2
  EXPECT_EQ(ec.at(2, 0)[0], 255);
  // The anomaly, unbounded too, is scaled by its own maximum: 6 bits black, 1.5 bits 3/4 white.
  Png anomaly;
  ASSERT_TRUE(decodePng((dir / "anomaly.png").string(), &anomaly));
  EXPECT_EQ(anomaly.at(2, 1)[0], 0);
  EXPECT_EQ(anomaly.at(1, 2)[0], 191);
  EXPECT_EQ(anomaly.at(0, 0)[0], 255);

  // Composite RGB = (m(o), m(e), m(Θ)); conflict is black.
  Png comp;
  ASSERT_TRUE(decodePng((dir / "composite.png").string(), &comp));
  ASSERT_EQ(comp.channels, 3);
  auto rgb = [&](int row, int col) {
    const uint8_t* p = comp.at(row, col);
    return std::vector<int>{p[0], p[1], p[2]};
  };
  EXPECT_EQ(rgb(2, 0), (std::vector<int>{255, 0, 0}));  // occupied: red
  EXPECT_EQ(rgb(2, 1), (std::vector<int>{0, 255, 0}));  // free: green
  EXPECT_EQ(rgb(0, 0), (std::vector<int>{0, 0, 255}));  // unknown: blue
  EXPECT_EQ(rgb(0, 3), (std::vector<int>{0, 0, 0}));    // conflict: black

  // map.yaml: map_server keys plus the layer scales.
  const std::string yaml = test::readText(dir / "map.yaml");
  for (const std::string key :
       {"image: pignistic.png\n", "resolution: 0.05\n", "origin: [-1.25, 2.5, 0.0]\n",
        "negate: 0\n", "occupied_thresh: 0.65\n", "free_thresh: 0.196\n", "width: 4\n",
        "height: 3\n", "npy_layout:", "png_layout:", "external_conflict_scale: 4\n",
        "  external_conflict: {image: external_conflict.png, npy: external_conflict.npy, "
        "png_white: 0, png_black: 4, min: 0, max: 4}\n"}) {
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
  }
  for (const std::string& name : layerNames()) {
    EXPECT_NE(yaml.find("  " + name + ": {image: " + name + ".png"), std::string::npos) << name;
  }
}

TEST(LayerWriter, RejectsInconsistentRasterAndBadDirectory) {
  LayerRaster raster = syntheticRaster();
  LayerWriteResult result;
  std::string error;
  EXPECT_FALSE(writeLayers(raster, "/nonexistent/dir", LayerWriterConfig(), &result, &error));
  EXPECT_FALSE(error.empty());
  raster.values[3].pop_back();
  EXPECT_FALSE(
      writeLayers(raster, test::scratchDir().string(), LayerWriterConfig(), &result, &error));
  EXPECT_NE(error.find("conflict"), std::string::npos) << error;
}

// A 100 x 100 raster of one value in every layer (40 kB per .npy, 10 kB per .pgm).
LayerRaster uniformRaster(float value) {
  LayerRaster r;
  r.resolution = 0.1;
  r.width = r.height = 100;
  for (auto& v : r.values) v.assign(100 * 100, value);
  r.observed.assign(100 * 100, 1);
  return r;
}

// Name -> size and a hash of the content of every file in `dir`.
std::map<std::string, std::pair<size_t, size_t>> contentsOf(const fs::path& dir) {
  std::map<std::string, std::pair<size_t, size_t>> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string content = test::readText(e.path());
    files[e.path().filename().string()] = {content.size(), std::hash<std::string>()(content)};
  }
  return files;
}

// A save that fails halfway (here: files may not grow past 20 kB, or 8 kB for the map_server
// pairs, as on a full disk) leaves every file of the previous save as it was, and no temporary
// file; the error says why.
TEST(LayerWriter, AFailedSaveLeavesThePreviousFiles) {
  const auto dir = test::scratchDir();
  std::string error;
  LayerWriteResult result;
  std::vector<std::string> pairs;
  ASSERT_TRUE(writeLayers(uniformRaster(0.2f), dir.string(), LayerWriterConfig(), &result, &error))
      << error;
  ASSERT_TRUE(
      writeMapServerLayers(uniformRaster(0.2f), dir.string(), LayerWriterConfig(), &pairs, &error))
      << error;
  const auto before = contentsOf(dir);
  // Each layer as PNG + NPY with composite.png, observed.npy and map.yaml; each as a PGM + YAML.
  ASSERT_EQ(before.size(), (2u * kLayerCount + 3u) + 2u * kLayerCount);
  for (int writer = 0; writer < 2; ++writer) {
    const int status = test::runInChild(
        [&] {
          std::string why;
          LayerWriteResult r;
          std::vector<std::string> files;
          const bool ok = writer == 0 ? writeLayers(uniformRaster(0.7f), dir.string(),
                                                    LayerWriterConfig(), &r, &why)
                                      : writeMapServerLayers(uniformRaster(0.7f), dir.string(),
                                                             LayerWriterConfig(), &files, &why);
          if (ok) return 1;
          // OpenCV's PGM writer reports success over a file cut short: the read-back check
          // catches it.
          const std::string reason =
              writer == 0 ? "': File too large" : "': the file came out incomplete (disk full?)";
          const bool named = why.find("cannot write '" + dir.string()) == 0;
          return named && why.find(reason) != std::string::npos ? 0 : 2;
        },
        writer == 0 ? 20000 : 8000);
    EXPECT_EQ(status, 0) << "writer " << writer;
    EXPECT_EQ(contentsOf(dir), before) << "writer " << writer;
  }
}

// map_server pairs: a binary PGM (P5) per layer, north-up, dark = high, and its YAML: trinary
// mode with the configured thresholds for the pignistic map, linear scale mode for the others.
TEST(LayerWriter, WritesMapServerPgmAndYamlPerLayer) {
  const auto dir = test::scratchDir();
  const LayerRaster raster = syntheticRaster();
  std::vector<std::string> files;
  std::string error;
  ASSERT_TRUE(writeMapServerLayers(raster, dir.string(), LayerWriterConfig(), &files, &error))
      << error;
  EXPECT_EQ(files.size(), 2u * kLayerCount);
  for (const std::string& name : layerNames()) {
    const std::string pgm = test::readText(dir / (name + ".pgm"));
    ASSERT_GE(pgm.size(), 12u) << name;
    std::istringstream header(pgm);
    std::string magic;
    int width = 0, height = 0, maxval = 0;
    header >> magic >> width >> height >> maxval;
    EXPECT_EQ(magic, "P5") << name;
    EXPECT_EQ(width, 4);
    EXPECT_EQ(height, 3);
    EXPECT_EQ(maxval, 255);
    const std::string pixels = pgm.substr(pgm.size() - 12);  // after one whitespace byte
    if (name == "occupied") {
      EXPECT_EQ(static_cast<uint8_t>(pixels[2 * 4 + 0]), 0);  // bottom-left: occupied
      EXPECT_EQ(static_cast<uint8_t>(pixels[0]), 255);        // top-left: nothing
    }
    const std::string yaml = test::readText(dir / (name + ".yaml"));
    const bool pignistic = name == "pignistic";
    for (const std::string& key :
         {"image: " + name + ".pgm\n", std::string("resolution: 0.05\n"),
          std::string("origin: [-1.25, 2.5, 0.0]\n"), std::string("negate: 0\n"),
          std::string(pignistic ? "mode: trinary\n" : "mode: scale\n"),
          std::string(pignistic ? "occupied_thresh: 0.65\n" : "occupied_thresh: 1\n"),
          std::string(pignistic ? "free_thresh: 0.196\n" : "free_thresh: 0\n")}) {
      EXPECT_NE(yaml.find(key), std::string::npos) << name << ": " << key;
    }
  }
  files.clear();
  EXPECT_FALSE(
      writeMapServerLayers(raster, "/nonexistent/dir", LayerWriterConfig(), &files, &error));
  EXPECT_NE(error.find("/nonexistent/dir"), std::string::npos) << error;
}

// --- summary.json -------------------------------------------------------------------------------

// trajectory.png: a 40 x 20 raster at 0.05 m from (-1, 0); BetP 0 (free, white) everywhere but
// one occupied cell. The path runs along y = 0.525 (image row 9) from x = -0.975 to 0.925 (columns
// 0 to 38), the reference along y = 0.225 (row 15); lines are 2 px wide (0.1 m).
TEST(TrajectoryImage, DrawsThePathAndReferenceOverThePignisticMap) {
  LayerRaster raster;
  raster.resolution = 0.05;
  raster.origin_x = -1.0;
  raster.origin_y = 0.0;
  raster.width = 40;
  raster.height = 20;
  for (auto& v : raster.values) v.assign(800, 0.0f);
  raster.values[static_cast<int>(Layer::kPignistic)][2 * 40 + 30] = 1.0f;  // row 2 from the bottom
  int c = 0, r = 0;
  trajectoryPixel(raster, -0.975, 0.525, &c, &r);
  EXPECT_EQ(c, 0);
  EXPECT_EQ(r, 9);
  trajectoryPixel(raster, 0.925, 0.225, &c, &r);
  EXPECT_EQ(c, 38);
  EXPECT_EQ(r, 15);

  TrajectoryImage image;
  for (int i = 0; i <= 38; ++i) image.path.emplace_back(-0.975 + 0.05 * i, 0.525, 0.0);
  for (int i = 0; i <= 38; ++i) image.reference.emplace_back(-0.975 + 0.05 * i, 0.225, 0.0);
  const auto dir = test::scratchDir();
  std::string error;
  ASSERT_TRUE(writeTrajectoryImage(raster, image, (dir / "t.png").string(), &error)) << error;
  Png png;
  ASSERT_TRUE(decodePng((dir / "t.png").string(), &png));
  ASSERT_EQ(png.width, 40);
  ASSERT_EQ(png.height, 20);
  ASSERT_EQ(png.channels, 3);
  auto rgb = [&](int row, int col) {
    const uint8_t* p = png.at(row, col);
    return std::vector<int>{p[0], p[1], p[2]};
  };
  EXPECT_EQ(rgb(9, 20), (std::vector<int>{220, 20, 20}));    // the path: red
  EXPECT_EQ(rgb(15, 20), (std::vector<int>{40, 90, 230}));   // the reference: blue
  EXPECT_EQ(rgb(17, 30), (std::vector<int>{0, 0, 0}));       // the occupied cell: black
  EXPECT_EQ(rgb(3, 20), (std::vector<int>{255, 255, 255}));  // free: white

  // Without layers to draw on, one line saying why.
  EXPECT_FALSE(writeTrajectoryImage(LayerRaster(), image, (dir / "e.png").string(), &error));
  EXPECT_NE(error.find("e.png"), std::string::npos) << error;
}

TEST(Summary, JsonHasTheDocumentedKeys) {
  const auto path = (test::scratchDir() / "summary.json").string();
  RunSummary s;
  s.rawlog = "x.rawlog";
  s.ground_truth = "gt.txt";
  s.scans_total = 10;
  s.scans_processed = 7;
  s.rays_bad = 3;
  s.long_steps = 4;
  s.group_updates = 30;  // over 6 updates (7 processed scans, the first initialises)
  s.truncated = true;
  s.warnings = {"one", "two"};
  s.ate = AteSummary{0.25, 0.5, 10};
  std::string error;
  ASSERT_TRUE(writeSummaryJson(path, s, &error)) << error;
  const auto j = nlohmann::json::parse(test::readText(path));
  for (const char* key :
       {"rawlog", "scans_total", "scans_processed", "scans_rejected", "rays_total", "rays_bad",
        "rays_no_return", "long_steps", "wall_time_s", "peak_rss_mb", "particles", "resolution",
        "seed", "threads", "truncated", "warnings", "ate_rmse_m", "ate_max_m", "ate_matched"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["scans_total"], 10);
  EXPECT_EQ(j["long_steps"], 4);
  EXPECT_EQ(j["group_updates"], 30);
  EXPECT_DOUBLE_EQ(j["groups_per_update"].get<double>(), 5.0);
  EXPECT_EQ(j["truncated"], true);
  EXPECT_EQ(j["warnings"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["ate_rmse_m"].get<double>(), 0.25);
  EXPECT_FALSE(j.contains("parameters"));

  // --param overrides are recorded as given, in order.
  s.parameters = {{"resample_threshold", "0.3"}, {"scan_matching", "false"}};
  ASSERT_TRUE(writeSummaryJson(path, s, &error)) << error;
  const auto with = nlohmann::ordered_json::parse(test::readText(path));
  ASSERT_TRUE(with.contains("parameters"));
  EXPECT_EQ(with["parameters"].size(), 2u);
  EXPECT_EQ(with["parameters"]["resample_threshold"], "0.3");
  EXPECT_EQ(with["parameters"].begin().key(), "resample_threshold");

  // Without ground truth there are no ATE keys, and without --export-octomap no "octomap".
  RunSummary plain;
  ASSERT_TRUE(writeSummaryJson(path, plain, &error));
  EXPECT_FALSE(nlohmann::json::parse(test::readText(path)).contains("ate_rmse_m"));
  EXPECT_FALSE(nlohmann::json::parse(test::readText(path)).contains("octomap"));
}

TEST(Summary, OctomapExportIsOneObject) {
  const auto path = (test::scratchDir() / "summary.json").string();
  RunSummary s;
  MapExportSummary o;
  o.files = {"octomap/map.evidential.ot", "octomap/map.bt", "octomap/map.color.ot"};
  o.bytes = {300, 100, 200};
  o.seconds = 1.5;
  o.z_min = -0.1;
  o.z_max = 0.2;
  o.z_layers = 7;
  o.voxels = 700;
  s.octomap = o;
  std::string error;
  ASSERT_TRUE(writeSummaryJson(path, s, &error)) << error;
  const auto j = nlohmann::json::parse(test::readText(path))["octomap"];
  EXPECT_EQ(j["files"].size(), 3u);
  EXPECT_EQ(j["files"][1], "octomap/map.bt");
  EXPECT_EQ(j["bytes"][2], 200);
  EXPECT_DOUBLE_EQ(j["export_time_s"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(j["z_min"].get<double>(), -0.1);
  EXPECT_DOUBLE_EQ(j["z_max"].get<double>(), 0.2);
  EXPECT_EQ(j["z_layers"], 7);
  EXPECT_EQ(j["voxels"], 700);
}

// --- progress -----------------------------------------------------------------------------------

TEST(Progress, LineShowsCountsRateAndEta) {
  const std::string line = ProgressBar::format(50, 200, 10.0);
  EXPECT_NE(line.find("50/200 scans"), std::string::npos) << line;
  EXPECT_NE(line.find("25.0%"), std::string::npos) << line;
  EXPECT_NE(line.find("5.0 scans/s"), std::string::npos) << line;
  EXPECT_NE(line.find("ETA 0:30"), std::string::npos) << line;
  EXPECT_NE(ProgressBar::format(3, 0, 1.0).find("3 scans"), std::string::npos);
}

TEST(Progress, NonTtyPrintsAboutEveryTenPercent) {
  const auto path = test::scratchDir() / "progress.txt";
  std::FILE* f = std::fopen(path.string().c_str(), "w");
  ASSERT_NE(f, nullptr);
  ProgressBar bar(f, 1000, false);
  for (uint64_t i = 1; i <= 1000; ++i) bar.update(i);
  bar.finish(1000);
  std::fclose(f);
  const std::string text = test::readText(path);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 10);
  EXPECT_EQ(text.find('\r'), std::string::npos);
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
