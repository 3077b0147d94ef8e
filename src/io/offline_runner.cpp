// The offline rawlog runner. See offline_runner.h.
#include "evidential_slam/io/offline_runner.h"

#include <malloc.h>
#include <sys/resource.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/metrics.h"
#include "evidential_slam/core/slam_engine.h"
#include "evidential_slam/io/command_line.h"
#include "evidential_slam/io/ground_truth.h"
#include "evidential_slam/io/layer_writer.h"
#include "evidential_slam/io/progress.h"
#include "evidential_slam/io/rawlog_reader.h"
#include "evidential_slam/io/summary.h"
#include "evidential_slam/io/trajectory_io.h"

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

class Run {
 public:
  Run(const OfflineOptions& o, std::FILE* out, std::FILE* err, bool tty,
      const MapExporter& octomap_exporter)
      : opt_(o), out_(out), err_(err), tty_(tty), octomap_exporter_(octomap_exporter) {}

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
  bool writeOutputs(const std::vector<StampedPose>& best_path, const EvidentialGridMap& best_map,
                    std::string* error);

  const OfflineOptions& opt_;
  std::FILE* out_;
  std::FILE* err_;
  bool tty_;
  const MapExporter& octomap_exporter_;
  std::unique_ptr<ProgressBar> progress_;
  RunSummary summary_;
  std::vector<StampedPose> truth_;
  std::vector<StampedPose> odometry_path_;
  // One row per processed scan: its stamp and the conflict alarm's verdict.
  struct ConflictRow {
    double stamp;
    double ec_bits;
    double mass_added;
    ConflictAlarmState alarm;
  };
  std::vector<ConflictRow> conflict_rows_;
  fs::path out_dir_;
  fs::path layers_dir_;
};

