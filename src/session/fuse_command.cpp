#include "evidential_slam/session/fuse_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>

#include <nlohmann/json.hpp>

#include "evidential_slam/core/fusion/alignment.h"
#include "evidential_slam/core/fusion/map_fusion.h"
#include "evidential_slam/core/fusion/map_score.h"
#include "evidential_slam/core/parameter_rows.h"
#include "evidential_slam/io/build_info.h"
#include "evidential_slam/io/command_line.h"
#include "evidential_slam/io/error_text.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/io/map_input.h"
#include "evidential_slam/io/occupancy_image.h"
#include "evidential_slam/session/map_files.h"
#include "evidential_slam/session/offline_runner.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// "x,y,yaw" (m, m, rad).
bool parsePose(const std::string& text, Pose2* pose) {
  double v[3];
  size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    const size_t comma = text.find(',', start);
    if ((i < 2) != (comma != std::string::npos)) return false;
    const std::string part = text.substr(start, i < 2 ? comma - start : std::string::npos);
    if (!parseNumber(part, &v[i]) || !std::isfinite(v[i])) return false;
    start = comma + 1;
  }
  *pose = Pose2(v[0], v[1], v[2]);
  return true;
}

bool isSessionParameter(const std::string& name) {
  bool found = false;
  SessionConfig s;
  auto visit = [&](const ParameterSpec& spec, auto&) { found = found || name == spec.name; };
  ES_SESSION_PARAMETERS(ES_VISIT_PARAMETER, s)
  return found;
}

Json poseJson(const Pose2& p) { return Json{{"x", p.x}, {"y", p.y}, {"yaw", p.theta}}; }

// What a map holds, for fusion.json: how much it observed and how certain it is.
struct MapStats {
  size_t observed = 0;
  size_t occupied = 0;  // classified occupied / free (map_score.h's classes)
  size_t free = 0;
  double mean_nonspecificity = 0.0;  // m(Θ) over the observed cells
  double mean_conflict = 0.0;        // m(∅) over the observed cells
};

MapStats mapStats(const EvidentialGridMap& map, const fusion::ClassifyConfig& classify) {
  MapStats s;
  double ns = 0.0, conflict = 0.0;
  const CellBox box = map.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& c = map.cell(x, y);
      if (!c.observed()) continue;
      ++s.observed;
      const double keep = std::exp(-static_cast<double>(c.lambda()));
      ns += keep * c.unknown();
      conflict += 1.0 - keep;
      const fusion::CellClass k = fusion::classify(c, classify);
      s.occupied += k == fusion::CellClass::kOccupied ? 1 : 0;
      s.free += k == fusion::CellClass::kFree ? 1 : 0;
    }
  }
  if (s.observed > 0) {
    s.mean_nonspecificity = ns / static_cast<double>(s.observed);
    s.mean_conflict = conflict / static_cast<double>(s.observed);
  }
  return s;
}

Json statsJson(const MapStats& s) {
  return Json{{"observed_cells", s.observed},
              {"occupied_cells", s.occupied},
              {"free_cells", s.free},
              {"mean_nonspecificity", s.mean_nonspecificity},
              {"mean_conflict", s.mean_conflict}};
}

Json scoreJson(const fusion::MapScore& s) {
  return Json{{"accuracy", s.accuracy()},
              {"coverage", s.coverage()},
              {"known", s.known},
              {"classified", s.classified},
              {"correct", s.correct}};
}

// A map as ground truth: its observed box, each cell in its class.
fusion::OccupancyRaster rasterOfMap(const EvidentialGridMap& map, const Pose2& offset,
                                    const fusion::ClassifyConfig& classify) {
  const CellBox box = map.observedBox();
  fusion::OccupancyRaster r;
  r.resolution = map.resolution();
  r.origin_x = box.min_x * map.resolution() + offset.x;
  r.origin_y = box.min_y * map.resolution() + offset.y;
  r.width = box.width();
  r.height = box.height();
  r.cells.reserve(static_cast<size_t>(r.width) * static_cast<size_t>(r.height));
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      r.cells.push_back(fusion::classify(map.cell(x, y), classify));
    }
  }
  return r;
}

bool looksLikeImage(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".pgm" || ext == ".bmp" || ext == ".jpg" || ext == ".jpeg";
}

}  // namespace

