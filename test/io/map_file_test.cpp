// The map file (map_file.h, docs/map_format.md): a round trip is bit-identical; a file made here by
// hand from the spec decodes to the cells it says; and every kind of damaged or foreign file gets
// a one-line error instead of a crash or a map: truncated at every byte, wrong signature, other
// versions, inconsistent sizes, absurd dimensions, bad cells, bad checksum, bad metadata, an empty
// file, a directory. The committed fuzzer seeds (test/data/map_file_seeds) are checked here too.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "evidential_slam/io/build_info.h"
#include "evidential_slam/io/map_file.h"
#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;
using Tile = EvidentialGridMap::Tile;

// --- maps and their comparison ---------------------------------------------------------------

// Cells in three tiles (negative coordinates too), conflicted ones, and a fourth tile allocated
// but vacuous.
EvidentialGridMap sampleMap() {
  EvidentialGridMap map(0.05);
  updateCell(map.mutableCell(0, 0), ScanMass{0.0f, 0.8f});
  updateCell(map.mutableCell(1, 0), ScanMass{0.63f, 0.0f});
  updateCell(map.mutableCell(-3, 2), ScanMass{0.3f, 0.3f});
  for (int i = 0; i < 40; ++i) {  // alternating hits and passes: λ grows
    updateCell(map.mutableCell(-40, -70), ScanMass{0.63f, 0.0f});
    updateCell(map.mutableCell(-40, -70), ScanMass{0.0f, 0.8f});
  }
  for (int x = 0; x < 32; ++x) updateCell(map.mutableCell(x, 31), ScanMass{0.2f, 0.5f});
  map.mutableTile(5, -4);  // allocated, never written
  return map;
}

MapFileInfo sampleInfo() {
  MapFileInfo info;
  info.robot_pose = Pose2(1.25, -3.5, 0.7);
  info.has_odometry_pose = true;
  info.odometry_pose = Pose2(10.0 / 3.0, 1e-17, -3.0);
  info.parameters = {{"particles", "30"}, {"resolution", "0.05"}, {"sensor.z_hit", "0.63"}};
  info.metadata = {{"source", "simul.rawlog"}, {"scans_processed", "866"}, {"note", "ä ∅ \"q\""}};
  return info;
}

// Same tiles at the same places, same cell bits.
void expectSameMaps(const EvidentialGridMap& a, const EvidentialGridMap& b) {
  EXPECT_EQ(a.resolution(), b.resolution());
  EXPECT_EQ(a.allocatedTiles(), b.allocatedTiles());
  size_t tiles = 0, differing = 0;
  a.forEachTile([&](int tx, int ty, const Tile& tile) {
    ++tiles;
    const Tile* other = b.tile(tx, ty);
    ASSERT_NE(other, nullptr) << "tile " << tx << ", " << ty;
    for (int k = 0; k < EvidentialGridMap::kTileCells; ++k) {
      const Cell& x = tile.cells[k];
      const Cell& y = other->cells[k];
      if (x.occupiedSteps() != y.occupiedSteps() || x.freeSteps() != y.freeSteps() ||
          x.lambdaBits() != y.lambdaBits()) {
        ++differing;
      }
      // The tile's may-hold-occupied bits agree with the cells (the forward model trusts them).
      if (y.occupied() > 0.0f) {
        EXPECT_TRUE(other->mayHoldOccupied(k));
      }
    }
  });
  EXPECT_EQ(tiles, a.allocatedTiles());
  EXPECT_EQ(differing, 0u);
}

std::string encode(const EvidentialGridMap& map, const MapFileInfo& info) {
  std::string bytes, error;
  EXPECT_TRUE(encodeMapFile(map, info, &bytes, &error)) << error;
  return bytes;
}

// Decodes; returns the error ("" on success) and checks it is one line.
std::string decodeError(const std::string& bytes, EvidentialGridMap* map = nullptr,
                        MapFileInfo* info = nullptr) {
  EvidentialGridMap local_map;
  MapFileInfo local_info;
  std::string error;
  const bool ok = decodeMapFile(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(),
                                map != nullptr ? map : &local_map,
                                info != nullptr ? info : &local_info, &error);
  if (ok) return "";
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  return error;
}