int Run::execute() {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!opt_.slam.isValid(&why)) return fail(kExitUsage, "invalid parameters: " + why);
  if (!opt_.conflict_alarm.isValid(&why)) return fail(kExitUsage, "invalid parameters: " + why);
  if (opt_.export_octomap && !octomap_exporter_) {
    return fail(kExitUsage, "--export-octomap is not available in this program");
  }

  summary_.rawlog = opt_.rawlog;
  summary_.ground_truth = opt_.ground_truth;
  summary_.preset = opt_.preset;
  summary_.parameters = opt_.parameters;
  summary_.particles = opt_.slam.particles;
  summary_.resolution = opt_.slam.resolution;
  summary_.seed = opt_.slam.seed;
  summary_.threads = opt_.slam.threads;

  if (!opt_.ground_truth.empty() && !readGroundTruth(opt_.ground_truth, &truth_, &why)) {
    return fail(kExitBadInput, why);
  }

  // Pre-pass: early, clear errors and the total for the progress line.
  RawlogReaderConfig reader_config;
  reader_config.laser_label = opt_.laser_label;
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

  out_dir_ = opt_.out_dir;
  layers_dir_ = out_dir_ / "layers";
  std::error_code ec;
  fs::create_directories(layers_dir_, ec);
  if (ec || !fs::is_directory(layers_dir_)) {
    return fail(kExitBadInput, "cannot create output directory '" + layers_dir_.string() +
                                   "': " + (ec ? ec.message() : "not a directory"));
  }

  RawlogReader reader(reader_config);
  if (!reader.open(opt_.rawlog, &why)) return fail(kExitBadInput, why);

  uint64_t total = survey.counts.scans_emitted;
  if (opt_.max_scans > 0 && opt_.max_scans < total) total = opt_.max_scans;
  if (!opt_.quiet) progress_ = std::make_unique<ProgressBar>(err_, total, tty_);

  auto engine_owner = std::make_unique<SlamEngine>(opt_.slam);
  SlamEngine& engine = *engine_owner;
  ConflictAlarm alarm(opt_.conflict_alarm);
  RawlogScan item;
  RawlogReader::Status status = RawlogReader::Status::kEnd;
  uint64_t given = 0;
  double slam_s = 0.0;
  bool stopped_early = false;
  while ((status = reader.next(&item)) == RawlogReader::Status::kScan) {
    if (opt_.max_scans > 0 && given >= opt_.max_scans) {
      stopped_early = true;
      break;
    }
    const auto s0 = std::chrono::steady_clock::now();
    const ScanUpdate update = engine.processScan(item.odometry, item.scan);
    slam_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    ++given;
    odometry_path_.push_back({item.scan.stamp, item.odometry});
    if (update.processed) {
      const ConflictAlarmState state = alarm.update(update.open_space_conflict_added);
      conflict_rows_.push_back(
          {item.scan.stamp, update.external_conflict_added, update.conflict_mass_added, state});
      if (state.rising) summary_.conflict_alarm_stamps.push_back(item.scan.stamp);
    }
    if (update.rejected) {
      const uint64_t rejected = engine.stats().scans_rejected;
      if (rejected <= kRejectionsShown) {
        char stamp[32];
        std::snprintf(stamp, sizeof(stamp), "%.6f", item.scan.stamp);
        warn("scan " + std::to_string(given) + " (t = " + stamp + " s) rejected: " + update.why,
             false);
        if (rejected == kRejectionsShown) {
          warn("further rejected scans are only counted (summary.json: scans_rejected)", false);
        }
      }
    }
    if (progress_) progress_->update(given);
  }
  if (progress_) progress_->finish(given);

  if (status == RawlogReader::Status::kTruncated || status == RawlogReader::Status::kError) {
    summary_.truncated = true;
    warn(reader.message());
  }
  for (const std::string& w : reader.warnings()) warn(w);
  if (given == 0) return fail(kExitBadInput, "no scan could be read from '" + opt_.rawlog + "'");

  const SlamStats stats = engine.stats();
  if (stats.scans_rejected > 0) {
    warn(std::to_string(stats.scans_rejected) + " of " + std::to_string(given) +
         " scans were rejected by the SLAM core");
  }
  if (stopped_early) {
    summary_.warnings.push_back("stopped after --max-scans " + std::to_string(opt_.max_scans));
  }
  summary_.scans_total = given;
  summary_.scans_processed = stats.scans_processed;
  summary_.scans_rejected = stats.scans_rejected;
  summary_.scans_without_odometry = reader.counts().scans_without_odometry;
  summary_.rays_total = stats.rays_total;
  summary_.rays_bad = stats.rays_bad;
  summary_.rays_no_return = stats.rays_no_return;
  summary_.resamplings = stats.resamplings;
  summary_.long_steps = stats.long_steps;
  summary_.slam_time_s = slam_s;
  if (stats.rays_bad > 0) {
    warn(std::to_string(stats.rays_bad) +
         " rays with NaN, infinite or negative ranges were skipped");
  }

  // The outputs need the best particle only. Its path and map (a copy sharing its tiles) are kept
  // and the filter is released before the layers' rasters are allocated, with the freed memory
  // handed back to the system, so writing them does not add to the run's peak memory.
  const std::vector<StampedPose> best_path = engine.bestTrajectory();
  const EvidentialGridMap best_map = engine.bestMap();
  engine_owner.reset();
  releaseFreeHeapMemory();

  if (!truth_.empty()) {
    AteResult ate;
    if (computeAte(best_path, truth_, opt_.ate_max_dt, &ate, &why)) {
      summary_.ate = AteSummary{ate.rmse, ate.max_error, ate.matched};
    } else {
      warn("no trajectory error: " + why);
    }
    if (computeAte(odometry_path_, truth_, opt_.ate_max_dt, &ate, &why)) {
      summary_.odometry_ate = AteSummary{ate.rmse, ate.max_error, ate.matched};
    }
  }

  if (!writeOutputs(best_path, best_map, &why)) return fail(kExitBadInput, why);

  summary_.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary_.peak_rss_mb = peakRssMb();
  const std::string summary_path = (out_dir_ / "summary.json").string();
  summary_.outputs.push_back("summary.json");
  if (!writeSummaryJson(summary_path, summary_, &why)) return fail(kExitBadInput, why);

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
  std::fprintf(out_, "trajectory: %s\n", (out_dir_ / "trajectory.tum").string().c_str());
  std::fprintf(out_, "layers:     %s/ (%dx%d cells; PNG, NPY, map.yaml)\n",
               layers_dir_.string().c_str(), summary_.map_width, summary_.map_height);
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

