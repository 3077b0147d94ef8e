// Conflict as the verifier of an alignment. At a wrong pose of two maps of a nearly symmetric
// building most walls still land on walls; what gives the pose away is structure of one map on
// open space the other has seen free: the conjunctive combination turns it into m(∅) in the middle
// of a room, where no registration error explains it. At the right pose the two maps contradict
// each other only near walls (each map's own distortion) and where the world changed.
#pragma once

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/pose2.h"

namespace evidential_slam {
namespace fusion {

// Occupied evidence counts here as structure: a cell's m̃(o) times the occupied evidence of its
// 8 neighbours (at most 1), so that a wall counts and a lone hit (noise, a passer-by) does not.
struct Disagreement {
  // Σ over the overlap of the conflict õ · ẽ_R fusing the maps creates where one map holds
  // structure õ and the other free evidence with no wall within the tolerance R (ẽ_R: the
  // smallest m̃(e)(1 - m̃(o)) over the observed cells within R). In cells of a fully confident
  // wall: 20 is a metre of wall at 0.05 m cells.
  double contradicted = 0.0;
  double occupied = 0.0;  // Σ õ of both maps over the overlap
  // Σ over the overlap of õ times the other map's largest õ within R: structure that meets
  // structure, what supports the pose (same units as `contradicted`).
  double matched = 0.0;
  size_t overlap = 0;  // moving cells on observed reference cells

  // The share of the overlap's occupied evidence the other map contradicts beyond R.
  double share() const { return occupied > 0.0 ? contradicted / occupied : 0.0; }
};

// The disagreement of `moving` placed at `pose` in `reference`'s frame (one resolution), with a
// registration tolerance of `tolerance` m (rounded up to whole cells).
Disagreement disagreement(const EvidentialGridMap& reference, const EvidentialGridMap& moving,
                          const Pose2& pose, double tolerance);

}  // namespace fusion
}  // namespace evidential_slam
