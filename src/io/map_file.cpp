// The map file of docs/map_format.md. Layout: a 32-byte header, the metadata as JSON, the tiles as
// one zlib stream, a CRC-32 of everything before it. Multi-byte fields are little-endian.
#include "evidential_slam/io/map_file.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/build_info.h"

namespace evidential_slam {
namespace io {
namespace {

using Json = nlohmann::json;
using Tile = EvidentialGridMap::Tile;

constexpr std::array<uint8_t, 10> kMagic = {0x89, 'E', 'V', 'M', 'A', 'P', '\r', '\n', 0x1A, '\n'};
constexpr size_t kHeaderBytes = 32;  // magic, version, metadata length, tile count, payload length
constexpr size_t kTrailerBytes = 4;  // CRC-32
constexpr size_t kCoordinateBytes = 8;                            // tx, ty as int32
constexpr size_t kTileBytes = EvidentialGridMap::kTileCells * 8;  // 3 + 3 + 2 per cell
constexpr uint64_t kDeflateMaxRatio = 1032;                       // zlib's best case
// zlib level 6 (its default): on simul's and intel's maps level 1 writes files 22 % larger, and
// level 9 gains 1-2 % for 5-8x the time (docs/decisions.md).
constexpr int kCompressionLevel = 6;

void putU16(std::string* out, uint16_t v) {
  out->push_back(static_cast<char>(v & 0xFF));
  out->push_back(static_cast<char>(v >> 8));
}
void putU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void putU64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
uint16_t getU16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t getU32(const uint8_t* p) {
  return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}
uint64_t getU64(const uint8_t* p) { return uint64_t{getU32(p)} | (uint64_t{getU32(p + 4)} << 32); }

// zlib's crc32 over any length (its length argument is a uInt).
uint32_t crc32Of(const uint8_t* data, size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (size > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = crc32(crc, data, chunk);
    data += chunk;
    size -= chunk;
  }
  return static_cast<uint32_t>(crc);
}

// A message fit for one line: control characters (a JSON parser may quote raw input) become
// spaces, and it is cut at 200 characters.
std::string oneLine(std::string s) {
  for (char& c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = ' ';
  }
  if (s.size() > 200) s = s.substr(0, 197) + "...";
  return s;
}

bool fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = oneLine(message);
  return false;
}

// A tile's cells field by field: the 1024 m̃(o) step counts (3 bytes each, high byte first), then
// the m̃(e) ones, then λ's half-float bits (2 bytes each, high byte first). Like values next to
// each other compress better than cell after cell or byte planes (docs/decisions.md).
constexpr size_t kFreeOffset = 3 * EvidentialGridMap::kTileCells;
constexpr size_t kLambdaOffset = 6 * EvidentialGridMap::kTileCells;

void encodeTile(const Tile& tile, uint8_t* out) {
  for (size_t k = 0; k < EvidentialGridMap::kTileCells; ++k) {
    const Cell& c = tile.cells[k];
    const uint32_t o = c.occupiedSteps(), e = c.freeSteps();
    const uint16_t l = c.lambdaBits();
    uint8_t* po = out + 3 * k;
    uint8_t* pe = out + kFreeOffset + 3 * k;
    uint8_t* pl = out + kLambdaOffset + 2 * k;
    po[0] = static_cast<uint8_t>(o >> 16);
    po[1] = static_cast<uint8_t>(o >> 8);
    po[2] = static_cast<uint8_t>(o);
    pe[0] = static_cast<uint8_t>(e >> 16);
    pe[1] = static_cast<uint8_t>(e >> 8);
    pe[2] = static_cast<uint8_t>(e);
    pl[0] = static_cast<uint8_t>(l >> 8);
    pl[1] = static_cast<uint8_t>(l);
  }
}

// Fills `tile` from its bytes; false (and the cell's index in `bad`) for bits no cell holds.
bool decodeTile(const uint8_t* in, Tile* tile, int* bad) {
  for (size_t k = 0; k < EvidentialGridMap::kTileCells; ++k) {
    const uint8_t* po = in + 3 * k;
    const uint8_t* pe = in + kFreeOffset + 3 * k;
    const uint8_t* pl = in + kLambdaOffset + 2 * k;
    const uint32_t o = (uint32_t{po[0]} << 16) | (uint32_t{po[1]} << 8) | po[2];
    const uint32_t e = (uint32_t{pe[0]} << 16) | (uint32_t{pe[1]} << 8) | pe[2];
    const uint16_t l = static_cast<uint16_t>((pl[0] << 8) | pl[1]);
    if (!Cell::fromBits(o, e, l, &tile->cells[k])) {
      *bad = static_cast<int>(k);
      return false;
    }
    tile->cellWritten(static_cast<int>(k));
  }
  return true;
}

// Compresses what is appended into one zlib stream.
class Deflater {
 public:
  Deflater() { ok_ = deflateInit(&zs_, kCompressionLevel) == Z_OK; }
  ~Deflater() { deflateEnd(&zs_); }
  Deflater(const Deflater&) = delete;
  Deflater& operator=(const Deflater&) = delete;