bool Run::writeOutputs(const std::vector<StampedPose>& best_path, const EvidentialGridMap& best_map,
                       std::string* error) {
  const std::string tum = (out_dir_ / "trajectory.tum").string();
  if (!writeTumTrajectory(tum, best_path, error)) return false;
  summary_.outputs.push_back("trajectory.tum");

  const std::string csv = (out_dir_ / "conflict.csv").string();
  {
    std::ofstream f(csv);
    f << "# per processed scan: stamp (s), the external conflict (bits) and the conflict mass m(0) "
         "(summed over cells) it added to the best map, the part of that mass added in the map's "
         "open space (the alarm's input), the alarm's running baseline of it, their ratio, alarm "
         "(1 = above threshold)\n"
      << "stamp,ec_added_bits,conflict_mass_added,open_space_conflict_added,baseline,ratio,alarm\n";
    char line[200];
    for (const ConflictRow& r : conflict_rows_) {
      std::snprintf(line, sizeof(line), "%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n", r.stamp, r.ec_bits,
                    r.mass_added, r.alarm.added, r.alarm.baseline, r.alarm.ratio,
                    r.alarm.alarm ? 1 : 0);
      f << line;
    }
    f.close();
    if (!f) {
      if (error) *error = "cannot write '" + csv + "'";
      return false;
    }
  }
  summary_.outputs.push_back("conflict.csv");

  const LayerRaster raster = extractLayers(best_map);
  LayerWriteResult written;
  if (!writeLayers(raster, layers_dir_.string(), LayerWriterConfig(), &written, error)) {
    return false;
  }
  for (const std::string& f : written.files) {
    summary_.outputs.push_back(fs::path(f).lexically_relative(out_dir_).string());
  }
  summary_.external_conflict_scale = written.external_conflict_scale;
  summary_.map_width = raster.width;
  summary_.map_height = raster.height;

  if (opt_.export_octomap) {
    MapExportReport report;
    if (!octomap_exporter_(best_map, opt_, &report, error)) return false;
    MapExportSummary octomap;
    for (const std::string& f : report.files) {
      const std::string rel = fs::path(f).lexically_relative(out_dir_).string();
      octomap.files.push_back(rel);
      summary_.outputs.push_back(rel);
    }
    octomap.bytes = report.bytes;
    octomap.seconds = report.seconds;
    octomap.z_min = opt_.octomap_z_min;
    octomap.z_max = opt_.octomap_z_max;
    octomap.z_layers = report.z_layers;
    octomap.voxels = report.voxels;
    summary_.octomap = octomap;
  }
  return true;
}

}  // namespace

double peakRssMb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

namespace {

// "a, b, c" wrapped to the usage text's indentation.
std::string paramNameList() {
  std::string text, line;
  for (const std::string& name : slamParameterNames()) {
    const std::string item = (text.empty() && line.empty() ? "" : ", ") + name;
    if (line.size() + item.size() > 62) {
      text += line + ",\n                        ";
      line = name;
    } else {
      line += item;
    }
  }
  return text + line;
}

}  // namespace

std::string offlineUsage(const std::string& program) {
  return "usage: " + program +
         " --rawlog FILE --out DIR [--ground-truth GT.txt] [--preset sim|real] [--particles K]\n"
         "       [--seed N] [--resolution M] [--threads N] [--max-scans N] [--laser-label L]\n"
         "       [--param NAME=VALUE]... [--quiet]\n"
         "       [--export-octomap [--octomap-z-min Z] [--octomap-z-max Z]]\n"
         "\n"
         "Evidential FastSLAM on an MRPT rawlog (Actions/SensoryFrame or observation-only).\n"
         "Writes DIR/trajectory.tum, DIR/layers/{<layer>.png,<layer>.npy,composite.png,\n"
         "observed.npy,map.yaml} and DIR/summary.json.\n"
         "\n"
         "  --rawlog FILE         input rawlog (.rawlog, gzip or plain)\n"
         "  --out DIR             output directory (created)\n"
         "  --ground-truth FILE   `t x y phi` per line; adds the ATE to summary.json\n"
         "  --preset P            sim: defaults sized on simulated odometry (default); real:\n"
         "                        for real wheel odometry (each hypothesis matched over +-20 deg\n"
         "                        of heading and with the translation missed or reversed)\n"
         "  --particles K         number of particles (default 100)\n"
         "  --seed N              random seed (default 1)\n"
         "  --resolution M        map cell size in metres (default 0.05)\n"
         "  --threads N           worker threads, 0 = all cores (default 0)\n"
         "  --max-scans N         stop after N scans\n"
         "  --laser-label L       use only scans with this sensor label\n"
         "  --param NAME=VALUE    set a SLAM parameter by its ROS name (README, Parameters),\n"
         "                        over the preset; repeatable. Names:\n"
         "                        " +
         paramNameList() +
         "\n"
         "  --quiet               no progress line and no warnings on stderr\n"
         "  --export-octomap      also write DIR/octomap/map.evidential.ot (all masses),\n"
         "                        map.bt (OcTree of BetP) and map.color.ot (RGB = masses)\n"
         "  --octomap-z-min Z     the voxel slab spans the layers from the one containing Z ...\n"
         "  --octomap-z-max Z     ... to the one containing Z, metres (both default 0: one layer)\n"
         "\n"
         "Exit codes: 0 success (also a truncated log), 1 bad usage, 2 unusable input or\n"
         "unwritable output, 3 internal error.\n";
}