std::string fuseUsage(const std::string& program) {
  std::ostringstream u;
  u << "usage: " << program
    << " --map A --map B [--map C ...] [--pose x,y,yaw ... | --estimate\n"
       "       | --initial-guess x,y,yaw[,sigma] ...]\n"
       "       --rule cautious|dempster|conjunctive|yager|disjunctive [--discount a ...]\n"
       "       --out DIR [options]\n"
       "Fuses evidential maps cell by cell and writes the fused map's files into DIR, as a SLAM\n"
       "run does (layers/, map.evmap, octomap/ with --export-octomap), plus fusion.json.\n"
       "  --map PATH            a map file (map.evmap) or a SLAM run's output directory; the\n"
       "                        first map's frame is the fused map's\n"
       "  --pose x,y,yaw        pose (m, m, rad) of the next map after the first in the first\n"
       "                        map's frame: one per map after the first\n"
       "  --estimate            estimate those poses instead: each map aligned on the first\n"
       "                        (refused when no pose explains the overlap, or when neither\n"
       "                        the score nor the conflict tells the candidates apart)\n"
       "  --initial-guess x,y,yaw[,sigma]  a guess of the next map's pose (as --pose; sigma m,\n"
       "                        default 1): the estimate lies within 3 sigma and 30 degrees of\n"
       "                        it; one per map after the first; implies --estimate\n"
       "                        (neither: the maps share a frame)\n"
       "  --rule NAME           combination rule: cautious (maps that may share evidence),\n"
       "                        conjunctive, dempster, yager (independent maps), disjunctive\n"
       "  --discount a          Shafer discount rate in [0, 1] (0: fully reliable): once for\n"
       "                        every map, or once per map in --map order\n"
       "  --out DIR             output directory (created)\n"
       "  --export-octomap      also write DIR/octomap/ (as --param export_octomap=true)\n"
       "  --param NAME=VALUE    a parameter of the map files (occupied_thresh, free_thresh,\n"
       "                        export_octomap, octomap_z_min, octomap_z_max)\n"
       "  --ground-truth PATH   score every map and the fused one against an occupancy image\n"
       "                        (black occupied, white free, centred on the origin) or a map\n"
       "  --ground-truth-resolution M   the image's metres per pixel (default 0.05)\n"
       "  --ground-truth-pose x,y,yaw   the fused map's frame in the truth's frame\n"
       "  --quiet               no summary on stdout\n"
       "Exit codes: 0 success, 1 bad usage, 2 unusable input (a map that cannot be read,\n"
       "resolutions that differ, an alignment refused) or unwritable output, 3 internal error.\n";
  return u.str();
}