  bool ok() const { return ok_; }
  void append(const uint8_t* data, size_t size, std::string* out) {
    run(data, size, Z_NO_FLUSH, out);
  }
  void finish(std::string* out) { run(nullptr, 0, Z_FINISH, out); }

 private:
  void run(const uint8_t* data, size_t size, int flush, std::string* out) {
    zs_.next_in = const_cast<Bytef*>(data);  // zlib's API is not const-correct
    zs_.avail_in = static_cast<uInt>(size);
    std::array<uint8_t, 1 << 16> buffer;
    int rc = Z_OK;
    do {
      zs_.next_out = buffer.data();
      zs_.avail_out = static_cast<uInt>(buffer.size());
      rc = deflate(&zs_, flush);
      if (rc == Z_STREAM_ERROR) ok_ = false;
      out->append(reinterpret_cast<const char*>(buffer.data()), buffer.size() - zs_.avail_out);
    } while (ok_ && (zs_.avail_out == 0 || (flush == Z_FINISH && rc != Z_STREAM_END)));
  }
  z_stream zs_{};
  bool ok_ = false;
};

// Reads exact byte counts out of one zlib stream held in memory.
class Inflater {
 public:
  Inflater(const uint8_t* data, size_t size) {
    zs_.next_in = const_cast<Bytef*>(data);
    zs_.avail_in = static_cast<uInt>(size);
    ok_ = inflateInit(&zs_) == Z_OK;
  }
  ~Inflater() { inflateEnd(&zs_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  // Fills out[0, size); false (and why) when the stream is corrupt or ends first.
  bool read(uint8_t* out, size_t size, std::string* why) {
    if (!ok_) return failed("zlib could not start", why);
    zs_.next_out = out;
    zs_.avail_out = static_cast<uInt>(size);
    while (zs_.avail_out > 0) {
      if (ended_) return failed("the payload ends before its last tile", why);
      const int rc = inflate(&zs_, Z_NO_FLUSH);
      if (rc == Z_STREAM_END) {
        ended_ = true;
      } else if (rc == Z_BUF_ERROR) {  // no progress: the input ran out mid-stream
        return failed("the payload's zlib stream is cut short", why);
      } else if (rc != Z_OK) {
        return failed(std::string("the payload's zlib stream is corrupt (") +
                          (zs_.msg != nullptr ? zs_.msg : "zlib error " + std::to_string(rc)) + ")",
                      why);
      }
    }
    return true;
  }
  // True when the stream ends here and nothing follows it.
  bool atEnd(std::string* why) {
    if (!ended_) {
      uint8_t extra = 0;
      zs_.next_out = &extra;
      zs_.avail_out = 1;
      const int rc = inflate(&zs_, Z_NO_FLUSH);
      if (zs_.avail_out == 0) return failed("the payload holds more than the header's tiles", why);
      if (rc == Z_BUF_ERROR) return failed("the payload's zlib stream is cut short", why);
      if (rc != Z_STREAM_END) {
        return failed(std::string("the payload's zlib stream is corrupt (") +
                          (zs_.msg != nullptr ? zs_.msg : "zlib error " + std::to_string(rc)) + ")",
                      why);
      }
      ended_ = true;
    }
    if (zs_.avail_in != 0) return failed("bytes follow the payload's zlib stream", why);
    return true;
  }

 private:
  bool failed(const std::string& what, std::string* why) {
    *why = what;
    return false;
  }
  z_stream zs_{};
  bool ok_ = false;
  bool ended_ = false;
};

// The tile index places the grid keeps for `tiles` tiles spanning tx0..tx1 x ty0..ty1, checked
// against MapFileLimits; false (and why) beyond them.
bool indexSpanFits(uint64_t tiles, int64_t tx0, int64_t ty0, int64_t tx1, int64_t ty1,
                   std::string* why) {
  if (tiles == 0) return true;
  const uint64_t places =
      static_cast<uint64_t>(tx1 - tx0 + 1) * static_cast<uint64_t>(ty1 - ty0 + 1);
  const uint64_t cap =
      std::min(MapFileLimits::kMaxIndexTiles,
               std::max(MapFileLimits::kMinIndexTiles, MapFileLimits::kIndexTilesPerTile * tiles));
  if (places <= cap) return true;
  *why = "the tiles span " + std::to_string(places) + " tile places, more than " +
         std::to_string(cap) + " for " + std::to_string(tiles) + " tiles";
  return false;
}

bool finitePose(const Pose2& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}

Json poseJson(const Pose2& p) { return Json{{"x", p.x}, {"y", p.y}, {"theta", p.theta}}; }

// The member `key` of `j` as a finite number.
bool number(const Json& j, const char* key, double* out, std::string* why) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) {
    *why = std::string("'") + key + "' is missing or not a number";
    return false;
  }
  *out = it->get<double>();
  if (!std::isfinite(*out)) {
    *why = std::string("'") + key + "' is not finite";
    return false;
  }
  return true;
}

bool poseFromJson(const Json& j, const char* key, Pose2* pose, std::string* why) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_object()) {
    *why = std::string("'") + key + "' is missing or not an object";
    return false;
  }
  double x = 0.0, y = 0.0, theta = 0.0;
  if (!number(*it, "x", &x, why) || !number(*it, "y", &y, why) ||
      !number(*it, "theta", &theta, why)) {
    *why = std::string(key) + ": " + *why;
    return false;
  }
  *pose = Pose2(x, y, theta);
  return true;
}