#define EXPECT_REFUSED(bytes, fragment)                                                 \
  do {                                                                                  \
    const std::string refused_error = decodeError(bytes);                               \
    EXPECT_NE(refused_error.find(fragment), std::string::npos)                          \
        << "error: '" << refused_error << "', expected it to say '" << fragment << "'"; \
  } while (0)

// --- files made by hand, from docs/map_format.md ------------------------------------------------

const std::string kMagic(
    "\x89"
    "EVMAP\r\n\x1a\n",
    10);

void putLe(std::string* s, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) s->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

std::string deflateBytes(const std::string& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string out(size, '\0');
  EXPECT_EQ(
      compress2(reinterpret_cast<Bytef*>(&out[0]), &size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()), 6),
      Z_OK);
  out.resize(size);
  return out;
}

// One cell's stored bits.
struct Bits {
  uint32_t occupied = 0, free = 0;
  uint16_t lambda = 0;
};

// The tiles' uncompressed bytes: the coordinates, then each tile's m̃(o) steps (3 bytes a cell,
// big-endian), m̃(e) steps (likewise) and λ bits (2 bytes a cell, big-endian).
std::string rawTiles(const std::vector<std::pair<int32_t, int32_t>>& coordinates,
                     const std::vector<std::vector<Bits>>& tiles) {
  std::string raw;
  for (const auto& [tx, ty] : coordinates) {
    putLe(&raw, static_cast<uint32_t>(tx), 4);
    putLe(&raw, static_cast<uint32_t>(ty), 4);
  }
  for (const std::vector<Bits>& cells : tiles) {
    std::string body(8 * 1024, '\0');
    for (size_t k = 0; k < cells.size(); ++k) {
      const Bits& b = cells[k];
      body[3 * k] = static_cast<char>(b.occupied >> 16);
      body[3 * k + 1] = static_cast<char>(b.occupied >> 8);
      body[3 * k + 2] = static_cast<char>(b.occupied);
      body[3072 + 3 * k] = static_cast<char>(b.free >> 16);
      body[3072 + 3 * k + 1] = static_cast<char>(b.free >> 8);
      body[3072 + 3 * k + 2] = static_cast<char>(b.free);
      body[6144 + 2 * k] = static_cast<char>(b.lambda >> 8);
      body[6144 + 2 * k + 1] = static_cast<char>(b.lambda);
    }
    raw += body;
  }
  return raw;
}

const std::string kMetadata =
    R"({"resolution": 0.1, "robot_pose": {"x": 1, "y": 2, "theta": 0.5}, "build": "by hand",)"
    R"( "parameters": {"particles": "5"}, "metadata": {}})";

struct Parts {
  std::string magic = kMagic;
  uint16_t version = 1;
  std::string metadata = kMetadata;
  uint32_t tiles = 0;
  std::string payload = deflateBytes("");
  uint32_t reserved = 0;
};

// Frames the parts into a file with a true CRC.
std::string frame(const Parts& p) {
  std::string f = p.magic;
  putLe(&f, p.version, 2);
  putLe(&f, p.metadata.size(), 4);
  putLe(&f, p.tiles, 4);
  putLe(&f, p.payload.size(), 8);
  putLe(&f, p.reserved, 4);
  f += p.metadata + p.payload;
  putLe(&f, crc32(0L, reinterpret_cast<const Bytef*>(f.data()), static_cast<uInt>(f.size())), 4);
  return f;
}

// A file of the given tiles (cells set as listed, the rest vacuous).
std::string handMade(const std::vector<std::pair<int32_t, int32_t>>& coordinates,
                     const std::vector<std::vector<Bits>>& tiles) {
  Parts p;
  p.tiles = static_cast<uint32_t>(coordinates.size());
  p.payload = deflateBytes(rawTiles(coordinates, tiles));
  return frame(p);
}

