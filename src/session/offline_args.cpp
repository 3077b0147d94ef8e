// The command line of evidential_slam_offline, declared on io::CommandLine. See offline_runner.h.
#include <memory>

#include "evidential_slam/io/command_line.h"
#include "evidential_slam/session/offline_runner.h"

namespace evidential_slam {
namespace io {
namespace {

// "a,b,c": three finite numbers.
bool parseTriple(const std::string& text, double v[3]) {
  std::vector<double> values;
  if (!parseNumberList(text, 3, 3, &values)) return false;
  std::copy(values.begin(), values.end(), v);
  return true;
}

// Declares every option of the offline runner on a CommandLine writing into `o`.
std::unique_ptr<CommandLine> offlineCommandLine(const std::string& program, OfflineOptions* o) {
  auto cl = std::make_unique<CommandLine>(
      "usage: " + program +
          " --rawlog FILE --out DIR [--ground-truth GT.txt] [--config FILE]...\n"
          "       [--preset NAME] [--param NAME=VALUE]... [--particles K] [--seed N]\n"
          "       [--resolution M] [--threads N] [--first-scan N] [--max-scans N]\n"
          "       [--load-map DIR|FILE] [--initial-pose X,Y,YAW] [--laser-label L] [--quiet]\n"
          "       [--localize-only [--initial-cov XX,YY,AA | --global] [--all-layers]]\n"
          "       [--profile] [--export-octomap [--octomap-z-min Z] [--octomap-z-max Z]]\n"
          "\n"
          "Evidential FastSLAM on an MRPT rawlog (Actions/SensoryFrame or observation-only).\n"
          "Writes DIR/map.evmap (the lossless map, for --load-map), DIR/trajectory.tum,\n"
          "DIR/conflict.csv, DIR/layers/ (every layer as PNG, NPY and map_server PGM + YAML)\n"
          "and DIR/summary.json.",
      "Exit codes: 0 success (also a truncated log), 1 bad usage, parameters or parameter\n"
      "files, 2 unusable input or unwritable output, 3 internal error.");
  auto text = [](std::string* field) { return [field](const std::string& v) { *field = v; }; };
  // Options that stand for one parameter join --param's list where they stand.
  auto shorthand = [o](const char* name) {
    return [o, name](const std::string& v) { o->parameters.emplace_back(name, v); };
  };
  cl->option("--rawlog", "FILE", "input rawlog (.rawlog, gzip or plain)", text(&o->rawlog))
      ->required();
  cl->option("--out", "DIR", "output directory (created)", text(&o->out_dir))->required();
  cl->option("--ground-truth", "FILE", "`t x y phi` per line; adds the ATE to summary.json",
             text(&o->ground_truth));
  cl->option("--config", "FILE",
             "parameter file (YAML `name: value`, as config/*.yaml and\n"
             "rosparam); repeatable, later files win",
             [o](const std::string& v) { o->config_files.push_back(v); });
  cl->option("--preset", "NAME", "the package's config/NAME.yaml, as --config",
             [o](const std::string& v) {
               if (v.empty() || v.find('/') != std::string::npos) {
                 throw UsageError("--preset wants the name of a file in config/ (e.g. sim)");
               }
               o->config_files.push_back(presetFile(v));
             });
  cl->param(&o->parameters,
            "set a parameter by its name (below) after the\nconfig files; repeatable");
  cl->option("--particles", "K", "= --param particles=K (default 100)", shorthand("particles"));
  cl->option("--seed", "N", "= --param seed=N (default 1)", shorthand("seed"));
  cl->option("--resolution", "M", "= --param resolution=M, metres per cell (default 0.05)",
             shorthand("resolution"));
  cl->option("--threads", "N", "= --param threads=N, 0 = all cores (default 0)",
             shorthand("threads"));
  cl->option("--first-scan", "N", "pass over the log's first N scans (0 = start at the first)",
             [o](const std::string& v) {
               if (!parseNumber(v, &o->first_scan)) {
                 throw UsageError("--first-scan wants an integer >= 0");
               }
             });
  cl->option("--max-scans", "N", "stop after N scans (counted from --first-scan)",
             [o](const std::string& v) {
               if (!parseNumber(v, &o->max_scans) || o->max_scans == 0) {
                 throw UsageError("--max-scans wants an integer >= 1");
               }
             });
  cl->option("--load-map", "PATH",
             "continue mapping on a saved map: a map.evmap file or the\n"
             "directory holding it (another run's --out, a node's save_map)",
             [o](const std::string& v) {
               if (v.empty()) throw UsageError("--load-map wants a map file or a directory");
               o->load_map = v;
             });
  cl->option("--initial-pose", "X,Y,YAW",
             "the first scan's pose in the map frame (m, m, rad); default\n"
             "with --load-map: the pose saved in the map file",
             [o](const std::string& v) {
               double p[3];
               if (!parseTriple(v, p)) {
                 throw UsageError("--initial-pose wants X,Y,YAW (three finite numbers: m, m, rad)");
               }
               o->initial_pose = Pose2(p[0], p[1], p[2]);
               o->has_initial_pose = true;
             });
  cl->flag("--localize-only",
           "localize on the --load-map map instead of mapping: the map\n"
           "is not changed; writes DIR/localization.csv (the estimate\n"
           "and its covariance per update) and layers/anomaly.* (what\n"
           "contradicts the map); --initial-pose defaults to 0,0,0",
           [o] { o->localize_only = true; });
  cl->flag("--all-layers",
           "with --localize-only: also write the stored map's layers\n"
           "into DIR/layers/ (unchanged: by default only the anomaly\n"
           "layer, the one the run makes, is written)",
           [o] { o->all_layers = true; });
  cl->option(
      "--initial-cov", "XX,YY,AA",
      "with --localize-only: the variances (m^2, m^2, rad^2) of\n"
      "the particles drawn around --initial-pose (default: the\n"
      "initial_cov_* parameters)",
      [o](const std::string& v) {
        double* c = o->initial_covariance;
        if (!parseTriple(v, c) || c[0] < 0.0 || c[1] < 0.0 || c[2] < 0.0) {
          throw UsageError("--initial-cov wants XX,YY,AA (three variances >= 0: m^2, m^2, rad^2)");
        }
        o->has_initial_covariance = true;
      });
  cl->flag("--global",
           "with --localize-only: spread the particles over the map's\n"
           "free space instead (global localization)",
           [o] { o->global_localization = true; });
  cl->option("--laser-label", "L", "use only scans with this sensor label", text(&o->laser_label));
  cl->flag("-q,--quiet", "no progress line and no warnings on stderr", [o] { o->quiet = true; });
  cl->flag("--profile",
           "time the filter's update by section and measure its compute\n"
           "floor (slower, more memory); report in DIR/profile.txt",
           [o] { o->profile = true; });
  cl->flag("--export-octomap",
           "= --param export_octomap=true: also write\n"
           "DIR/octomap/map.{evidential.ot,bt,color.ot}",
           [o] { o->parameters.emplace_back("export_octomap", "true"); });
  cl->option("--octomap-z-min", "Z", "= --param octomap_z_min=Z (the voxel slab's lowest height)",
             shorthand("octomap_z_min"));
  cl->option("--octomap-z-max", "Z", "= --param octomap_z_max=Z (its highest)",
             shorthand("octomap_z_max"));
  cl->appendHelp(
      sharedParameterHelp("Parameters (--param NAME=VALUE, --config files; the default and unit, "
                          "the type and range):"));
  return cl;
}

}  // namespace

std::string offlineUsage(const std::string& program) {
  OfflineOptions scratch;
  return offlineCommandLine(program, &scratch)->help();
}

bool parseOfflineArgs(const std::vector<std::string>& args, OfflineOptions* o, bool* help,
                      std::string* error) {
  auto bad = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!offlineCommandLine("evidential_slam_offline", o)->parse(args, help, error)) return false;
  if (*help) return true;
  std::string why;
  if (!applyParameters(o->config_files, o->parameters, &o->params, &o->ignored, &why)) {
    return bad(why);
  }
  if (o->localize_only && o->load_map.empty()) {
    return bad("--localize-only needs --load-map (the map to localize on)");
  }
  if (!o->localize_only && (o->global_localization || o->has_initial_covariance || o->all_layers)) {
    return bad(std::string(o->global_localization      ? "--global"
                           : o->has_initial_covariance ? "--initial-cov"
                                                       : "--all-layers") +
               " needs --localize-only");
  }
  if (o->global_localization && (o->has_initial_pose || o->has_initial_covariance)) {
    return bad(
        "--global spreads the particles over the map: not with --initial-pose or "
        "--initial-cov");
  }
  if (!o->params.isValid(&why)) return bad("invalid parameters: " + why);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