bool stringMap(const Json& j, const char* key, std::map<std::string, std::string>* out,
               std::string* why) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_object()) {
    *why = std::string("'") + key + "' is missing or not an object";
    return false;
  }
  out->clear();
  for (const auto& [name, value] : it->items()) {
    if (!value.is_string()) {
      *why = std::string(key) + ": '" + name + "' is not a string";
      return false;
    }
    (*out)[name] = value.get<std::string>();
  }
  return true;
}

// The deepest nesting of arrays and objects in JSON text (strings skipped), counted without
// parsing; stops counting past `limit`.
int jsonNesting(const uint8_t* data, size_t size, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < size; ++i) {
    const uint8_t c = data[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

bool parseMetadata(const uint8_t* data, size_t size, double* resolution, MapFileInfo* info,
                   std::string* why) {
  if (jsonNesting(data, size, MapFileLimits::kMaxMetadataNesting) >
      MapFileLimits::kMaxMetadataNesting) {
    *why = "the metadata nests arrays or objects deeper than " +
           std::to_string(MapFileLimits::kMaxMetadataNesting) + " levels";
    return false;
  }
  Json j;
  try {
    j = Json::parse(data, data + size);
  } catch (const Json::exception& e) {
    *why = std::string("the metadata is not JSON: ") + e.what();
    return false;
  }
  if (!j.is_object()) {
    *why = "the metadata is not a JSON object";
    return false;
  }
  if (!number(j, "resolution", resolution, why)) return false;
  if (!(*resolution >= MapFileLimits::kMinResolution &&
        *resolution <= MapFileLimits::kMaxResolution)) {
    *why = "resolution " + std::to_string(*resolution) + " m is outside [" +
           std::to_string(MapFileLimits::kMinResolution) + ", " +
           std::to_string(MapFileLimits::kMaxResolution) + "]";
    return false;
  }
  if (!poseFromJson(j, "robot_pose", &info->robot_pose, why)) return false;
  if (!(std::abs(info->robot_pose.x) <= MapFileLimits::kMaxPoseCoordinate &&
        std::abs(info->robot_pose.y) <= MapFileLimits::kMaxPoseCoordinate)) {
    *why = "robot_pose: (" + std::to_string(info->robot_pose.x) + ", " +
           std::to_string(info->robot_pose.y) + ") m is farther than " +
           std::to_string(MapFileLimits::kMaxPoseCoordinate) + " m from the map frame's origin";
    return false;
  }
  info->has_odometry_pose = j.contains("odometry_pose");
  if (info->has_odometry_pose && !poseFromJson(j, "odometry_pose", &info->odometry_pose, why)) {
    return false;
  }
  const auto build = j.find("build");
  if (build == j.end() || !build->is_string()) {
    *why = "'build' is missing or not a string";
    return false;
  }
  info->build = build->get<std::string>();
  return stringMap(j, "parameters", &info->parameters, why) &&
         stringMap(j, "metadata", &info->metadata, why);
}

}  // namespace

bool MapFileInfo::operator==(const MapFileInfo& o) const {
  const auto same = [](const Pose2& a, const Pose2& b) {
    return a.x == b.x && a.y == b.y && a.theta == b.theta;
  };
  return same(robot_pose, o.robot_pose) && has_odometry_pose == o.has_odometry_pose &&
         (!has_odometry_pose || same(odometry_pose, o.odometry_pose)) && build == o.build &&
         parameters == o.parameters && metadata == o.metadata;
}

bool encodeMapFile(const EvidentialGridMap& map, const MapFileInfo& info, std::string* bytes,
                   std::string* error, MapFileStats* stats) {
  const double resolution = map.resolution();
  if (!(resolution >= MapFileLimits::kMinResolution &&
        resolution <= MapFileLimits::kMaxResolution)) {
    return fail(error, "cannot store resolution " + std::to_string(resolution) + " m");
  }
  if (!finitePose(info.robot_pose) || (info.has_odometry_pose && !finitePose(info.odometry_pose))) {
    return fail(error, "cannot store a pose that is not finite");
  }
  std::vector<std::pair<int, int>> coordinates;
  std::vector<const Tile*> tiles;
  map.forEachTile([&](int tx, int ty, const Tile& tile) {
    coordinates.emplace_back(tx, ty);
    tiles.push_back(&tile);
  });
  for (const auto& [tx, ty] : coordinates) {
    if (std::abs(tx) > MapFileLimits::kMaxTileCoordinate ||
        std::abs(ty) > MapFileLimits::kMaxTileCoordinate) {
      return fail(error, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) +
                             ") lies beyond what a map file holds");
    }
  }
  if (tiles.size() > MapFileLimits::kMaxTiles) {
    return fail(error, std::to_string(tiles.size()) + " tiles are more than a map file holds");
  }
  if (!coordinates.empty()) {  // what the reader would refuse is not written
    int64_t min_x = coordinates.front().first, max_x = min_x;
    for (const auto& c : coordinates) {
      min_x = std::min<int64_t>(min_x, c.first);
      max_x = std::max<int64_t>(max_x, c.first);
    }
    std::string why;
    if (!indexSpanFits(coordinates.size(), min_x, coordinates.front().second, max_x,
                       coordinates.back().second, &why)) {
      return fail(error, why);
    }
  }

  Json meta;
  meta["resolution"] = resolution;
  meta["robot_pose"] = poseJson(info.robot_pose);
  if (info.has_odometry_pose) meta["odometry_pose"] = poseJson(info.odometry_pose);
  meta["build"] = buildVersion();
  meta["parameters"] = info.parameters;
  meta["metadata"] = info.metadata;
  // Invalid UTF-8 in a name or value (a file name, say) is stored as U+FFFD, not refused.
  const std::string metadata = meta.dump(1, ' ', false, Json::error_handler_t::replace) + "\n";
  if (metadata.size() > MapFileLimits::kMaxMetadataBytes) {
    return fail(error, "the metadata (" + std::to_string(metadata.size()) +
                           " bytes) is more than a map file holds");
  }

  // Tiles in forEachTile's order: by ty, then tx, as the reader requires.
  std::string payload;
  Deflater deflater;
  if (!deflater.ok()) return fail(error, "zlib could not start");
  std::vector<uint8_t> buffer(std::max(kTileBytes, coordinates.size() * kCoordinateBytes));
  for (size_t i = 0; i < coordinates.size(); ++i) {
    for (int b = 0; b < 4; ++b) {
      buffer[i * 8 + b] =
          static_cast<uint8_t>(static_cast<uint32_t>(coordinates[i].first) >> (8 * b));
      buffer[i * 8 + 4 + b] =
          static_cast<uint8_t>(static_cast<uint32_t>(coordinates[i].second) >> (8 * b));
    }
  }
  deflater.append(buffer.data(), coordinates.size() * kCoordinateBytes, &payload);
  for (const Tile* tile : tiles) {
    encodeTile(*tile, buffer.data());
    deflater.append(buffer.data(), kTileBytes, &payload);
  }
  deflater.finish(&payload);
  if (!deflater.ok()) return fail(error, "zlib failed to compress the tiles");

  std::string& out = *bytes;
  out.clear();
  out.reserve(kHeaderBytes + metadata.size() + payload.size() + kTrailerBytes);
  out.append(reinterpret_cast<const char*>(kMagic.data()), kMagic.size());
  putU16(&out, kMapFormatVersion);
  putU32(&out, static_cast<uint32_t>(metadata.size()));
  putU32(&out, static_cast<uint32_t>(tiles.size()));
  putU64(&out, payload.size());
  putU32(&out, 0);  // reserved
  out += metadata;
  out += payload;
  putU32(&out, crc32Of(reinterpret_cast<const uint8_t*>(out.data()), out.size()));
  if (out.size() > MapFileLimits::kMaxFileBytes) {
    return fail(error, "the file would be " + std::to_string(out.size()) +
                           " bytes, more than a map file holds");
  }
  if (stats != nullptr) {
    stats->file_bytes = out.size();
    stats->tiles = tiles.size();
    stats->raw_payload_bytes = tiles.size() * (kCoordinateBytes + kTileBytes);
  }
  return true;
}