// --- round trips --------------------------------------------------------------------------------

TEST(MapFile, RoundTripIsBitIdentical) {
  const EvidentialGridMap map = sampleMap();
  const MapFileInfo info = sampleInfo();
  const std::string bytes = encode(map, info);
  EvidentialGridMap read(0.5);
  MapFileInfo read_info;
  ASSERT_EQ(decodeError(bytes, &read, &read_info), "");
  expectSameMaps(map, read);
  EXPECT_EQ(read.allocatedTiles(), 4u);
  EXPECT_NE(read.tile(5, -4), nullptr);  // the vacuous tile is kept
  EXPECT_TRUE(read.cell(-40, -70).conflicted());
  EXPECT_EQ(read.cell(-40, -70).lambdaBits(), map.cell(-40, -70).lambdaBits());
  MapFileInfo expected = info;
  expected.build = buildVersion();
  EXPECT_TRUE(read_info == expected);
  EXPECT_EQ(read_info.metadata.at("note"), "ä ∅ \"q\"");
  EXPECT_EQ(read_info.odometry_pose.y, 1e-17);
  EXPECT_EQ(read_info.odometry_pose.x, 10.0 / 3.0);
  // The encoding is canonical: the map read back encodes to the same bytes.
  EXPECT_EQ(encode(read, read_info), bytes);
}

TEST(MapFile, EmptyMapRoundTrips) {
  EvidentialGridMap empty(0.2);
  MapFileInfo info;
  EvidentialGridMap read;
  MapFileInfo read_info;
  ASSERT_EQ(decodeError(encode(empty, info), &read, &read_info), "");
  EXPECT_EQ(read.resolution(), 0.2);
  EXPECT_EQ(read.allocatedTiles(), 0u);
  EXPECT_FALSE(read_info.has_odometry_pose);
}

TEST(MapFile, WriteAndReadAFile) {
  const fs::path dir = test::scratchDir();
  const std::string path = (dir / kMapFileName).string();
  MapFileStats stats;
  std::string error;
  ASSERT_TRUE(writeMapFile(path, sampleMap(), sampleInfo(), &error, &stats)) << error;
  EXPECT_EQ(stats.file_bytes, fs::file_size(path));
  EXPECT_EQ(stats.tiles, 4u);
  EXPECT_EQ(stats.raw_payload_bytes, 4u * (8 + 8192));
  EXPECT_FALSE(fs::exists(path + ".partial"));
  // Overwriting an existing map works (through the temporary file).
  ASSERT_TRUE(writeMapFile(path, sampleMap(), sampleInfo(), &error)) << error;
  EvidentialGridMap read;
  MapFileInfo info;
  ASSERT_TRUE(readMapFile(path, &read, &info, &error)) << error;
  expectSameMaps(sampleMap(), read);
}

// A directory stands for the map file in it.
TEST(MapFile, ResolvePath) {
  const fs::path dir = test::scratchDir();
  EXPECT_EQ(resolveMapFilePath(dir.string()), (dir / kMapFileName).string());
  EXPECT_EQ(resolveMapFilePath((dir / "other.evmap").string()), (dir / "other.evmap").string());
  EXPECT_EQ(resolveMapFilePath("no/such/dir"), "no/such/dir");
}

// Names and values that are not UTF-8 are stored (as U+FFFD), not refused.
TEST(MapFile, InvalidUtf8IsReplaced) {
  MapFileInfo info;
  info.metadata["source"] = "log\xff.rawlog";
  MapFileInfo read_info;
  ASSERT_EQ(decodeError(encode(EvidentialGridMap(0.05), info), nullptr, &read_info), "");
  EXPECT_EQ(read_info.metadata.at("source"), "log\xef\xbf\xbd.rawlog");
}

