// The map fusion command behind `evidential_slam_fuse`: reads N maps (map files or SLAM runs'
// output directories), places them in the first map's frame by given poses, by estimated ones
// (fusion::alignMaps) or as they are, fuses them by one combination rule (fusion::fuseMaps) and
// writes the fused map's files as a SLAM run does (writeMapFiles, the lossless map file among
// them), plus fusion.json. Kept out of main() so the command line and the run are tested without
// a process.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "evidential_slam/core/fusion/combination.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace io {

struct FuseOptions {
  std::vector<std::string> maps;  // --map, in order; the first one's frame is the fused frame
  std::vector<Pose2> poses;       // --pose: none, or one per map after the first
  bool estimate = false;          // --estimate: poses of maps 2..N found by alignment on map 1
  // --initial-guess x,y,yaw[,sigma]: none, or one per map after the first (as --pose; sigma in m,
  // default 1): the estimate is searched within 3 sigma and 30° of it. Implies --estimate.
  struct Guess {
    Pose2 pose;
    double sigma = 1.0;
  };
  std::vector<Guess> guesses;
  fusion::Rule rule = fusion::Rule::kCautious;
  bool rule_given = false;
  std::vector<double> discounts;  // --discount: none (0), one for every map, or one per map
  std::string out_dir;
  SessionConfig session;  // the map files' settings (--param, --export-octomap)
  // --ground-truth: an occupancy image (black occupied, white free; --ground-truth-resolution m
  // per pixel, centred on the origin) or a map (anything --map takes; its cells classified as in
  // scoring); every map and the fused one are scored against it.
  std::string ground_truth;
  double ground_truth_resolution = 0.05;
  Pose2 ground_truth_pose;  // --ground-truth-pose: the fused frame in the truth's frame
  bool quiet = false;
};

// Usage text for --help and usage errors.
std::string fuseUsage(const std::string& program);

// Parses the arguments after the program name. False with a one-line `error` on bad usage;
// `help` is set (and true returned) for -h/--help.
bool parseFuseArgs(const std::vector<std::string>& args, FuseOptions* options, bool* help,
                   std::string* error);

// Runs everything; returns the exit code of session/offline_runner.h (0 ok, 2 unusable input:
// a map that cannot be read, maps of different resolutions, an alignment refused, an output that
// cannot be written; 3 internal). The short summary goes to `out`, `error: ...` lines to `err`.
int runFuse(const FuseOptions& options, std::FILE* out, std::FILE* err);

}  // namespace io
}  // namespace evidential_slam