bool parseOfflineArgs(const std::vector<std::string>& args, OfflineOptions* o, bool* help,
                      std::string* error) {
  *help = false;
  bool z_given = false;
  auto bad = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  for (size_t i = 0; i < args.size(); ++i) {
    const CommandLineArg arg = splitArg(args[i]);
    const std::string& flag = arg.flag;
    std::string value = arg.value;
    const bool has_inline = arg.has_value;
    if (flag == "-h" || flag == "--help") {
      *help = true;
      return true;
    }
    if (flag == "--quiet" || flag == "-q") {
      if (has_inline) return bad("--quiet takes no value");
      o->quiet = true;
      continue;
    }
    if (flag == "--export-octomap") {
      if (has_inline) return bad("--export-octomap takes no value");
      o->export_octomap = true;
      continue;
    }
    static const char* kValued[] = {
        "--rawlog",        "--out",           "--ground-truth", "--preset",    "--particles",
        "--seed",          "--resolution",    "--threads",      "--max-scans", "--laser-label",
        "--octomap-z-min", "--octomap-z-max", "--param"};
    bool known = false;
    for (const char* k : kValued) known = known || flag == k;
    if (!known) return bad("unknown option '" + args[i] + "'");
    if (!has_inline) {
      if (i + 1 >= args.size()) return bad(flag + " needs a value");
      value = args[++i];
    }
    if (flag == "--rawlog") {
      o->rawlog = value;
    } else if (flag == "--out") {
      o->out_dir = value;
    } else if (flag == "--ground-truth") {
      o->ground_truth = value;
    } else if (flag == "--laser-label") {
      o->laser_label = value;
    } else if (flag == "--preset") {
      if (value != "sim" && value != "real") return bad("--preset wants 'sim' or 'real'");
      o->preset = value;
    } else if (flag == "--particles") {
      int k = 0;
      if (!parseNumber(value, &k) || k < 1) return bad("--particles wants an integer >= 1");
      o->slam.particles = k;
    } else if (flag == "--seed") {
      uint64_t s = 0;
      if (!parseNumber(value, &s)) return bad("--seed wants a non-negative integer");
      o->slam.seed = s;
    } else if (flag == "--resolution") {
      double r = 0;
      if (!parseNumber(value, &r) || !(r > 0.0) || r > 10.0) {
        return bad("--resolution wants metres per cell in (0, 10]");
      }
      o->slam.resolution = r;
    } else if (flag == "--threads") {
      int t = 0;
      if (!parseNumber(value, &t) || t < 0) return bad("--threads wants an integer >= 0");
      o->slam.threads = t;
    } else if (flag == "--max-scans") {
      uint64_t n = 0;
      if (!parseNumber(value, &n) || n == 0) return bad("--max-scans wants an integer >= 1");
      o->max_scans = n;
    } else if (flag == "--param") {
      const size_t eq = value.find('=');
      if (eq == std::string::npos || eq == 0) return bad("--param wants NAME=VALUE");
      o->parameters.emplace_back(value.substr(0, eq), value.substr(eq + 1));
    } else if (flag == "--octomap-z-min" || flag == "--octomap-z-max") {
      double z = 0;
      if (!parseNumber(value, &z) || !std::isfinite(z) || std::abs(z) > 1000.0) {
        return bad(flag + " wants a height in metres within +-1000");
      }
      (flag == "--octomap-z-min" ? o->octomap_z_min : o->octomap_z_max) = z;
      z_given = true;
    }
  }
  if (o->preset == "real") applyRealRobotPreset(&o->slam);
  for (const auto& [name, text] : o->parameters) {
    std::string why;
    if (!setSlamParameter(name, text, &o->slam, &why)) return bad("--param " + why);
  }
  if (o->rawlog.empty()) return bad("--rawlog is required");
  if (o->out_dir.empty()) return bad("--out is required");
  if (z_given && !o->export_octomap) {
    return bad("--octomap-z-min/--octomap-z-max need --export-octomap");
  }
  if (o->octomap_z_min > o->octomap_z_max) {
    return bad("--octomap-z-min must not be above --octomap-z-max");
  }
  return true;
}

namespace {

// First meaningful line of an exception text (MRPT's carry a banner and a call stack).
std::string oneLine(const std::string& what) {
  std::string text = what;
  const size_t msg = text.find("Message:");
  if (msg != std::string::npos) text = text.substr(msg + 8);
  const size_t start = text.find_first_not_of(" \t\n");
  if (start == std::string::npos) return "(no message)";
  text = text.substr(start);
  const size_t eol = text.find('\n');
  return eol == std::string::npos ? text : text.substr(0, eol);
}

}  // namespace

int runOffline(const OfflineOptions& options, std::FILE* out, std::FILE* err, bool err_is_tty,
               const MapExporter& octomap_exporter) {
  try {
    Run run(options, out, err, err_is_tty, octomap_exporter);
    return run.execute();
  } catch (const std::bad_alloc&) {
    std::fprintf(err, "error: out of memory\n");
    return kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(err, "error: unexpected failure: %s\n", oneLine(e.what()).c_str());
    return kExitInternal;
  }
}

}  // namespace io
}  // namespace evidential_slam
