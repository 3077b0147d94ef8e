// The lossless evidential map file (format spec: docs/map_format.md): every allocated tile of an
// EvidentialGridMap with its cells' stored bits, the resolution, the robot's pose when saved and
// what made the map (build, parameters, free-form metadata), zlib-compressed and CRC-checked.
// A map written and read back is bit-identical: same tiles, same Cell bits. The reader gives any
// damaged or foreign file a one-line error and never allocates more than the file can justify.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace io {

// How a front end uses it.
// Saving: writeMapFile(<out>/kMapFileName, engine.bestMap(), info) with info.robot_pose =
//   engine.bestPose(), info.odometry_pose = engine.lastOdometry() (has_odometry_pose = true), the
//   parameter table as info.parameters and e.g. the log, scan count and stamp as info.metadata.
// Continuing: readMapFile(resolveMapFilePath(arg), &map, &info); construct the SlamEngine with
//   config.resolution = map.resolution() (startFromMap refuses another); then
//   engine.startFromMap(map, pose, &why, odometry) with pose = info.robot_pose or a pose the user
//   gave, and odometry = &info.odometry_pose only when the scans to come share the saved
//   odometry frame (the same log continued), else nullptr.

// The name front ends give the file in their output directory.
constexpr const char* kMapFileName = "map.evmap";
// `path` itself, or path/kMapFileName when `path` is a directory (`--load-map DIR`).
std::string resolveMapFilePath(const std::string& path);
// The format version this build writes and the only one it reads.
constexpr uint16_t kMapFormatVersion = 1;

// Everything in a map file beside the cells.
struct MapFileInfo {
  Pose2 robot_pose;  // map frame, when the map was saved (SlamEngine::bestPose())
  // The odometry pose (odom frame) at the same moment. It lets a run that continues the same log
  // or odometry frame start at the exact pose (SlamEngine::startFromMap's `odometry`); meaningless
  // once the odometry frame has been reset (another log, a restarted robot).
  bool has_odometry_pose = false;
  Pose2 odometry_pose;
  // The build that wrote the file (buildVersion(); set by the writer, whatever is passed in).
  std::string build;
  // The parameters that made the map, name -> value as text (the caller's parameter table).
  std::map<std::string, std::string> parameters;
  // Free-form provenance, e.g. "source" (the log), "scans_processed", "stamp".
  std::map<std::string, std::string> metadata;

  bool operator==(const MapFileInfo& o) const;
};

// Sizes of a written file, for reports.
struct MapFileStats {
  uint64_t file_bytes = 0;
  uint64_t tiles = 0;
  uint64_t raw_payload_bytes = 0;  // the tiles' bytes before compression
};

// Encodes `map` and `info` into the bytes of a map file. False (and a one-line `error`) when the
// map or the poses cannot be stored (a non-finite pose, a resolution outside the readable range).
bool encodeMapFile(const EvidentialGridMap& map, const MapFileInfo& info, std::string* bytes,
                   std::string* error, MapFileStats* stats = nullptr);
// Decodes the bytes of a map file. False (and a one-line `error`) for anything but a valid file
// of a version this build reads; `map` and `info` are then untouched.
bool decodeMapFile(const uint8_t* data, size_t size, EvidentialGridMap* map, MapFileInfo* info,
                   std::string* error);

class AtomicFiles;
// Writes `path` (through a temporary file renamed over it, so an existing map is never left
// half-written; staged into `staged` when given, to be renamed with the rest of its set). The
// error names the file.
bool writeMapFile(const std::string& path, const EvidentialGridMap& map, const MapFileInfo& info,
                  std::string* error, MapFileStats* stats = nullptr,
                  AtomicFiles* staged = nullptr);
// Reads `path`. The error names the file: "map.evmap: truncated: ...".
bool readMapFile(const std::string& path, EvidentialGridMap* map, MapFileInfo* info,
                 std::string* error);

// The reader's limits (docs/map_format.md): beyond them a file is refused before anything is
// allocated for it.
struct MapFileLimits {
  static constexpr uint64_t kMaxFileBytes = uint64_t{1} << 31;      // 2 GiB
  static constexpr uint32_t kMaxMetadataBytes = uint32_t{1} << 24;  // 16 MiB
  static constexpr int kMaxMetadataNesting = 16;            // the writer nests 2 levels deep
  static constexpr uint32_t kMaxTiles = uint32_t{1} << 22;  // 32 GiB of cells
  static constexpr int32_t kMaxTileCoordinate = 1 << 20;    // |tx|, |ty|
  // The tile index spans at most max(kMinIndexTiles, kIndexTilesPerTile * tiles) tiles and never
  // more than kMaxIndexTiles (16 bytes each).
  static constexpr uint64_t kMinIndexTiles = uint64_t{1} << 16;
  static constexpr uint64_t kIndexTilesPerTile = 4096;
  static constexpr uint64_t kMaxIndexTiles = uint64_t{1} << 24;
  static constexpr double kMinResolution = 1e-3;  // m
  static constexpr double kMaxResolution = 1e2;   // m
  // |robot_pose.x|, |robot_pose.y|: the parameter table's largest max_map_extent (a test checks).
  static constexpr double kMaxPoseCoordinate = 1e5;  // m
};

}  // namespace io
}  // namespace evidential_slam