TEST(MapFile, WriterRefusesWhatItCannotStore) {
  std::string bytes, error;
  MapFileInfo info;
  info.robot_pose.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(encodeMapFile(EvidentialGridMap(0.05), info, &bytes, &error));
  EXPECT_NE(error.find("finite"), std::string::npos) << error;
  EXPECT_FALSE(encodeMapFile(EvidentialGridMap(1e-4), MapFileInfo{}, &bytes, &error));
  EXPECT_NE(error.find("resolution"), std::string::npos) << error;
  EvidentialGridMap far(0.05);
  updateCell(far.mutableCell(40 << 20, 0), ScanMass{0.5f, 0.0f});
  EXPECT_FALSE(encodeMapFile(far, MapFileInfo{}, &bytes, &error));
  EXPECT_NE(error.find("beyond"), std::string::npos) << error;
  // Two tiles 300 tiles apart need a 301 x 301 index, more than the reader allows for 2 tiles.
  EvidentialGridMap sparse(0.05);
  updateCell(sparse.mutableCell(0, 0), ScanMass{0.5f, 0.0f});
  updateCell(sparse.mutableCell(300 * 32, 300 * 32), ScanMass{0.5f, 0.0f});
  EXPECT_FALSE(encodeMapFile(sparse, MapFileInfo{}, &bytes, &error));
  EXPECT_NE(error.find("tile places"), std::string::npos) << error;
  const fs::path dir = test::scratchDir();
  EXPECT_FALSE(writeMapFile((dir / "missing" / "map.evmap").string(), EvidentialGridMap(0.05),
                            MapFileInfo{}, &error));
  EXPECT_NE(error.find("missing/map.evmap"), std::string::npos) << error;
}

// --- the spec, by hand --------------------------------------------------------------------------

// A file written from docs/map_format.md alone: tile (-1, 2) with cell k = 37 (x = 5, y = 1 in
// the tile, so cell (-27, 65)) at m̃(o) = 2^22 steps (0.5), m̃(e) = 2^21 (0.25), λ = half 1.0.
TEST(MapFile, HandMadeFileDecodes) {
  std::vector<Bits> cells(1024);
  cells[37] = Bits{1u << 22, 1u << 21, 0x3C00};
  const std::string bytes = handMade({{-1, 2}}, {cells});
  EvidentialGridMap map;
  MapFileInfo info;
  ASSERT_EQ(decodeError(bytes, &map, &info), "");
  EXPECT_EQ(map.resolution(), 0.1);
  EXPECT_EQ(map.allocatedTiles(), 1u);
  const Cell& c = map.cell(-27, 65);
  EXPECT_EQ(c.occupied(), 0.5f);
  EXPECT_EQ(c.free(), 0.25f);
  EXPECT_EQ(c.lambda(), 1.0f);
  EXPECT_FALSE(map.cell(-28, 65).observed());
  EXPECT_EQ(info.robot_pose.x, 1.0);
  EXPECT_EQ(info.robot_pose.theta, 0.5);
  EXPECT_EQ(info.build, "by hand");
  EXPECT_EQ(info.parameters.at("particles"), "5");
  EXPECT_FALSE(info.has_odometry_pose);
}

// --- damaged and foreign files ------------------------------------------------------------------

TEST(MapFileDamage, TruncatedAtEveryByte) {
  const std::string bytes = encode(sampleMap(), sampleInfo());
  ASSERT_GT(bytes.size(), 300u);
  EXPECT_REFUSED(std::string(), "empty file");
  for (size_t n = 1; n < bytes.size(); ++n) {
    const std::string error = decodeError(bytes.substr(0, n));
    ASSERT_NE(error.find("truncated"), std::string::npos) << n << " bytes: " << error;
  }
}

