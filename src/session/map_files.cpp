#include "evidential_slam/session/map_files.h"

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/layer_writer.h"
#include "evidential_slam/io/octomap_export.h"
#include "evidential_slam/io/trajectory_image.h"
#include "evidential_slam/io/trajectory_io.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

bool makeDirectory(const fs::path& dir, std::string* error) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!ec && fs::is_directory(dir)) return true;
  if (error != nullptr) {
    *error = "cannot create output directory " + io::quotedPath(dir.string()) + ": " +
             (ec ? ec.message() : "not a directory");
  }
  return false;
}

bool writeConflictCsv(const std::string& path, const std::vector<ConflictRecord>& rows,
                      io::AtomicFiles* files, std::string* error) {
  return files->add(
      path,
      [&](std::ostream& f) {
        f << "# per processed scan: stamp (s), the external conflict (bits) and the conflict mass "
             "m(0) (summed over cells) it added to the best map, the part of that mass added in "
             "the map's open space, the alarm's baseline (the largest contradiction_added of "
             "recent quiet scans), contradiction_added / baseline, alarm (1 = above threshold on "
             "conflict_alarm_confirm_scans scans in a row), and the alarm's input "
             "contradiction_added: the cells of confident evidence the scan contradicted, each "
             "weighted by its conflict K (anomaly.h: hits in open space and passes through "
             "obstacles)\n"
          << "stamp,ec_added_bits,conflict_mass_added,open_space_conflict_added,baseline,ratio,"
             "alarm,contradiction_added\n";
        char line[200];
        for (const ConflictRecord& r : rows) {
          std::snprintf(line, sizeof(line), "%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.6g\n", r.stamp,
                        r.ec_added_bits, r.conflict_mass_added, r.open_space_conflict_added,
                        r.alarm.baseline, r.alarm.ratio, r.alarm.alarm ? 1 : 0, r.alarm.added);
          f << line;
        }
        return static_cast<bool>(f);
      },
      error);
}

}  // namespace

MapSave captureMapSave(const MappingSession& session) {
  MapSave save;
  for (const auto& [name, value] : parameterValues(session.parameters())) {
    save.info.parameters[name] = value;
  }
  if (session.localizing()) {
    const Localizer& localizer = session.localizer();
    save.map = localizer.map();
    save.anomaly = localizer.anomaly();
    save.trajectory = localizer.trajectory();
    save.info.robot_pose = localizer.estimate().mean;
    save.info.metadata["mode"] = "localization";
    save.info.metadata["scans_received"] = std::to_string(localizer.stats().scans_received);
    save.info.metadata["scans_processed"] = std::to_string(localizer.stats().scans_processed);
    if (!save.trajectory.empty()) {
      char stamp[40];
      std::snprintf(stamp, sizeof(stamp), "%.6f", save.trajectory.back().stamp);
      save.info.metadata["stamp"] = stamp;
    }
    return save;
  }
  const SlamEngine& engine = session.engine();
  save.map = engine.bestMap();
  save.anomaly = engine.bestAnomaly();
  save.trajectory = engine.bestTrajectory();
  save.conflicts = session.conflictLog();
  save.info.robot_pose = engine.bestPose();
  save.info.has_odometry_pose = engine.stats().scans_received > 0;
  save.info.odometry_pose = engine.lastOdometry();
  save.info.metadata["scans_received"] = std::to_string(engine.stats().scans_received);
  save.info.metadata["scans_processed"] = std::to_string(engine.stats().scans_processed);
  if (!save.trajectory.empty()) {
    char stamp[40];
    std::snprintf(stamp, sizeof(stamp), "%.6f", save.trajectory.back().stamp);
    save.info.metadata["stamp"] = stamp;
  }
  save.info.metadata["mapping_paused"] = session.mappingPaused() ? "true" : "false";
  return save;
}

