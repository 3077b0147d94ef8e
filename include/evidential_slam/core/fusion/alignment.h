// Estimates the pose of one evidential map in another's frame: an exhaustive search over yaw and
// translation on pooled grids, refined coarse to fine and then by the project's scan matcher (ICP
// on the moving map's occupied cells), every candidate scored by the conflict fusing the maps
// there would create, the last few verified by the conflict beyond registration error
// (alignment_check.h). Refuses when no pose explains the overlap or the evidence cannot tell.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace fusion {

// A pose is judged by its structure conflict: over the cells both maps observed there (the
// overlap), Σ K / Σ (m̃(o) of either map), K = m̃_A(o) m̃_B(e) + m̃_A(e) m̃_B(o) being the conflict the
// fusion creates in a cell: the share of the occupied evidence in the overlap that the other map
// contradicts. A cell's m̃(e) counts here only as far as its 3 x 3 neighbours are free too (the
// smallest of their m̃(e)): maps are judged up to a cell of misregistration (each map's own
// distortion, nearest-neighbour resampling), not by the edges of their walls. Poses are ranked by
// their score, (Σ K + S₀/2) / (Σ m̃(o) + S₀), S₀ the occupied evidence the overlap must hold
// (min_overlap): an overlap that barely meets the requirement cannot win on a few cells that happen
// not to conflict. The search runs on pooled grids (alignment.cpp).
struct AlignmentConfig {
  // m: the exhaustive search's pooled cell (the map's cell times the smallest power of two that
  // reaches it; coarser when a grid would exceed max_search_cells). A corridor keeps free cells
  // after the 3 x 3 erosion only if it is about four of them wide: 0.4 m serves 1.6 m corridors.
  double search_resolution = 0.4;
  int max_search_cells = 640;  // FFT grid cells per axis at most (the two maps' extents together)
  // rad between searched yaws; 0: the arc of two pooled cells at the moving map's farthest observed
  // cell from its origin.
  double yaw_step = 0.0;
  // Best distinct poses of the search that are refined. Symmetric and periodic floors have many
  // near-equal minima (a half turn, shifts by a room) that crowd the true pose out: with 8, 6 of
  // 60 generated pairs were aligned wrongly, with 24, 1 (docs/fusion.md §9).
  int candidates = 24;
  // m: the coarse-to-fine refinement's finest pooled cell, before ICP (about the matcher's reach).
  double refine_resolution = 0.2;
  // The overlap must hold at least this share of the smaller map's observed cells and of its
  // occupied evidence (Σ m̃(o)).
  double min_overlap = 0.2;
  double max_conflict = 0.3;  // structure conflict above which no pose explains the overlap
  // The best pose's score must be at most this times that of the best pose that is distinct from
  // it (farther than distinct_distance or turned more than distinct_angle).
  double ambiguity_ratio = 0.7;
  double distinct_distance = 1.0;        // m
  double distinct_angle = 0.1745329252;  // rad (10°)
  bool icp = true;                       // refine with the scan matcher (ScanMatcher::refine)
  ScanMatcherConfig matcher;             // that refinement's settings
  // Refine the accepted pose below the cell: least conflict per occupied evidence on the maps' own
  // cells, without the score's tolerance (alignment.cpp, refineSubCell).
  bool subcell = true;
  // Conflict as the verifier (alignment_check.h). The score is ambiguous when distinct
  // candidates score within 1 / ambiguity_ratio of the best (the band); among those, the one
  // whose disagreement share is lowest is taken when it is at most verify_ratio times every other
  // one's and every other one contradicts at least verify_min_length m of confident wall more;
  // otherwise the alignment is refused. The tolerance is the registration error two maps of one
  // building may have locally.
  double verify_tolerance = 0.3;  // m
  double verify_ratio = 0.5;
  double verify_min_length = 1.0;  // m
  // A candidate other than the best-scored can be chosen only if it scores within this share of
  // the best (a near tie of the score).
  double verify_score_margin = 0.1;
  // A prior on the moving map's pose in the reference frame (--initial-guess, map_merge's
  // init_pose_*): candidates farther than 3 prior_sigma or turned more than 3 prior_sigma_yaw
  // from it are not considered.
  bool has_prior = false;
  Pose2 prior;
  double prior_sigma = 1.0;        // m
  double prior_sigma_yaw = 0.175;  // rad (10°)

  bool isValid(std::string* why) const;
};

struct AlignmentResult {
  Pose2 pose;                       // the moving map's pose in the reference map's frame
  double conflict = 0.0;            // structure conflict there, on the maps' own cells
  double score = 0.0;               // its score (ranks the poses)
  double mean_conflict = 0.0;       // mean K over the overlap there, without the tolerance
  size_t overlap_cells = 0;         // cells of the moving map that land on observed reference cells
  double alternative_score = -1.0;  // score of the best distinct pose (-1: none)
  Pose2 alternative_pose;           // and where it is
  size_t yaws_searched = 0;         // yaws of the exhaustive search
  double search_resolution = 0;     // m, its pooled cell
  // The final distinct candidates, best score first, with their verification.
  struct Candidate {
    Pose2 pose;
    double score = 0.0;
    double conflict = 0.0;        // structure conflict
    double disagreement = 0.0;    // Disagreement::share
    double contradicted_m = 0.0;  // Disagreement::contradicted in m of confident wall
    double matched_m = 0.0;       // Disagreement::matched in m of confident wall
    size_t overlap = 0;           // cells of the moving map on observed reference cells
  };
  std::vector<Candidate> candidates;
  bool decided_by_verifier = false;  // the score was ambiguous; the verifier chose `pose`
};

// The pose of `moving` in `reference`'s frame. False (and a one-line `why` with the numbers) when
// the maps' resolutions differ, a map has no observed cell, no pose overlaps them enough, or the
// best pose's conflict is above max_conflict or not clearly below the best distinct alternative's;
// `result` then holds what was found.
bool alignMaps(const EvidentialGridMap& reference, const EvidentialGridMap& moving,
               const AlignmentConfig& config, AlignmentResult* result, std::string* why);

}  // namespace fusion
}  // namespace evidential_slam