TEST(MapFileDamage, WrongSignature) {
  std::string bytes = encode(sampleMap(), sampleInfo());
  bytes[1] = 'X';
  EXPECT_REFUSED(bytes, "not an evidential map file");
  EXPECT_REFUSED(std::string("P5\n10 10\n255\n"), "not an evidential map file");
  EXPECT_REFUSED(std::string("\x89PNG\r\n\x1a\n", 8), "not an evidential map file");
  EXPECT_REFUSED(std::string(100, '\0'), "not an evidential map file");
  // Text-mode damage (CR LF to LF) breaks the signature too.
  std::string text_mode = bytes;
  text_mode[1] = 'E';
  text_mode.erase(6, 1);
  EXPECT_REFUSED(text_mode, "not an evidential map file");
}

TEST(MapFileDamage, OtherVersions) {
  Parts p;
  p.version = 2;
  EXPECT_REFUSED(frame(p), "format version 2 is newer than this build reads (1)");
  p.version = 0xFFFF;
  EXPECT_REFUSED(frame(p), "format version 65535 is newer");
  p.version = 0;
  EXPECT_REFUSED(frame(p), "format version 0 is not one this build reads");
  EXPECT_EQ(decodeError(frame(Parts{})), "");
}

TEST(MapFileDamage, InconsistentSizes) {
  // Cell 0's first bytes (05 00 00 00 ...) read as tile (5, 0) when the header claims a third
  // tile: the tiles' bytes then run out rather than failing an earlier check.
  std::vector<Bits> cells(1024);
  cells[0] = Bits{0x050000, 0, 0};
  const std::string two = rawTiles({{0, 0}, {1, 0}}, {cells, cells});
  Parts p;
  p.payload = deflateBytes(two);
  p.tiles = 2;
  EXPECT_EQ(decodeError(frame(p)), "");
  p.tiles = 3;  // more tiles than the payload holds
  EXPECT_REFUSED(frame(p), "ends before its last tile");
  p.tiles = 1;  // fewer
  EXPECT_REFUSED(frame(p), "holds more than the header's tiles");
  p.tiles = 2;
  p.payload = deflateBytes(two.substr(0, two.size() - 1));  // a tile one byte short
  EXPECT_REFUSED(frame(p), "ends before its last tile");
  p.payload = deflateBytes(two) + "xyz";  // bytes after the zlib stream
  EXPECT_REFUSED(frame(p), "bytes follow the payload's zlib stream");
  p.payload = deflateBytes(two);
  p.payload.resize(p.payload.size() - 3);  // the zlib stream cut short
  EXPECT_REFUSED(frame(p), "cut short");

  // Sizes in the header that disagree with the file's length.
  const std::string good = encode(sampleMap(), sampleInfo());
  EXPECT_REFUSED(good + "x", "1 bytes follow the end the header gives");
  std::string longer_metadata = good;
  longer_metadata[12] = static_cast<char>(longer_metadata[12] + 1);
  EXPECT_REFUSED(longer_metadata, "truncated");
  std::string huge_payload = good;
  huge_payload[27] = 0x7F;
  EXPECT_REFUSED(huge_payload, "more than a map file holds");
}

TEST(MapFileDamage, AbsurdDimensions) {
  Parts p;
  p.tiles = MapFileLimits::kMaxTiles + 1;
  EXPECT_REFUSED(frame(p), "tiles, more than a map file holds");
  p.tiles = 1000000;  // far more than a tiny payload can inflate to
  EXPECT_REFUSED(frame(p), "more than a");
  p.tiles = 0;
  p.metadata = std::string(MapFileLimits::kMaxMetadataBytes + 1u, ' ');
  EXPECT_REFUSED(frame(p), "bytes of metadata, more than a map file holds");

  const std::vector<Bits> vacuous(1024);
  EXPECT_REFUSED(handMade({{0, MapFileLimits::kMaxTileCoordinate + 1}}, {vacuous}),
                 "lies beyond what a map file holds");
  EXPECT_REFUSED(handMade({{std::numeric_limits<int32_t>::min(), 0}}, {vacuous}), "lies beyond");
  // Two tiles 2^20 apart would need a tile index of 2^20 places for 2 tiles.
  EXPECT_REFUSED(handMade({{-(1 << 19), 0}, {1 << 19, 0}}, {vacuous, vacuous}),
                 "tile places, more than");
  EXPECT_REFUSED(handMade({{1, 0}, {0, 0}}, {vacuous, vacuous}), "not in order");
  EXPECT_REFUSED(handMade({{0, 1}, {5, 0}}, {vacuous, vacuous}), "not in order");
  EXPECT_REFUSED(handMade({{3, 3}, {3, 3}}, {vacuous, vacuous}), "repeats a tile");
  // Tiles in a 256 x 256 box (the cap for 2 tiles) are fine.
  EXPECT_EQ(decodeError(handMade({{0, 0}, {255, 255}}, {vacuous, vacuous})), "");
}