bool writeMapFiles(const std::string& dir, const MapSave& save, const SessionConfig& config,
                   MapFilesReport* report, std::string* error, io::AtomicFiles* staged) {
  *report = MapFilesReport();
  io::AtomicFiles own;
  io::AtomicFiles* files = staged != nullptr ? staged : &own;
  const fs::path root(dir);
  const fs::path layers_dir = root / "layers";
  if (!makeDirectory(root, error)) return false;

  // The lossless map first: it is what a later run continues from.
  const std::string evmap = (root / io::kMapFileName).string();
  if (!io::writeMapFile(evmap, save.map, save.info, error, &report->map_file_stats, files)) {
    return false;
  }
  report->files.push_back(evmap);
  report->map_file = evmap;
  const std::string tum = (root / "trajectory.tum").string();
  if (!io::writeTumTrajectory(tum, save.trajectory, error, files)) return false;
  report->files.push_back(tum);
  const std::string csv = (root / "conflict.csv").string();
  if (!writeConflictCsv(csv, save.conflicts, files, error)) return false;
  report->files.push_back(csv);

  const EvidentialGridMap& map = save.map;
  if (!denseLayersFit(map, config, &report->layers_skipped)) {
    report->layers_skipped = "layers/ not written: " + report->layers_skipped;
  } else {
    if (!makeDirectory(layers_dir, error)) return false;
    // trajectory.png is drawn over the pignistic layer.
    const uint32_t wanted = save.anomaly_layer_only
                                ? layerBit(Layer::kPignistic) | layerBit(Layer::kAnomaly)
                                : kAllLayers;
    const LayerRaster raster = extractLayers(map, 10, &save.anomaly, wanted);
    io::LayerWriterConfig layer_config;
    layer_config.occupied_thresh = config.occupied_thresh;
    layer_config.free_thresh = config.free_thresh;
    if (save.anomaly_layer_only) {
      if (!io::writeLayerFiles(raster, Layer::kAnomaly, layers_dir.string(), layer_config,
                               &report->files, error, files)) {
        return false;
      }
    } else {
      io::LayerWriteResult written;
      if (!io::writeLayers(raster, layers_dir.string(), layer_config, &written, error, files) ||
          !io::writeMapServerLayers(raster, layers_dir.string(), layer_config, &report->files,
                                    error, files)) {
        return false;
      }
      report->files.insert(report->files.end(), written.files.begin(), written.files.end());
      report->external_conflict_scale = written.external_conflict_scale;
    }
    io::TrajectoryImage picture;
    picture.path.reserve(save.trajectory.size());
    for (const StampedPose& p : save.trajectory) picture.path.push_back(p.pose);
    picture.reference = save.reference_path;
    picture.caption = save.trajectory_caption;
    const std::string png = (root / "trajectory.png").string();
    if (!io::writeTrajectoryImage(raster, picture, png, error, files)) return false;
    report->files.push_back(png);
    report->map_width = raster.width;
    report->map_height = raster.height;
    report->anomaly_layer_only = save.anomaly_layer_only;
  }

  if (config.export_octomap) {
    const fs::path octomap_dir = root / "octomap";
    if (!makeDirectory(octomap_dir, error)) return false;
    io::OctomapExportConfig octomap_config;
    octomap_config.z_min = config.octomap_z_min;
    octomap_config.z_max = config.octomap_z_max;
    io::OctomapExportResult result;
    if (!io::exportOctomap(map, save.anomaly, octomap_config, (octomap_dir / "map").string(),
                           &result, error, files)) {
      return false;
    }
    OctomapFilesReport octomap;
    for (const io::OctomapExportFile& f : result.files) {
      octomap.files.push_back(f.path);
      octomap.bytes.push_back(f.bytes);
      report->files.push_back(f.path);
    }
    octomap.seconds = result.seconds;
    octomap.z_layers = result.z_layers;
    octomap.voxels = result.voxels;
    report->octomap = octomap;
  }
  return staged != nullptr || own.commit(error);
}

bool loadMapFile(const std::string& path, LoadedMap* out, std::string* error) {
  LoadedMap loaded;
  loaded.path = io::resolveMapFilePath(path);
  if (!io::readMapFile(loaded.path, &loaded.map, &loaded.info, error)) return false;
  *out = std::move(loaded);
  return true;
}

bool denseLayersFit(const EvidentialGridMap& map, const SessionConfig& config, std::string* why) {
  return denseLayersFit(map.observedBox(), map.resolution(), config, why);
}

bool denseLayersFit(const CellBox& box, double resolution, const SessionConfig& config,
                    std::string* why) {
  if (box.empty() || config.max_layer_cells <= 0) return true;
  const double cells = static_cast<double>(box.width()) * static_cast<double>(box.height());
  if (cells <= config.max_layer_cells) return true;
  if (why != nullptr) {
    char text[300];
    // About 60 bytes a cell: ten float32 layers, observed, the PNGs and PGMs while they are made.
    std::snprintf(text, sizeof(text),
                  "the observed box is %d x %d cells (%.0f m x %.0f m), %.3g cells, more than "
                  "max_layer_cells (%d); its dense layers would need about %.1f GB",
                  box.width(), box.height(), box.width() * resolution, box.height() * resolution,
                  cells, config.max_layer_cells, cells * 60.0 / 1e9);
    *why = text;
  }
  return false;
}

OutputFolders::OutputFolders(const std::string& dir) : dir_(dir) {
  if (dir_.empty()) return;
  std::error_code ec;
  const fs::path root(dir_);
  dir_existed_ = fs::exists(root, ec) || ec;  // unsure: keep it
  layers_existed_ = fs::exists(root / "layers", ec) || ec;
  octomap_existed_ = fs::exists(root / "octomap", ec) || ec;
}

void OutputFolders::removeCreated() const {
  if (dir_.empty()) return;
  std::error_code ec;
  const fs::path root(dir_);
  if (!dir_existed_) {
    fs::remove_all(root, ec);
    return;
  }
  if (!layers_existed_) fs::remove_all(root / "layers", ec);
  if (!octomap_existed_) fs::remove_all(root / "octomap", ec);
}

}  // namespace evidential_slam
