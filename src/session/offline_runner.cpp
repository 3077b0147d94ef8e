// The offline rawlog runner. See offline_runner.h.
#include "evidential_slam/session/offline_runner.h"

#include <malloc.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/profile.h"
#include "evidential_slam/io/atomic_files.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/progress.h"
#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/io/summary.h"
#include "evidential_slam/session/map_files.h"
#include "evidential_slam/session/session.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

// Returns the heap's free pages to the system (glibc keeps freed memory mapped otherwise).
void releaseFreeHeapMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

// Rejected scans are reported one by one only this often; the rest are counted.
constexpr uint64_t kRejectionsShown = 3;

// One row of localization.csv: the estimate after an update.
struct LocalizationRow {
  double stamp;
  PoseEstimate estimate;
  LocalizationUpdate update;
};

class Run {
 public:
  Run(const OfflineOptions& o, std::FILE* out, std::FILE* err, bool tty)
      : opt_(o), out_(out), err_(err), tty_(tty) {}

  int execute();

 private:
  int fail(int code, const std::string& message) {
    if (progress_) progress_->clearLine();
    std::fprintf(err_, "error: %s\n", message.c_str());
    return code;
  }
  void warn(const std::string& message, bool keep = true) {
    if (keep) summary_.warnings.push_back(message);
    if (opt_.quiet) return;
    if (progress_) progress_->clearLine();
    std::fprintf(err_, "warning: %s\n", message.c_str());
  }
  // Starts `session` on the loaded map (or an empty one) at --initial-pose or the saved pose.
  bool startSession(MappingSession* session, const LoadedMap& loaded, const std::string& source,
                    std::string* why);
  // --localize-only: starts `session`'s Localizer on the loaded map.
  bool startLocalization(MappingSession* session, const LoadedMap& loaded, std::string* why);

  const OfflineOptions& opt_;
  std::FILE* out_;
  std::FILE* err_;
  bool tty_;
  std::unique_ptr<ProgressBar> progress_;
  RunSummary summary_;
  std::vector<StampedPose> truth_;
  std::vector<StampedPose> odometry_path_;
  fs::path out_dir_;
  AtomicFiles outputs_;  // every output file, staged until the run has written them all
  std::vector<LocalizationRow> localization_rows_;
};

bool Run::startLocalization(MappingSession* session, const LoadedMap& loaded, std::string* why) {
  LocalizationStart start;
  start.global = opt_.global_localization;
  start.pose = opt_.initial_pose;
  const LocalizationConfig& c = opt_.params.localization;
  start.covariance.diagonal() << c.initial_cov_xx, c.initial_cov_yy, c.initial_cov_aa;
  if (opt_.has_initial_covariance) {
    start.covariance.diagonal() << opt_.initial_covariance[0], opt_.initial_covariance[1],
        opt_.initial_covariance[2];
  }
  if (!session->startLocalization(loaded.map, start, why)) {
    *why = loaded.path + ": " + *why;
    return false;
  }
  StartSummary summary;
  summary.map_file = loaded.path;
  summary.map_tiles = loaded.map.allocatedTiles();
  summary.x = start.pose.x;
  summary.y = start.pose.y;
  summary.theta = start.pose.theta;
  summary.pose_from = start.global            ? "--global"
                      : opt_.has_initial_pose ? "--initial-pose"
                                              : "default (0, 0, 0)";
  summary_.start = summary;
  return true;
}