TEST(MapFileDamage, CellsNoGridHolds) {
  const std::vector<Bits> bad = {
      Bits{(1u << 23) + 1, 0, 0},         // m̃(o) > 1
      Bits{1u << 22, (1u << 22) + 1, 0},  // m̃(o) + m̃(e) > 1
      Bits{0, 0, 0x7C00},                 // λ = inf
      Bits{0, 0, 0x7E00},                 // λ = NaN
      Bits{0, 0, 0x8000},                 // λ = -0
      Bits{0, 0, 0xBC00},                 // λ = -1
      Bits{0xFFFFFF, 0xFFFFFF, 0},        // all bits set
  };
  for (const Bits& b : bad) {
    std::vector<Bits> cells(1024);
    cells[700] = b;
    EXPECT_REFUSED(handMade({{2, -3}}, {cells}),
                   "tile (2, -3) cell 700 holds bits no cell can hold");
  }
  std::vector<Bits> edge(1024);
  edge[0] = Bits{1u << 23, 0, 0x7BFF};  // m̃(o) = 1, λ = 65504: the largest a cell holds
  edge[1] = Bits{0, 1u << 23, 0};
  edge[2] = Bits{3u << 21, 1u << 21, 1};
  EXPECT_EQ(decodeError(handMade({{0, 0}}, {edge})), "");
}

TEST(MapFileDamage, BadChecksum) {
  const std::string good = encode(sampleMap(), sampleInfo());
  for (const size_t at : {size_t{40}, good.size() / 2, good.size() - 5, good.size() - 1}) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    SCOPED_TRACE("byte " + std::to_string(at));
    EXPECT_REFUSED(bad, "checksum mismatch");
  }
  // A damaged zlib stream behind a true checksum is caught by zlib.
  Parts p;
  p.tiles = 1;
  p.payload = deflateBytes(rawTiles({{0, 0}}, {std::vector<Bits>(1024)}));
  p.payload[4] = static_cast<char>(p.payload[4] ^ 0xFF);
  EXPECT_REFUSED(frame(p), "payload");
}

