// The command line of evidential_slam_fuse, declared on io::CommandLine. See fuse_command.h.
#include <memory>

#include "evidential_slam/core/parameter_rows.h"
#include "evidential_slam/io/command_line.h"
#include "evidential_slam/session/fuse_command.h"

namespace evidential_slam {
namespace io {
namespace {

// "x,y,yaw" (m, m, rad).
bool parsePose(const std::string& text, Pose2* pose) {
  std::vector<double> v;
  if (!parseNumberList(text, 3, 3, &v)) return false;
  *pose = Pose2(v[0], v[1], v[2]);
  return true;
}

// The rows of the map files' settings (SessionConfig) with their defaults: what --param takes.
struct SessionRows {
  std::vector<ParameterSpec> specs;
  std::vector<std::pair<std::string, std::string>> defaults;
  SessionRows() {
    SessionConfig s;
    auto visit = [&](const ParameterSpec& spec, const auto& field) {
      specs.push_back(spec);
      defaults.emplace_back(spec.name, valueText(field));
    };
    ES_SESSION_PARAMETERS(ES_VISIT_PARAMETER, s)
  }
  bool has(const std::string& name) const {
    for (const ParameterSpec& spec : specs) {
      if (name == spec.name) return true;
    }
    return false;
  }
};

// What parseFuseArgs checks after the options are read.
struct FuseExtras {
  ParameterAssignments parameters;
  bool ground_truth_pose_given = false;
  bool ground_truth_resolution_given = false;
};

std::unique_ptr<CommandLine> fuseCommandLine(const std::string& program, FuseOptions* o,
                                             FuseExtras* x) {
  auto cl = std::make_unique<CommandLine>(
      "usage: " + program +
          " --map A --map B [--map C ...] [--pose x,y,yaw ... | --estimate\n"
          "       | --initial-guess x,y,yaw[,sigma] ...]\n"
          "       --rule cautious|dempster|conjunctive|yager|disjunctive [--discount a ...]\n"
          "       --out DIR [options]\n"
          "Fuses evidential maps cell by cell and writes the fused map's files into DIR, as a "
          "SLAM\n"
          "run does (layers/, map.evmap, octomap/ with --export-octomap), plus fusion.json.",
      "Exit codes: 0 success, 1 bad usage, 2 unusable input (a map that cannot be read,\n"
      "resolutions that differ, an alignment refused) or unwritable output, 3 internal error.");
  auto pose = [](const char* option, Pose2* to, std::function<void()> then) {
    return [option, to, then](const std::string& v) {
      if (!parsePose(v, to)) {
        throw UsageError(std::string(option) + " wants x,y,yaw (m, m, rad), not '" + v + "'");
      }
      then();
    };
  };
  cl->option("--map", "PATH",
             "a map file (map.evmap) or a SLAM run's output directory; the\n"
             "first map's frame is the fused map's",
             [o](const std::string& v) {
               if (v.empty()) throw UsageError("--map wants a path");
               o->maps.push_back(v);
             });
  auto next_pose = std::make_shared<Pose2>();
  cl->option("--pose", "x,y,yaw",
             "pose (m, m, rad) of the next map after the first in the first\n"
             "map's frame: one per map after the first",
             pose("--pose", next_pose.get(), [o, next_pose] { o->poses.push_back(*next_pose); }));
  cl->flag("--estimate",
           "estimate those poses instead: each map aligned on the first\n"
           "(refused when no pose explains the overlap, or when neither\n"
           "the score nor the conflict tells the candidates apart)",
           [o] { o->estimate = true; });
  cl->option("--initial-guess", "x,y,yaw[,sigma]",
             "a guess of the next map's pose (as --pose; sigma m,\n"
             "default 1): the estimate lies within 3 sigma and 30 degrees of\n"
             "it; one per map after the first; implies --estimate\n"
             "(neither: the maps share a frame)",
             [o](const std::string& value) {
               std::vector<double> v;
               if (!parseNumberList(value, 3, 4, &v) || (v.size() == 4 && !(v[3] > 0.0))) {
                 throw UsageError(
                     "--initial-guess wants x,y,yaw or x,y,yaw,sigma (m, m, rad, m > 0), not '" +
                     value + "'");
               }
               o->guesses.push_back({Pose2(v[0], v[1], v[2]), v.size() == 4 ? v[3] : 1.0});
               o->estimate = true;
             });
  cl->option("--rule", "NAME",
             "combination rule: cautious (maps that may share evidence),\n"
             "conjunctive, dempster, yager (independent maps), disjunctive",
             [o](const std::string& v) {
               if (!fusion::parseRule(v, &o->rule)) {
                 throw UsageError(
                     "--rule wants cautious, dempster, conjunctive, yager or disjunctive, not '" +
                     v + "'");
               }
               o->rule_given = true;
             });
  cl->option("--discount", "a",
             "Shafer discount rate in [0, 1] (0: fully reliable): once for\n"
             "every map, or once per map in --map order",
             [o](const std::string& v) {
               double a = 0.0;
               if (!parseNumber(v, &a) || !(a >= 0.0 && a <= 1.0)) {
                 throw UsageError("--discount wants a number in [0, 1], not '" + v + "'");
               }
               o->discounts.push_back(a);
             });
  cl->option("--out", "DIR", "output directory (created)",
             [o](const std::string& v) { o->out_dir = v; });
  cl->flag("--export-octomap", "also write DIR/octomap/ (as --param export_octomap=true)",
           [x] { x->parameters.emplace_back("export_octomap", "true"); });
  cl->param(&x->parameters, "a parameter of the map files (below)");
  cl->option("--ground-truth", "PATH",
             "score every map and the fused one against an occupancy image\n"
             "(black occupied, white free, centred on the origin) or a map",
             [o](const std::string& v) { o->ground_truth = v; });
  cl->option(
      "--ground-truth-resolution", "M", "the image's metres per pixel (default 0.05)",
      [o, x](const std::string& v) {
        if (!parseNumber(v, &o->ground_truth_resolution) ||
            !(o->ground_truth_resolution > 0.0 && std::isfinite(o->ground_truth_resolution))) {
          throw UsageError("--ground-truth-resolution wants a number > 0 (m per pixel)");
        }
        x->ground_truth_resolution_given = true;
      });
  cl->option("--ground-truth-pose", "x,y,yaw", "the fused map's frame in the truth's frame",
             pose("--ground-truth-pose", &o->ground_truth_pose,
                  [x] { x->ground_truth_pose_given = true; }));
  cl->flag("-q,--quiet", "no summary on stdout", [o] { o->quiet = true; });
  const SessionRows rows;
  cl->appendHelp(parameterHelp(
      "Parameters of the map files (--param NAME=VALUE; the default and unit, the type and "
      "range):",
      rows.specs, rows.defaults));
  return cl;
}

}  // namespace

std::string fuseUsage(const std::string& program) {
  FuseOptions o;
  FuseExtras x;
  return fuseCommandLine(program, &o, &x)->help();
}

bool parseFuseArgs(const std::vector<std::string>& args, FuseOptions* o, bool* help,
                   std::string* error) {
  auto bad = [&](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  FuseExtras x;
  if (!fuseCommandLine("evidential_slam_fuse", o, &x)->parse(args, help, error)) return false;
  if (*help) return true;
  const SessionRows rows;
  Parameters params;
  for (const auto& [name, text] : x.parameters) {
    if (!rows.has(name)) {
      return bad("--param " + name +
                 ": not a parameter of a map's files (occupied_thresh, "
                 "free_thresh, export_octomap, octomap_z_min, octomap_z_max)");
    }
    std::string why;
    if (!setParameter(name, text, &params, &why)) return bad(why);
  }
  o->session = params.session;
  if (o->maps.size() < 2) return bad("at least two --map are required");
  if (!o->rule_given) return bad("--rule is required");
  if (o->out_dir.empty()) return bad("--out is required");
  if (o->estimate && !o->poses.empty()) {
    return bad(o->guesses.empty() ? "--pose and --estimate exclude each other"
                                  : "--pose and --initial-guess exclude each other");
  }
  if (!o->guesses.empty() && o->guesses.size() != o->maps.size() - 1) {
    return bad("--initial-guess: " + std::to_string(o->guesses.size()) + " given for " +
               std::to_string(o->maps.size()) + " maps; one per map after the first");
  }
  if (!o->poses.empty() && o->poses.size() != o->maps.size() - 1) {
    return bad("--pose: " + std::to_string(o->poses.size()) + " given for " +
               std::to_string(o->maps.size()) + " maps; one per map after the first");
  }
  if (o->discounts.size() > 1 && o->discounts.size() != o->maps.size()) {
    return bad("--discount: " + std::to_string(o->discounts.size()) + " given for " +
               std::to_string(o->maps.size()) + " maps; one for all or one per map");
  }
  if (o->ground_truth.empty() && (x.ground_truth_pose_given || x.ground_truth_resolution_given)) {
    return bad("--ground-truth-pose and --ground-truth-resolution need --ground-truth");
  }
  std::string why;
  if (!o->session.isValid(&why)) return bad("invalid parameters: " + why);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
