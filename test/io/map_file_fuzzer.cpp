// libFuzzer target for decodeMapFile (built with clang by cmake/MapFileTargets.cmake, run by
// test_map_file_fuzz). Each input is decoded three ways, so that mutations reach past the checks
// that guard the rest: as it is; with its CRC trailer recomputed (past the checksum); and with
// the bytes after its metadata taken as the uncompressed tiles, compressed here and framed with
// true sizes and CRC (past zlib, into the tile list and the cells). Besides "no crash, no leak, no
// undefined behaviour" under ASan/UBSan: a rejected input gets a one-line error and leaves the
// outputs untouched, and an accepted one re-encodes to a file that decodes to the same map and
// metadata. ES_FUZZ_EXPECT_VALID=1 makes a rejected input (as it is) abort: the test uses it to
// check that its valid seeds are read by this build.
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "evidential_slam/io/map_file.h"

namespace {

namespace es = evidential_slam;
namespace io = evidential_slam::io;

[[noreturn]] void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz invariant broken: %s %s\n", what, detail.c_str());
  std::abort();
}

void putU32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint32_t getU32(const uint8_t* p) {
  return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}

bool sameMaps(const es::EvidentialGridMap& a, const es::EvidentialGridMap& b) {
  if (a.resolution() != b.resolution() || a.allocatedTiles() != b.allocatedTiles()) return false;
  bool same = true;
  a.forEachTile([&](int tx, int ty, const es::EvidentialGridMap::Tile& tile) {
    const es::EvidentialGridMap::Tile* other = b.tile(tx, ty);
    if (other == nullptr) {
      same = false;
      return;
    }
    for (int k = 0; k < es::EvidentialGridMap::kTileCells; ++k) {
      const es::Cell& x = tile.cells[k];
      const es::Cell& y = other->cells[k];
      if (x.occupiedSteps() != y.occupiedSteps() || x.freeSteps() != y.freeSteps() ||
          x.lambdaBits() != y.lambdaBits()) {
        same = false;
      }
    }
  });
  return same;
}

// Decodes `bytes` and checks the invariants; true when it was accepted.
bool check(const std::vector<uint8_t>& bytes) {
  es::EvidentialGridMap map(0.123);
  io::MapFileInfo info;
  info.metadata["untouched"] = "yes";
  std::string error;
  if (!io::decodeMapFile(bytes.data(), bytes.size(), &map, &info, &error)) {
    if (error.empty() || error.find('\n') != std::string::npos) die("bad error message:", error);
    if (map.resolution() != 0.123 || map.allocatedTiles() != 0 || info.metadata.size() != 1) {
      die("outputs changed on an error:", error);
    }
    return false;
  }
  // Observed cells lie within the allocated tiles (a sanity check of the grid the reader built).
  const es::CellBox observed = map.observedBox(), allocated = map.allocatedBox();
  if (!observed.empty() && (observed.min_x < allocated.min_x || observed.max_x > allocated.max_x ||
                            observed.min_y < allocated.min_y || observed.max_y > allocated.max_y)) {
    die("observed cells outside the allocated tiles", "");
  }
  std::string again;
  if (!io::encodeMapFile(map, info, &again, &error)) die("accepted map not writable:", error);
  es::EvidentialGridMap map2;
  io::MapFileInfo info2;
  if (!io::decodeMapFile(reinterpret_cast<const uint8_t*>(again.data()), again.size(), &map2,
                         &info2, &error)) {
    die("re-encoded map not readable:", error);
  }
  info.build = info2.build;  // the writer records its own build
  if (!sameMaps(map, map2) || !(info == info2)) die("re-encoded map differs", "");
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool expect_valid = [] {
    const char* v = std::getenv("ES_FUZZ_EXPECT_VALID");
    return v != nullptr && std::strcmp(v, "1") == 0;
  }();
  constexpr size_t kHeader = 32, kTrailer = 4;
  std::vector<uint8_t> bytes(data, data + size);
  const bool accepted = check(bytes);
  if (expect_valid && !accepted) die("valid seed rejected", "");
  if (size < kHeader + kTrailer) return 0;

  // Past the checksum.
  const uLong crc = crc32(0L, bytes.data(), static_cast<uInt>(size - kTrailer));
  putU32(&bytes[size - kTrailer], static_cast<uint32_t>(crc));
  check(bytes);

  // Past zlib: what follows the metadata (without the trailer) is the tiles' raw bytes.
  const uint32_t metadata_bytes = getU32(data + 12);
  if (metadata_bytes > size - kHeader - kTrailer) return 0;
  const uint8_t* raw = data + kHeader + metadata_bytes;
  const size_t raw_size = size - kHeader - kTrailer - metadata_bytes;
  std::vector<uint8_t> compressed(compressBound(static_cast<uLong>(raw_size)));
  uLongf compressed_size = static_cast<uLongf>(compressed.size());
  if (compress2(compressed.data(), &compressed_size, raw, static_cast<uLong>(raw_size), 1) !=
      Z_OK) {
    die("zlib failed", "");
  }
  std::vector<uint8_t> framed(data, data + kHeader + metadata_bytes);
  const uint64_t payload = compressed_size;
  for (int i = 0; i < 8; ++i) framed[20 + i] = static_cast<uint8_t>(payload >> (8 * i));
  framed.insert(framed.end(), compressed.begin(), compressed.begin() + compressed_size);
  framed.resize(framed.size() + kTrailer);
  putU32(
      &framed[framed.size() - kTrailer],
      static_cast<uint32_t>(crc32(0L, framed.data(), static_cast<uInt>(framed.size() - kTrailer))));
  check(framed);
  return 0;
}