TEST(MapFileDamage, BadMetadata) {
  const auto with = [](const std::string& metadata) {
    Parts p;
    p.metadata = metadata;
    return frame(p);
  };
  EXPECT_REFUSED(with("{\"resolution\": 0.1,\n\x01 oops"),
                 "bad metadata: the metadata is not JSON");
  EXPECT_REFUSED(with("[1, 2]"), "not a JSON object");
  EXPECT_REFUSED(with(""), "not JSON");
  const std::string pose = R"("robot_pose": {"x": 1, "y": 2, "theta": 0.5})";
  const std::string rest = R"("build": "b", "parameters": {}, "metadata": {})";
  EXPECT_REFUSED(with("{" + pose + ", " + rest + "}"), "'resolution' is missing");
  EXPECT_REFUSED(with(R"({"resolution": "0.1", )" + pose + ", " + rest + "}"),
                 "'resolution' is missing or not a number");
  EXPECT_REFUSED(with(R"({"resolution": 0, )" + pose + ", " + rest + "}"), "resolution 0.0");
  EXPECT_REFUSED(with(R"({"resolution": 1e999, )" + pose + ", " + rest + "}"), "bad metadata");
  EXPECT_REFUSED(with(R"({"resolution": 0.1, )" + rest + "}"), "'robot_pose' is missing");
  EXPECT_REFUSED(with(R"({"resolution": 0.1, "robot_pose": {"x": 1, "y": 2}, )" + rest + "}"),
                 "robot_pose: 'theta' is missing");
  EXPECT_REFUSED(with(R"({"resolution": 0.1, )" + pose +
                      R"(, "odometry_pose": 3, "build": "b", "parameters": {}, "metadata": {}})"),
                 "'odometry_pose' is missing or not an object");
  EXPECT_REFUSED(with(R"({"resolution": 0.1, )" + pose + R"(, "parameters": {}, "metadata": {}})"),
                 "'build' is missing");
  EXPECT_REFUSED(with(R"({"resolution": 0.1, )" + pose +
                      R"(, "build": "b", "parameters": {"particles": 30}, "metadata": {}})"),
                 "parameters: 'particles' is not a string");
  EXPECT_REFUSED(with(R"({"resolution": 0.1, )" + pose + R"(, "build": "b", "parameters": {}})"),
                 "'metadata' is missing");
  // Members this version does not know are ignored.
  EXPECT_EQ(
      decodeError(with(R"({"resolution": 0.1, )" + pose + ", " + rest + R"(, "later": [1]})")), "");
  // Nesting is bounded before parsing (a million brackets once took over a minute); brackets in
  // strings do not count.
  const auto nested = [&](int depth) {
    return with(R"({"resolution": 0.1, )" + pose + ", " + rest + R"(, "later": )" +
                std::string(depth, '[') + std::string(depth, ']') +
                R"(, "s": "[[[[[[[[[[[[[[[["})");
  };
  const int limit = MapFileLimits::kMaxMetadataNesting;
  EXPECT_EQ(decodeError(nested(limit - 1)), "");
  EXPECT_REFUSED(nested(limit), "nests arrays or objects deeper than 16 levels");
  EXPECT_REFUSED(nested(1000000), "nests arrays or objects deeper than 16 levels");
}

TEST(MapFileDamage, ReservedBytesMustBeZero) {
  Parts p;
  p.reserved = 1;
  EXPECT_REFUSED(frame(p), "reserved header bytes are not zero");
}

// A refused file leaves the caller's map and metadata as they were.
TEST(MapFileDamage, OutputsUntouchedOnError) {
  EvidentialGridMap map = sampleMap();
  MapFileInfo info = sampleInfo();
  std::string bad = encode(sampleMap(), sampleInfo());
  bad[bad.size() - 1] = static_cast<char>(bad[bad.size() - 1] ^ 1);
  EXPECT_NE(decodeError(bad, &map, &info), "");
  expectSameMaps(sampleMap(), map);
  EXPECT_TRUE(info == sampleInfo());
}

TEST(MapFileDamage, FilesThatAreNotMaps) {
  const fs::path dir = test::scratchDir();
  EvidentialGridMap map;
  MapFileInfo info;
  std::string error;
  const auto refused = [&](const fs::path& path, const std::string& fragment) {
    EXPECT_FALSE(readMapFile(path.string(), &map, &info, &error)) << path;
    EXPECT_EQ(error.rfind(path.string() + ": ", 0), 0u) << error;
    EXPECT_NE(error.find(fragment), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  refused(dir / "absent.evmap", "no such file");
  refused(dir, "is a directory");
  test::writeText(dir / "empty.evmap", "");
  refused(dir / "empty.evmap", "empty file");
  test::writeText(dir / "map.yaml", "image: pignistic.png\nresolution: 0.05\n");
  refused(dir / "map.yaml", "not an evidential map file");
  const std::string good = encode(sampleMap(), sampleInfo());
  test::writeText(dir / "cut.evmap", good.substr(0, good.size() / 2));
  refused(dir / "cut.evmap", "truncated");
}

// --- the fuzzer's committed seeds ---------------------------------------------------------------

const char* const kSeedDir = ES_TEST_DATA_DIR "/map_file_seeds";

// The valid seeds: small maps of a few shapes (the fuzzer's inputs stay well under 16 KB).
std::vector<std::pair<std::string, std::string>> validSeeds() {
  std::vector<std::pair<std::string, std::string>> seeds;
  seeds.emplace_back("valid_empty.evmap", encode(EvidentialGridMap(0.05), MapFileInfo{}));
  EvidentialGridMap few(0.05);
  updateCell(few.mutableCell(0, 0), ScanMass{0.0f, 0.8f});
  updateCell(few.mutableCell(1, 0), ScanMass{0.63f, 0.0f});
  updateCell(few.mutableCell(2, 0), ScanMass{0.63f, 0.0f});
  updateCell(few.mutableCell(2, 0), ScanMass{0.0f, 0.8f});
  MapFileInfo info;
  info.robot_pose = Pose2(0.5, -0.25, 1.0);
  info.has_odometry_pose = true;
  info.odometry_pose = Pose2(3.0, 4.0, -0.5);
  info.parameters = {{"particles", "30"}};
  info.metadata = {{"source", "seed"}};
  seeds.emplace_back("valid_one_tile.evmap", encode(few, info));
  EvidentialGridMap three(0.1);
  updateCell(three.mutableCell(-1, -1), ScanMass{0.3f, 0.3f});
  updateCell(three.mutableCell(40, 3), ScanMass{0.63f, 0.0f});
  updateCell(three.mutableCell(5, 70), ScanMass{0.0f, 0.8f});
  seeds.emplace_back("valid_three_tiles.evmap", encode(three, MapFileInfo{}));
  return seeds;
}

// A seed with its payload uncompressed: not a file, but what the fuzzer's third decoding
// (map_file_fuzzer.cpp) compresses and frames itself.
std::string rawSeed(const std::string& file) {
  uint32_t metadata_bytes = 0;
  for (int i = 3; i >= 0; --i)
    metadata_bytes = (metadata_bytes << 8) | static_cast<uint8_t>(file[12 + i]);
  const size_t payload_at = 32 + metadata_bytes;
  const std::string payload = file.substr(payload_at, file.size() - payload_at - 4);
  std::string raw(64 * 1024, '\0');
  uLongf size = static_cast<uLongf>(raw.size());
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(&raw[0]), &size,
                       reinterpret_cast<const Bytef*>(payload.data()),
                       static_cast<uLong>(payload.size())),
            Z_OK);
  raw.resize(size);
  return file.substr(0, payload_at) + raw + std::string(4, '\0');
}

// ES_WRITE_MAP_FILE_SEEDS=1 rewrites the committed seeds (after a format change).
TEST(MapFileSeeds, CommittedSeedsAreCurrent) {
  const auto seeds = validSeeds();
  if (const char* v = std::getenv("ES_WRITE_MAP_FILE_SEEDS"); v != nullptr && v[0] == '1') {
    fs::create_directories(kSeedDir);
    for (const auto& [name, bytes] : seeds) test::writeText(fs::path(kSeedDir) / name, bytes);
    test::writeText(fs::path(kSeedDir) / "raw_one_tile.bin", rawSeed(seeds[1].second));
  }
  size_t total = 0;
  for (const auto& [name, bytes] : seeds) {
    const std::string committed = test::readText(fs::path(kSeedDir) / name);
    total += committed.size();
    EvidentialGridMap want, got;
    MapFileInfo want_info, got_info;
    ASSERT_EQ(decodeError(bytes, &want, &want_info), "") << name;
    ASSERT_EQ(decodeError(committed, &got, &got_info), "") << name;
    expectSameMaps(want, got);
    got_info.build = want_info.build;
    EXPECT_TRUE(got_info == want_info) << name;
  }
  for (const auto& entry : fs::directory_iterator(kSeedDir)) {
    if (entry.path().filename().string().rfind("valid_", 0) != 0) {
      total += fs::file_size(entry.path());
    }
  }
  EXPECT_LT(total, 200u * 1024u);
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