bool decodeMapFile(const uint8_t* data, size_t size, EvidentialGridMap* map, MapFileInfo* info,
                   std::string* error) {
  if (size == 0) return fail(error, "empty file");
  if (std::memcmp(data, kMagic.data(), std::min(size, kMagic.size())) != 0) {
    return fail(error, "not an evidential map file (no EVMAP signature)");
  }
  if (size < kHeaderBytes) {
    return fail(error, "truncated: " + std::to_string(size) + " bytes, shorter than the header");
  }
  const uint16_t version = getU16(data + 10);
  if (version > kMapFormatVersion) {
    return fail(error, "format version " + std::to_string(version) +
                           " is newer than this build reads (" + std::to_string(kMapFormatVersion) +
                           "): update evidential_slam");
  }
  if (version != kMapFormatVersion) {
    return fail(error, "format version " + std::to_string(version) +
                           " is not one this build reads (" + std::to_string(kMapFormatVersion) +
                           ")");
  }
  const uint32_t metadata_bytes = getU32(data + 12);
  const uint32_t tile_count = getU32(data + 16);
  const uint64_t payload_bytes = getU64(data + 20);
  if (getU32(data + 28) != 0) return fail(error, "reserved header bytes are not zero");
  if (metadata_bytes > MapFileLimits::kMaxMetadataBytes) {
    return fail(error, "the header claims " + std::to_string(metadata_bytes) +
                           " bytes of metadata, more than a map file holds");
  }
  if (tile_count > MapFileLimits::kMaxTiles) {
    return fail(error, "the header claims " + std::to_string(tile_count) +
                           " tiles, more than a map file holds");
  }
  if (payload_bytes > MapFileLimits::kMaxFileBytes) {
    return fail(error, "the header claims a payload of " + std::to_string(payload_bytes) +
                           " bytes, more than a map file holds");
  }
  const uint64_t expected = kHeaderBytes + uint64_t{metadata_bytes} + payload_bytes + kTrailerBytes;
  if (size < expected) {
    return fail(error, "truncated: " + std::to_string(size) + " bytes, the header says " +
                           std::to_string(expected));
  }
  if (size > expected) {
    return fail(error, std::to_string(size - expected) +
                           " bytes follow the end the header gives (" + std::to_string(expected) +
                           " bytes)");
  }
  const uint32_t stored_crc = getU32(data + size - kTrailerBytes);
  const uint32_t crc = crc32Of(data, size - kTrailerBytes);
  if (crc != stored_crc) return fail(error, "checksum mismatch: the file is corrupt");

  double resolution = 0.0;
  MapFileInfo read_info;
  std::string why;
  if (!parseMetadata(data + kHeaderBytes, metadata_bytes, &resolution, &read_info, &why)) {
    return fail(error, "bad metadata: " + why);
  }

  // The tiles' bytes cannot exceed what deflate packs into the payload at best: a header that
  // claims more is refused before the coordinates are allocated.
  const uint64_t raw_bytes = uint64_t{tile_count} * (kCoordinateBytes + kTileBytes);
  if (raw_bytes > kDeflateMaxRatio * payload_bytes + 64) {
    return fail(error, "the header claims " + std::to_string(tile_count) + " tiles, more than a " +
                           std::to_string(payload_bytes) + "-byte payload can hold");
  }
  Inflater inflater(data + kHeaderBytes + metadata_bytes, static_cast<size_t>(payload_bytes));
  std::vector<uint8_t> buffer(std::max<size_t>(kTileBytes, tile_count * kCoordinateBytes));
  if (!inflater.read(buffer.data(), tile_count * kCoordinateBytes, &why)) {
    return fail(error, why);
  }
  std::vector<std::pair<int32_t, int32_t>> coordinates(tile_count);
  int64_t min_x = 0, min_y = 0, max_x = -1, max_y = -1;
  for (uint32_t i = 0; i < tile_count; ++i) {
    const int32_t tx = static_cast<int32_t>(getU32(&buffer[i * kCoordinateBytes]));
    const int32_t ty = static_cast<int32_t>(getU32(&buffer[i * kCoordinateBytes + 4]));
    if (tx < -MapFileLimits::kMaxTileCoordinate || tx > MapFileLimits::kMaxTileCoordinate ||
        ty < -MapFileLimits::kMaxTileCoordinate || ty > MapFileLimits::kMaxTileCoordinate) {
      return fail(error, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) +
                             ") lies beyond what a map file holds");
    }
    if (i > 0 && std::make_pair(ty, tx) <=
                     std::make_pair(coordinates[i - 1].second, coordinates[i - 1].first)) {
      return fail(error, "the tile list is not in order or repeats a tile");
    }
    coordinates[i] = {tx, ty};
    min_x = i == 0 ? tx : std::min<int64_t>(min_x, tx);
    max_x = i == 0 ? tx : std::max<int64_t>(max_x, tx);
    min_y = i == 0 ? ty : min_y;  // ty is non-decreasing
    max_y = ty;
  }
  if (!indexSpanFits(tile_count, min_x, min_y, max_x, max_y, &why)) return fail(error, why);

  EvidentialGridMap read_map(resolution);
  if (tile_count > 0) {
    read_map.reserveTiles(static_cast<int>(min_x), static_cast<int>(min_y), static_cast<int>(max_x),
                          static_cast<int>(max_y));
  }
  for (const auto& [tx, ty] : coordinates) {
    if (!inflater.read(buffer.data(), kTileBytes, &why)) return fail(error, why);
    int bad = 0;
    if (!decodeTile(buffer.data(), &read_map.mutableTile(tx, ty), &bad)) {
      return fail(error, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + ") cell " +
                             std::to_string(bad) + " holds bits no cell can hold");
    }
  }
  if (!inflater.atEnd(&why)) return fail(error, why);
  *map = std::move(read_map);
  *info = std::move(read_info);
  return true;
}

