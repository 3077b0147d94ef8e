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
#include "evidential_slam/io/build_info.h"
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