bool parseFuseArgs(const std::vector<std::string>& args, FuseOptions* o, bool* help,
                   std::string* error) {
  *help = false;
  auto bad = [&](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  static const char* const kValued[] = {"--map",
                                        "--pose",
                                        "--initial-guess",
                                        "--rule",
                                        "--discount",
                                        "--out",
                                        "--param",
                                        "--ground-truth",
                                        "--ground-truth-resolution",
                                        "--ground-truth-pose"};
  Parameters params;
  std::vector<std::pair<std::string, std::string>> parameters;
  bool ground_truth_pose_given = false, ground_truth_resolution_given = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const CommandLineArg arg = splitArg(args[i]);
    const std::string& flag = arg.flag;
    std::string value = arg.value;
    if (flag == "-h" || flag == "--help") {
      *help = true;
      return true;
    }
    if (flag == "--estimate" || flag == "--quiet" || flag == "-q" || flag == "--export-octomap") {
      if (arg.has_value) return bad(flag + " takes no value");
      if (flag == "--estimate") {
        o->estimate = true;
      } else if (flag == "--export-octomap") {
        parameters.emplace_back("export_octomap", "true");
      } else {
        o->quiet = true;
      }
      continue;
    }
    bool known = false;
    for (const char* k : kValued) known = known || flag == k;
    if (!known) return bad("unknown option '" + args[i] + "'");
    if (!arg.has_value) {
      if (i + 1 >= args.size()) return bad(flag + " needs a value");
      value = args[++i];
    }
    if (flag == "--map") {
      if (value.empty()) return bad("--map wants a path");
      o->maps.push_back(value);
    } else if (flag == "--pose") {
      Pose2 pose;
      if (!parsePose(value, &pose)) {
        return bad("--pose wants x,y,yaw (m, m, rad), not '" + value + "'");
      }
      o->poses.push_back(pose);
    } else if (flag == "--initial-guess") {
      std::vector<double> v;
      if (!io::parseNumberList(value, 3, 4, &v) || (v.size() == 4 && !(v[3] > 0.0))) {
        return bad("--initial-guess wants x,y,yaw or x,y,yaw,sigma (m, m, rad, m > 0), not '" +
                   value + "'");
      }
      o->guesses.push_back({Pose2(v[0], v[1], v[2]), v.size() == 4 ? v[3] : 1.0});
      o->estimate = true;
    } else if (flag == "--rule") {
      if (!fusion::parseRule(value, &o->rule)) {
        return bad("--rule wants cautious, dempster, conjunctive, yager or disjunctive, not '" +
                   value + "'");
      }
      o->rule_given = true;
    } else if (flag == "--discount") {
      double a = 0.0;
      if (!parseNumber(value, &a) || !(a >= 0.0 && a <= 1.0)) {
        return bad("--discount wants a number in [0, 1], not '" + value + "'");
      }
      o->discounts.push_back(a);
    } else if (flag == "--out") {
      o->out_dir = value;
    } else if (flag == "--param") {
      const size_t eq = value.find('=');
      if (eq == std::string::npos || eq == 0) return bad("--param wants NAME=VALUE");
      parameters.emplace_back(value.substr(0, eq), value.substr(eq + 1));
    } else if (flag == "--ground-truth") {
      o->ground_truth = value;
    } else if (flag == "--ground-truth-resolution") {
      if (!parseNumber(value, &o->ground_truth_resolution) ||
          !(o->ground_truth_resolution > 0.0 && std::isfinite(o->ground_truth_resolution))) {
        return bad("--ground-truth-resolution wants a number > 0 (m per pixel)");
      }
      ground_truth_resolution_given = true;
    } else if (flag == "--ground-truth-pose") {
      if (!parsePose(value, &o->ground_truth_pose)) {
        return bad("--ground-truth-pose wants x,y,yaw (m, m, rad), not '" + value + "'");
      }
      ground_truth_pose_given = true;
    }
  }
  for (const auto& [name, text] : parameters) {
    if (!isSessionParameter(name)) {
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
  if (o->ground_truth.empty() && (ground_truth_pose_given || ground_truth_resolution_given)) {
    return bad("--ground-truth-pose and --ground-truth-resolution need --ground-truth");
  }
  std::string why;
  if (!o->session.isValid(&why)) return bad("invalid parameters: " + why);
  return true;
}

int runFuse(const FuseOptions& options, std::FILE* out, std::FILE* err) {
  // A failed fusion leaves no folder it made (the files are staged, the folders are not).
  const OutputFolders folders(options.out_dir);
  auto failWith = [&](int code, const std::string& message) {
    folders.removeCreated();
    std::fprintf(err, "error: %s\n", message.c_str());
    return code;
  };
  try {
    const auto start = std::chrono::steady_clock::now();
    const size_t n = options.maps.size();
    std::vector<EvidentialGridMap> maps(n);
    std::vector<MapInput> inputs(n);
    for (size_t i = 0; i < n; ++i) {
      std::string error;
      if (!readMapInput(options.maps[i], &maps[i], &inputs[i], &error)) {
        return failWith(kExitBadInput, error);
      }
      if (maps[i].observedBox().empty()) {
        return failWith(kExitBadInput, "map '" + options.maps[i] + "' has no observed cell");
      }
    }
    for (size_t i = 1; i < n; ++i) {
      const double r0 = maps[0].resolution(), r = maps[i].resolution();
      if (std::abs(r - r0) > 1e-9 * r0) {
        std::ostringstream msg;
        msg << "map '" << options.maps[i] << "' has " << r << " m cells and '" << options.maps[0]
            << "' " << r0 << " m: fusion needs one resolution";
        return failWith(kExitBadInput, msg.str());
      }
    }
    // Fusion works over the maps' observed boxes: bounded up front (max_layer_cells), with the
    // size it would need, as the saved layers are.
    CellBox all;
    for (size_t i = 0; i < n; ++i) {
      std::string why;
      if (!denseLayersFit(maps[i], options.session, &why)) {
        return failWith(kExitBadInput, "map " + quotedPath(options.maps[i]) + ": " + why);
      }
      all.extend(maps[i].observedBox());
    }
    {
      std::string why;
      if (!denseLayersFit(all, maps[0].resolution(), options.session, &why)) {
        return failWith(kExitBadInput, "the maps together: " + why);
      }
    }
    const double read_s = secondsSince(start);

    // Poses of the grids in the fused frame (map 1's run frame): given, estimated or shared.
    // pose_of_run[i] is map i's run frame in map 1's; the grid adds its layer offset.
    std::vector<Pose2> pose_of_run(n);
    std::vector<std::string> pose_source(n, "reference");
    std::vector<Json> alignments(n);
    const auto align_start = std::chrono::steady_clock::now();
    for (size_t i = 1; i < n; ++i) {
      if (options.estimate) {
        fusion::AlignmentResult result;
        fusion::AlignmentConfig align;
        if (!options.guesses.empty()) {
          // Run frames -> grid poses, as below the other way round.
          const FuseOptions::Guess& guess = options.guesses[i - 1];
          align.has_prior = true;
          align.prior = inputs[0].offset.inverse().compose(guess.pose).compose(inputs[i].offset);
          align.prior_sigma = guess.sigma;
          align.prior_sigma_yaw = 10.0 * 3.14159265358979323846 / 180.0;
        }
        std::string why;
        if (!fusion::alignMaps(maps[0], maps[i], align, &result, &why)) {
          return failWith(kExitBadInput, "cannot align map '" + options.maps[i] + "' on '" +
                                             options.maps[0] + "': " + why);
        }
        // Grid poses -> run frames: offset_1 ∘ aligned ∘ offset_i⁻¹.
        pose_of_run[i] = inputs[0].offset.compose(result.pose).compose(inputs[i].offset.inverse());
        pose_source[i] = "estimated";
        alignments[i] = Json{{"structure_conflict", result.conflict},
                             {"score", result.score},
                             {"mean_conflict", result.mean_conflict},
                             {"overlap_cells", result.overlap_cells},
                             {"alternative_score", result.alternative_score},
                             {"alternative_pose", poseJson(result.alternative_pose)},
                             {"decided_by_verifier", result.decided_by_verifier},
                             {"initial_guess", !options.guesses.empty()},
                             {"yaws_searched", result.yaws_searched},
                             {"search_resolution", result.search_resolution}};
      } else if (!options.poses.empty()) {
        pose_of_run[i] = options.poses[i - 1];
        pose_source[i] = "given";
      } else {
        pose_source[i] = "shared frame";
      }
    }
    const double align_s = secondsSince(align_start);

    std::vector<fusion::FusionSource> sources(n);
    for (size_t i = 0; i < n; ++i) {
      sources[i].map = &maps[i];
      sources[i].pose = pose_of_run[i].compose(inputs[i].offset);
      sources[i].discount = options.discounts.empty()       ? 0.0
                            : options.discounts.size() == 1 ? options.discounts[0]
                                                            : options.discounts[i];
    }
    fusion::FusionConfig config;
    config.rule = options.rule;
    EvidentialGridMap fused;
    fusion::FusionReport report;
    std::string why;
    const auto fuse_start = std::chrono::steady_clock::now();
    if (!fusion::fuseMaps(sources, config, &fused, &report, &why)) {
      return failWith(kExitBadInput, why);
    }
    const double fuse_s = secondsSince(fuse_start);

    // The map's files, as a SLAM run writes them, the map file among them (no path, no conflict
    // record: those files are empty).
    const auto write_start = std::chrono::steady_clock::now();
    MapSave save;
    save.map = std::move(fused);
    save.info.metadata["source"] = "evidential_slam_fuse";
    save.info.metadata["fusion_rule"] = fusion::ruleName(options.rule);
    for (size_t i = 0; i < n; ++i) {
      save.info.metadata["fusion_map_" + std::to_string(i + 1)] = inputs[i].path;
    }
    MapFilesReport files;
    std::string error;
    if (!writeMapFiles(options.out_dir, save, options.session, &files, &error)) {
      return failWith(kExitBadInput, error);
    }
    const EvidentialGridMap& fused_map = save.map;
    const double write_s = secondsSince(write_start);

    // Scores against the ground truth.
    const fusion::ClassifyConfig classify;
    Json scores;
    if (!options.ground_truth.empty()) {
      fusion::OccupancyRaster truth;
      if (looksLikeImage(options.ground_truth)) {
        OccupancyImageConfig image;
        image.resolution = options.ground_truth_resolution;
        if (!readOccupancyImage(options.ground_truth, image, &truth, &error)) {
          return failWith(kExitBadInput, error);
        }
      } else {
        EvidentialGridMap truth_map;
        MapInput truth_input;
        if (!readMapInput(options.ground_truth, &truth_map, &truth_input, &error)) {
          return failWith(kExitBadInput, "ground truth: " + error);
        }
        if (truth_map.observedBox().empty()) {
          return failWith(kExitBadInput,
                          "ground truth '" + options.ground_truth + "' has no observed cell");
        }
        truth = rasterOfMap(truth_map, truth_input.offset, classify);
      }
      auto score = [&](const EvidentialGridMap& map, const Pose2& in_fused,
                       const std::string& name) {
        fusion::MapScore s;
        std::string reason;
        if (!fusion::scoreMap(map, options.ground_truth_pose.compose(in_fused), truth, classify, &s,
                              &reason)) {
          throw std::runtime_error("scoring " + name + ": " + reason);
        }
        return s;
      };
      Json per_map = Json::array();
      for (size_t i = 0; i < n; ++i) {
        per_map.push_back(scoreJson(score(maps[i], sources[i].pose, options.maps[i])));
      }
      scores = Json{{"ground_truth", options.ground_truth},
                    {"ground_truth_pose", poseJson(options.ground_truth_pose)},
                    {"maps", per_map},
                    {"fused", scoreJson(score(fused_map, Pose2(), "the fused map"))}};
    }

    Json j;
    j["build"] = buildVersion();
    j["rule"] = fusion::ruleName(options.rule);
    Json map_list = Json::array();
    for (size_t i = 0; i < n; ++i) {
      Json m{{"path", options.maps[i]},
             {"read_from", inputs[i].path},
             {"kind", mapInputKindName(inputs[i].kind)},
             {"pose", poseJson(pose_of_run[i])},
             {"pose_source", pose_source[i]},
             {"discount", sources[i].discount},
             {"observed_cells_in_fusion", report.observed_cells[i]},
             {"stats", statsJson(mapStats(maps[i], classify))}};
      if (!alignments[i].is_null()) m["alignment"] = alignments[i];
      map_list.push_back(m);
    }
    j["maps"] = map_list;
    j["fused_cells"] = report.fused_cells;
    j["overlap_cells"] = report.overlap_cells;
    j["mean_conflict"] = report.mean_conflict;
    j["mean_conflict_added"] = report.mean_conflict_added;
    j["fused"] = statsJson(mapStats(fused_map, classify));
    if (!scores.is_null()) j["scores"] = scores;
    j["seconds"] = Json{{"read", read_s},
                        {"align", align_s},
                        {"fuse", fuse_s},
                        {"write", write_s},
                        {"total", secondsSince(start)}};
    Json written = Json::array();
    for (const std::string& f : files.files) {
      written.push_back(fs::relative(f, options.out_dir).generic_string());
    }
    j["outputs"] = written;
    const std::string json_path = (fs::path(options.out_dir) / "fusion.json").string();
    std::ofstream json(json_path);
    json << j.dump(2, ' ', false, Json::error_handler_t::replace) << "\n";
    json.close();
    if (!json) return failWith(kExitBadInput, "cannot write '" + json_path + "'");

    if (!options.quiet) {
      std::fprintf(out,
                   "fused %zu maps by the %s rule: %zu cells, %zu in the overlap, "
                   "mean conflict %.4f\n",
                   n, fusion::ruleName(options.rule).c_str(), report.fused_cells,
                   report.overlap_cells, report.mean_conflict);
      for (size_t i = 1; i < n; ++i) {
        std::fprintf(out, "  map %zu at (%.3f m, %.3f m, %.4f rad), %s\n", i + 1, pose_of_run[i].x,
                     pose_of_run[i].y, pose_of_run[i].theta, pose_source[i].c_str());
      }
      if (!scores.is_null()) {
        const Json& f = scores["fused"];
        std::fprintf(out, "  fused map: accuracy %.4f, coverage %.4f against %s\n",
                     f["accuracy"].get<double>(), f["coverage"].get<double>(),
                     options.ground_truth.c_str());
      }
      std::fprintf(out, "  written to %s (fusion.json)\n", options.out_dir.c_str());
    }
    return kExitOk;
  } catch (const std::bad_alloc&) {
    return failWith(kExitInternal, "internal error: out of memory");
  } catch (const std::exception& e) {
    return failWith(kExitInternal, "internal error: " + oneLineMessage(e.what()));
  }
}

}  // namespace io
}  // namespace evidential_slam