// Writes localization.csv: per update, the estimate with its covariance and the particles.
bool writeLocalizationCsv(const std::string& path, const std::vector<LocalizationRow>& rows,
                          AtomicFiles* files, std::string* error) {
  return files->add(
      path,
      [&](std::ostream& f) {
        f << "# per localization update: stamp (s), the estimate (m, m, rad; map frame) and its "
             "covariance (m^2, m*rad, rad^2), the particles after the update, resampled (1 = "
             "yes), the mean log plausibility per weighed beam, the anomaly the scan added "
             "(bits), what it contradicted (the conflict alarm's input, about cells), the "
             "conflict alarm (1 = on), the particles drawn again by kidnap_recovery (1 = yes), the "
             "scan's log plausibility per weighed beam under the predicted cloud (the kidnap "
             "alarm's input), how far it fell below the alarm's baseline median in envelopes "
             "(the deepest recent fall), the kidnap alarm (1 = on)\n"
          << "stamp,x,y,theta,cov_xx,cov_xy,cov_xa,cov_yy,cov_ya,cov_aa,particles,resampled,"
             "mean_log_plausibility,anomaly_added_bits,contradiction,alarm,respread,log_evidence,"
             "kidnap_ratio,kidnap_alarm\n";
        char line[400];
        for (const LocalizationRow& r : rows) {
          const Pose2& m = r.estimate.mean;
          const Eigen::Matrix3d& c = r.estimate.covariance;
          std::snprintf(
              line, sizeof(line),
              "%.6f,%.6f,%.6f,%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%zu,%d,%.6g,%.6g,%.6g,%d,"
              "%d,%.6g,%.4g,%d\n",
              r.stamp, m.x, m.y, m.theta, c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2), c(2, 2),
              r.update.particles, r.update.resampled ? 1 : 0, r.update.mean_log_plausibility,
              r.update.anomaly_added_bits, r.update.contradiction, r.update.alarm.alarm ? 1 : 0,
              r.update.respread ? 1 : 0, r.update.log_evidence, r.update.kidnap_alarm.ratio,
              r.update.kidnap_alarm.alarm ? 1 : 0);
          f << line;
        }
        return static_cast<bool>(f);
      },
      error);
}

bool Run::startSession(MappingSession* session, const LoadedMap& loaded, const std::string& source,
                       std::string* why) {
  StartSummary start;
  const bool have_map = !loaded.path.empty();
  const EvidentialGridMap empty(opt_.params.slam.resolution);
  const EvidentialGridMap& map = have_map ? loaded.map : empty;
  Pose2 pose = opt_.initial_pose;
  start.pose_from = "--initial-pose";
  // The saved odometry pose places the first scan only when this run continues the log the map
  // was made from: the same odometry frame (map_file.h).
  const Pose2* anchor = nullptr;
  if (have_map && !opt_.has_initial_pose) {
    pose = loaded.info.robot_pose;
    start.pose_from = "map file";
    const auto saved_source = loaded.info.metadata.find("source");
    if (loaded.info.has_odometry_pose && saved_source != loaded.info.metadata.end() &&
        saved_source->second == source) {
      anchor = &loaded.info.odometry_pose;
    }
  }
  if (have_map && std::abs(map.resolution() - opt_.params.slam.resolution) > 1e-9) {
    char text[160];
    std::snprintf(text, sizeof(text), "the loaded map's resolution (%g m) replaces %g m",
                  map.resolution(), opt_.params.slam.resolution);
    warn(text);
  }
  if (!session->startFromMap(map, pose, why, anchor)) {
    *why = (have_map ? loaded.path + ": " : std::string("--initial-pose: ")) + *why;
    return false;
  }
  start.map_file = loaded.path;
  start.map_tiles = map.allocatedTiles();
  start.x = pose.x;
  start.y = pose.y;
  start.theta = pose.theta;
  start.odometry_anchored = anchor != nullptr;
  summary_.start = start;
  return true;
}