std::string resolveMapFilePath(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return (std::filesystem::path(path) / kMapFileName).string();
  }
  return path;
}

bool writeMapFile(const std::string& path, const EvidentialGridMap& map, const MapFileInfo& info,
                  std::string* error, MapFileStats* stats, AtomicFiles* staged) {
  std::string bytes, why;
  if (!encodeMapFile(map, info, &bytes, &why, stats)) return fail(error, path + ": " + why);
  // Temporary name, fsync, rename (atomic_files.h): a failed write leaves the previous map.
  const auto write = [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
  };
  if (staged != nullptr) return staged->add(path, write, error);
  return writeFileAtomically(path, write, error);
}

bool readMapFile(const std::string& path, EvidentialGridMap* map, MapFileInfo* info,
                 std::string* error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return fail(error, path + ": no such file");
  if (fs::is_directory(status)) return fail(error, path + ": is a directory, not a map file");
  if (!fs::is_regular_file(status)) return fail(error, path + ": not a regular file");
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return fail(error, path + ": cannot read (" + ec.message() + ")");
  if (size > MapFileLimits::kMaxFileBytes) {
    return fail(error, path + ": " + std::to_string(size) + " bytes, more than a map file holds");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(error, path + ": cannot open");
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<uintmax_t>(in.gcount()) != size) return fail(error, path + ": read error");
  std::string why;
  if (!decodeMapFile(bytes.data(), bytes.size(), map, info, &why)) {
    return fail(error, path + ": " + why);
  }
  return true;
}

}  // namespace io
}  // namespace evidential_slam
