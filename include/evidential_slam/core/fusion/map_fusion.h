// Whole-map fusion: N evidential grids, each placed by a rigid pose in the fused map's frame,
// combined cell by cell with one rule (combination.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/fusion/combination.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace fusion {

// One map to fuse: its pose in the fused map's frame (the first map's frame: the first source's
// pose is then the identity) and its discount rate (Shafer discounting, combination.h).
struct FusionSource {
  const EvidentialGridMap* map = nullptr;
  Pose2 pose;
  double discount = 0.0;  // [0, 1]: 0 = fully reliable, 1 = ignored
};

struct FusionConfig {
  Rule rule = Rule::kCautious;
  bool isValid(std::string* why) const;
};

struct FusionReport {
  size_t fused_cells = 0;    // cells of the fused map observed by at least one source
  size_t overlap_cells = 0;  // cells observed by at least two sources
  // Mean over the overlap of the conflict the fusion creates (conflictBetween of the discounted
  // sources: how much they contradict each other, whatever the rule then does with it); 0 without
  // overlap.
  double mean_conflict = 0.0;
  // Mean over the overlap of what the rule added to m(∅): the fused cell's m(∅) minus the largest
  // m(∅) of its (discounted) sources. Negative where the rule removes conflict (Dempster, Yager).
  double mean_conflict_added = 0.0;
  std::vector<size_t> observed_cells;  // per source, its observed cells in the fused map
};

// Fuses the sources into `fused` (replaced; the first source's resolution). Each fused cell takes
// from every source the cell under its centre (nearest neighbour, see map_fusion.cpp); a source
// that never observed that cell is no source for it, so a cell only one map observed keeps that
// map's belief (discounted, and for Dempster's and Yager's rules with its conflict handled by the
// rule); a source with discount 1 is no source anywhere. False (and a one-line `why`) for no
// sources, a missing map, resolutions that differ, a discount outside [0, 1], a non-finite pose or
// an invalid config.
bool fuseMaps(const std::vector<FusionSource>& sources, const FusionConfig& config,
              EvidentialGridMap* fused, FusionReport* report, std::string* why);

}  // namespace fusion
}  // namespace evidential_slam