int Run::execute() {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!opt_.params.isValid(&why)) return fail(kExitUsage, "invalid parameters: " + why);

  summary_.mode = opt_.localize_only ? "localization" : "slam";
  summary_.rawlog = opt_.rawlog;
  summary_.ground_truth = opt_.ground_truth;
  summary_.config_files = opt_.config_files;
  summary_.parameters = opt_.parameters;
  summary_.parameter_values = parameterValues(opt_.params);
  const SlamConfig& slam = opt_.params.slam;
  summary_.particles = slam.particles;
  summary_.resolution = slam.resolution;
  summary_.seed = static_cast<uint64_t>(slam.seed);
  summary_.threads = slam.threads;
  for (const std::string& name : opt_.ignored) {
    warn("'" + name + "' in a config file is a parameter of the ROS node only: not used here");
  }

  if (!opt_.ground_truth.empty() && !readGroundTruth(opt_.ground_truth, &truth_, &why)) {
    return fail(kExitBadInput, why);
  }
  LoadedMap loaded;
  if (!opt_.load_map.empty() && !loadMapFile(opt_.load_map, &loaded, &why)) {
    return fail(kExitBadInput, why);
  }

  // Pre-pass: early, clear errors and the total for the progress line.
  RawlogReaderConfig reader_config;
  reader_config.laser_label = opt_.laser_label;
  reader_config.stamps = stampPolicy(opt_.params.session);
  RawlogSurvey survey;
  if (!surveyRawlog(opt_.rawlog, reader_config, &survey, &why)) return fail(kExitBadInput, why);
  if (survey.status == RawlogReader::Status::kError) return fail(kExitBadInput, survey.message);
  const std::string label_note =
      opt_.laser_label.empty() ? "" : " with label '" + opt_.laser_label + "'";
  if (survey.counts.scans == 0) {
    return fail(kExitBadInput, "no 2-D laser scans (CObservation2DRangeScan)" + label_note +
                                   " in '" + opt_.rawlog + "'");
  }
  if (survey.counts.odometry_samples == 0) {
    return fail(kExitBadInput, "no odometry in '" + opt_.rawlog +
                                   "' (needs CActionRobotMovement2D or CObservationOdometry)");
  }
  if (survey.counts.scans_emitted == 0) {
    return fail(kExitBadInput, "no scan in '" + opt_.rawlog + "' has odometry near its time");
  }
  summary_.rawlog_format = toString(survey.format);
  if (opt_.first_scan >= survey.counts.scans_emitted) {
    return fail(kExitBadInput, "--first-scan " + std::to_string(opt_.first_scan) + ": '" +
                                   opt_.rawlog + "' has " +
                                   std::to_string(survey.counts.scans_emitted) + " usable scans");
  }

  out_dir_ = opt_.out_dir;
  std::error_code ec;
  fs::create_directories(out_dir_, ec);
  if (ec || !fs::is_directory(out_dir_)) {
    return fail(kExitBadInput, "cannot create output directory " + quotedPath(out_dir_.string()) +
                                   ": " + (ec ? ec.message() : "not a directory"));
  }

  RawlogReader reader(reader_config);
  if (!reader.open(opt_.rawlog, &why)) return fail(kExitBadInput, why);

  uint64_t total = survey.counts.scans_emitted - opt_.first_scan;
  if (opt_.max_scans > 0 && opt_.max_scans < total) total = opt_.max_scans;
  if (!opt_.quiet) progress_ = std::make_unique<ProgressBar>(err_, total, tty_);

  // --profile: the filter reports its sections to this profiler while the log is processed.
  std::unique_ptr<Profiler> profiler;
  if (opt_.profile) {
    profiler = std::make_unique<Profiler>();
    profiler->floor_enabled = true;
    Profiler::setActive(profiler.get());
  }
  const double cpu_before = processCpuSeconds();
  auto session = std::make_unique<MappingSession>(opt_.params);
  session->setResetSaveRoot(out_dir_.string());
  const std::string source = fs::weakly_canonical(fs::path(opt_.rawlog), ec).string();
  if (opt_.localize_only) {
    if (!startLocalization(session.get(), loaded, &why)) return fail(kExitBadInput, why);
  } else if (!opt_.load_map.empty() || opt_.has_initial_pose) {
    if (!startSession(session.get(), loaded, source, &why)) return fail(kExitBadInput, why);
  }
  RawlogScan item;
  RawlogReader::Status status = RawlogReader::Status::kEnd;
  uint64_t skipped = 0;
  while (skipped < opt_.first_scan &&
         (status = reader.next(&item)) == RawlogReader::Status::kScan) {
    ++skipped;
  }
  summary_.first_scan = skipped;
  uint64_t given = 0;
  uint64_t rejected = 0;
  double first_stamp = 0.0, last_stamp = 0.0;
  double slam_s = 0.0;
  bool stopped_early = false;
  while (skipped == opt_.first_scan &&
         (status = reader.next(&item)) == RawlogReader::Status::kScan) {
    if (opt_.max_scans > 0 && given >= opt_.max_scans) {
      stopped_early = true;
      break;
    }
    const auto s0 = std::chrono::steady_clock::now();
    const SessionScanResult result = session->processScan(item.odometry, item.scan);
    slam_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    if (given == 0) first_stamp = item.scan.stamp;
    last_stamp = item.scan.stamp;
    ++given;
    odometry_path_.push_back({item.scan.stamp, item.odometry});
    if (!result.message.empty()) warn(result.message);
    if (result.update.processed && result.alarm.rising) {
      summary_.conflict_alarm_stamps.push_back(item.scan.stamp);
    }
    if (result.localization.processed && result.localization.alarm.rising) {
      summary_.conflict_alarm_stamps.push_back(item.scan.stamp);
    }
    if (result.localization.processed) {
      localization_rows_.push_back(
          {item.scan.stamp, session->localizer().estimate(), result.localization});
    }
    if (result.rejected()) {
      ++rejected;
      if (rejected <= kRejectionsShown) {
        char stamp[32];
        std::snprintf(stamp, sizeof(stamp), "%.6f", item.scan.stamp);
        warn("scan " + std::to_string(given) + " (t = " + stamp +
                 " s) rejected: " + result.rejectionReason(),
             false);
        if (rejected == kRejectionsShown) {
          warn("further rejected scans are only counted (summary.json: scans_rejected)", false);
        }
      }
    }
    if (progress_) progress_->update(given);
  }
  if (progress_) progress_->finish(given);
  const double slam_cpu_s = processCpuSeconds() - cpu_before;
  Profiler::setActive(nullptr);

  if (status == RawlogReader::Status::kTruncated || status == RawlogReader::Status::kError) {
    summary_.truncated = true;
    warn(reader.message());
  }
  for (const std::string& w : reader.warnings()) warn(w);
  if (given == 0) return fail(kExitBadInput, "no scan could be read from '" + opt_.rawlog + "'");

  const SlamStats stats = session->engine().stats();
  if (!opt_.localize_only) rejected = stats.scans_rejected;
  if (rejected > 0) {
    warn(std::to_string(rejected) + " of " + std::to_string(given) + " scans were rejected by " +
         (opt_.localize_only ? "the localizer" : "the SLAM core"));
  }
  if (stopped_early) {
    summary_.warnings.push_back("stopped after --max-scans " + std::to_string(opt_.max_scans));
  }
  summary_.resolution = session->parameters().slam.resolution;
  summary_.parameter_values = parameterValues(session->parameters());
  summary_.scans_total = given;
  summary_.scans_processed = stats.scans_processed;
  summary_.scans_rejected = rejected;
  summary_.scans_without_odometry = reader.counts().scans_without_odometry;
  summary_.scans_dropped = session->scansDropped();
  summary_.rays_total = stats.rays_total;
  summary_.rays_bad = stats.rays_bad;
  summary_.rays_no_return = stats.rays_no_return;
  summary_.resamplings = stats.resamplings;
  summary_.long_steps = stats.long_steps;
  summary_.group_updates = stats.group_updates;
  summary_.slam_time_s = slam_s;
  if (opt_.localize_only) {
    const Localizer& localizer = session->localizer();
    const LocalizerStats& l = localizer.stats();
    LocalizationSummary loc;
    loc.global = opt_.global_localization;
    loc.updates = l.scans_processed;
    loc.resamplings = l.resamplings;
    loc.particles_min = l.min_particles_used;
    loc.particles_max = l.max_particles_used;
    loc.particles_mean =
        l.scans_processed > 0 ? static_cast<double>(l.particle_updates) / l.scans_processed : 0.0;
    loc.cpu_time_s = slam_cpu_s;
    loc.log_duration_s = last_stamp - first_stamp;
    loc.real_time_factor = slam_s > 0.0 ? loc.log_duration_s / slam_s : 0.0;
    loc.real_time_factor_cpu = slam_cpu_s > 0.0 ? loc.log_duration_s / slam_cpu_s : 0.0;
    loc.anomaly_bits = localizer.anomaly().total();
    loc.anomaly_cells = localizer.anomaly().size();
    loc.lookup_bytes = l.lookup_bytes;
    loc.lookup_build_s = l.lookup_build_s;
    loc.recoveries = l.recoveries;
    loc.global_searches = l.global_searches;
    loc.global_search_s = l.global_search_s;
    loc.proposal_matches = l.proposal_matches;
    summary_.localization = loc;
    summary_.scans_processed = l.scans_processed;
    summary_.resamplings = l.resamplings;
    summary_.particles = static_cast<int>(l.max_particles_used);
    summary_.resolution = localizer.map().resolution();
  }
  if (stats.rays_bad > 0) {
    warn(std::to_string(stats.rays_bad) +
         " rays with NaN, infinite or negative ranges were skipped");
  }

  // The outputs need the best particle only. Its path and map (a copy sharing its tiles) are kept
  // and the filter is released before the layers' rasters are allocated, with the freed memory
  // handed back to the system, so writing them does not add to the run's peak memory.
  MapSave save = captureMapSave(*session);
  session.reset();
  releaseFreeHeapMemory();
  if (save.map.observedBox().empty()) {
    return fail(kExitBadInput, "no map: none of the " + std::to_string(given) +
                                   " scans read from '" + opt_.rawlog + "' had a usable range (" +
                                   std::to_string(rejected) + " rejected, " +
                                   std::to_string(stats.rays_bad) + " of " +
                                   std::to_string(stats.rays_total) + " rays unusable)");
  }
  save.info.metadata["source"] = source;
  save.info.metadata["first_scan"] = std::to_string(opt_.first_scan);
  save.info.metadata["next_scan"] = std::to_string(opt_.first_scan + given);
  if (!loaded.path.empty()) save.info.metadata["loaded_map"] = loaded.path;
  // A localization leaves the map as it was: its layers are the mapping run's (--all-layers
  // writes them again).
  save.anomaly_layer_only = opt_.localize_only && !opt_.all_layers;
  const std::vector<StampedPose>& best_path = save.trajectory;

  if (!truth_.empty()) {
    AteResult ate;
    if (computeAte(best_path, truth_, opt_.ate_max_dt, &ate, &why)) {
      summary_.ate = AteSummary{ate.rmse, ate.max_error, ate.matched};
      // trajectory.png draws the truth over the run's time span in the map frame: the
      // alignment's inverse applied to it.
      const Pose2 to_map = ate.alignment.inverse();
      for (const StampedPose& t : truth_) {
        if (t.stamp >= best_path.front().stamp - opt_.ate_max_dt &&
            t.stamp <= best_path.back().stamp + opt_.ate_max_dt) {
          save.reference_path.push_back(to_map.compose(t.pose));
        }
      }
      char caption[96];
      std::snprintf(caption, sizeof caption,
                    "red: path, blue: ground truth; ATE %.3f m (max %.3f m)", ate.rmse,
                    ate.max_error);
      save.trajectory_caption = caption;
    } else {
      warn("no trajectory error: " + why);
    }
    if (computeAte(odometry_path_, truth_, opt_.ate_max_dt, &ate, &why)) {
      summary_.odometry_ate = AteSummary{ate.rmse, ate.max_error, ate.matched};
    }
  }

  MapFilesReport files;
  if (!writeMapFiles(out_dir_.string(), save, opt_.params.session, &files, &why, &outputs_)) {
    return fail(kExitBadInput, why);
  }
  if (!files.layers_skipped.empty()) warn(files.layers_skipped);
  summary_.map_file = MapFileSummary{fs::path(files.map_file).lexically_relative(out_dir_).string(),
                                     files.map_file_stats.file_bytes, files.map_file_stats.tiles};
  for (const std::string& f : files.files) {
    summary_.outputs.push_back(fs::path(f).lexically_relative(out_dir_).string());
  }
  if (opt_.localize_only) {
    const std::string csv = (out_dir_ / "localization.csv").string();
    if (!writeLocalizationCsv(csv, localization_rows_, &outputs_, &why)) {
      return fail(kExitBadInput, why);
    }
    summary_.outputs.push_back("localization.csv");
  }
  summary_.external_conflict_scale = files.external_conflict_scale;
  summary_.map_width = files.map_width;
  summary_.map_height = files.map_height;
  if (files.octomap) {
    MapExportSummary octomap;
    for (const std::string& f : files.octomap->files) {
      octomap.files.push_back(fs::path(f).lexically_relative(out_dir_).string());
    }
    octomap.bytes = files.octomap->bytes;
    octomap.seconds = files.octomap->seconds;
    octomap.z_min = opt_.params.session.octomap_z_min;
    octomap.z_max = opt_.params.session.octomap_z_max;
    octomap.z_layers = files.octomap->z_layers;
    octomap.voxels = files.octomap->voxels;
    summary_.octomap = octomap;
  }

  summary_.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary_.peak_rss_mb = peakRssMb();
  if (profiler) {
    char line[160];
    std::snprintf(
        line, sizeof(line),
        "process CPU (user + system) while processing the log: %.2f s, %.2f ms per "
        "update (floor replay included)\n",
        slam_cpu_s,
        1e3 * slam_cpu_s / std::max<double>(1.0, profiler->counter(ProfileCounter::kUpdates)));
    const std::string report = profiler->report() + line;
    if (!outputs_.add((out_dir_ / "profile.txt").string(),
                      [&](std::ostream& out) { return static_cast<bool>(out << report); }, &why)) {
      return fail(kExitBadInput, why);
    }
    summary_.outputs.push_back("profile.txt");
    std::fprintf(out_, "%s", report.c_str());
  }
  const std::string summary_path = (out_dir_ / "summary.json").string();
  summary_.outputs.push_back("summary.json");
  // Every output replaces the previous run's only now, all together (atomic_files.h).
  if (!writeSummaryJson(summary_path, summary_, &why, &outputs_) || !outputs_.commit(&why)) {
    return fail(kExitBadInput, why);
  }

  std::fprintf(out_, "scans:      %llu read, %llu processed, %llu rejected%s\n",
               static_cast<unsigned long long>(given),
               static_cast<unsigned long long>(summary_.scans_processed),
               static_cast<unsigned long long>(summary_.scans_rejected),
               summary_.truncated ? " (log truncated)" : "");
  std::fprintf(out_, "time:       %.1f s (SLAM %.1f s, %.1f scans/s), peak RSS %.0f MB\n",
               summary_.wall_time_s, slam_s, slam_s > 0 ? given / slam_s : 0.0,
               summary_.peak_rss_mb);
  if (summary_.ate) {
    std::fprintf(out_, "ATE:        RMSE %.3f m, max %.3f m over %llu poses", summary_.ate->rmse_m,
                 summary_.ate->max_m, static_cast<unsigned long long>(summary_.ate->matched));
    if (summary_.odometry_ate) {
      std::fprintf(out_, " (odometry alone: RMSE %.3f m)", summary_.odometry_ate->rmse_m);
    }
    std::fprintf(out_, "\n");
  }
  std::fprintf(out_, "map file:   %s (%.2f MB, %llu tiles)\n", files.map_file.c_str(),
               static_cast<double>(files.map_file_stats.file_bytes) / 1e6,
               static_cast<unsigned long long>(files.map_file_stats.tiles));
  std::fprintf(out_, "trajectory: %s\n", (out_dir_ / "trajectory.tum").string().c_str());
  if (summary_.localization) {
    const LocalizationSummary& l = *summary_.localization;
    std::fprintf(out_,
                 "localized:  %llu updates, particles %llu-%llu (mean %.0f), %.0fx real time "
                 "(%.0fx per CPU second); %s\n",
                 static_cast<unsigned long long>(l.updates),
                 static_cast<unsigned long long>(l.particles_min),
                 static_cast<unsigned long long>(l.particles_max), l.particles_mean,
                 l.real_time_factor, l.real_time_factor_cpu,
                 (out_dir_ / "localization.csv").string().c_str());
  }
  if (summary_.map_width > 0 && files.anomaly_layer_only) {
    std::fprintf(out_, "layers:     %s/ (%dx%d cells; the anomaly layer: PNG, NPY, PGM)\n",
                 (out_dir_ / "layers").string().c_str(), summary_.map_width, summary_.map_height);
  } else if (summary_.map_width > 0) {
    std::fprintf(out_, "layers:     %s/ (%dx%d cells; PNG, NPY, PGM, map.yaml)\n",
                 (out_dir_ / "layers").string().c_str(), summary_.map_width, summary_.map_height);
  } else {
    std::fprintf(out_, "layers:     not written (max_layer_cells)\n");
  }
  if (summary_.octomap) {
    const MapExportSummary& o = *summary_.octomap;
    uint64_t bytes = 0;
    for (uint64_t b : o.bytes) bytes += b;
    std::fprintf(out_, "octomap:    %s/ (%zu files, %.1f MB, %llu voxels, export %.2f s)\n",
                 (out_dir_ / "octomap").string().c_str(), o.files.size(), bytes / 1e6,
                 static_cast<unsigned long long>(o.voxels), o.seconds);
  }
  std::fprintf(out_, "summary:    %s\n", summary_path.c_str());
  std::fflush(out_);
  return kExitOk;
}

}  // namespace

double processCpuSeconds() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double peakRssMb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

std::string presetFile(const std::string& name) {
  return (fs::path(ES_CONFIG_DIR) / (name + ".yaml")).string();
}

int runOffline(const OfflineOptions& options, std::FILE* out, std::FILE* err, bool err_is_tty) {
  // A failed run leaves no folder it made: the output directory (or its layers/ and octomap/ in
  // one that existed) is removed unless it was there before. The files are staged (AtomicFiles)
  // and dropped on failure already.
  const OutputFolders folders(options.out_dir);
  int code = kExitInternal;
  try {
    Run run(options, out, err, err_is_tty);
    code = run.execute();
  } catch (const std::bad_alloc&) {
    std::fprintf(err, "error: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(err, "error: unexpected failure: %s\n", oneLineMessage(e.what()).c_str());
  }
  if (code != kExitOk) folders.removeCreated();
  return code;
}

}  // namespace io
}  // namespace evidential_slam
