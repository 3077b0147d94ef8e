// Hand-made layer rasters for the exploration tests, drawn as text: one string per row, the
// first string the top row (highest y). '.' free (BetP 0.1, NS 0.2: one free pass), '#'
// occupied (BetP 0.9, NS 0.1), '?' never observed (BetP 0.5, NS 1), '~' uncertain (BetP 0.45,
// NS 0.6), 'x' free but in conflict (as '.', EC 2 bits), 'b' balanced evidence (BetP 0.5, NS 0.1:
// measured often, as often occupied as free). The entropy layer is H(BetP) in bits.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "evidential_slam/core/layers.h"
#include "evidential_slam/core/measures.h"

namespace evidential_slam {
namespace testing_exploration {

inline void setCell(LayerRaster* r, int col, int row, char c) {
  const size_t i = static_cast<size_t>(row) * r->width + col;
  float betp = 0.5f, ns = 1.0f, ec = 0.0f;
  switch (c) {
    case '.':
      betp = 0.1f, ns = 0.2f;
      break;
    case '#':
      betp = 0.9f, ns = 0.1f;
      break;
    case '~':
      betp = 0.45f, ns = 0.6f;
      break;
    case 'x':
      betp = 0.1f, ns = 0.2f, ec = 2.0f;
      break;
    case 'b':
      betp = 0.5f, ns = 0.1f;
      break;
    default:
      break;
  }
  r->values[static_cast<int>(Layer::kPignistic)][i] = betp;
  r->values[static_cast<int>(Layer::kNonspecificity)][i] = ns;
  r->values[static_cast<int>(Layer::kUnknown)][i] = ns;
  r->values[static_cast<int>(Layer::kExternalConflict)][i] = ec;
  r->values[static_cast<int>(Layer::kEntropy)][i] =
      static_cast<float>(-(betp * std::log2(betp) + (1.0f - betp) * std::log2(1.0f - betp)));
  r->observed[i] = c == '?' ? 0 : 1;
}

// A raster of `width` x `height` cells, all never observed.
inline LayerRaster blankRaster(int width, int height, double resolution, double origin_x = 0.0,
                               double origin_y = 0.0) {
  LayerRaster r;
  r.resolution = resolution;
  r.origin_x = origin_x;
  r.origin_y = origin_y;
  r.width = width;
  r.height = height;
  const size_t n = static_cast<size_t>(width) * height;
  for (auto& v : r.values) v.assign(n, 0.0f);
  r.observed.assign(n, 0);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) setCell(&r, col, row, '?');
  }
  return r;
}

inline LayerRaster drawRaster(const std::vector<std::string>& rows, double resolution,
                              double origin_x = 0.0, double origin_y = 0.0) {
  const int height = static_cast<int>(rows.size());
  const int width = static_cast<int>(rows.front().size());
  LayerRaster r = blankRaster(width, height, resolution, origin_x, origin_y);
  for (int k = 0; k < height; ++k) {
    const int row = height - 1 - k;
    for (int col = 0; col < width; ++col) setCell(&r, col, row, rows[k].at(col));
  }
  return r;
}

// Fills the box of cells [col0, col1] x [row0, row1] with `c`.
inline void fillBox(LayerRaster* r, int col0, int row0, int col1, int row1, char c) {
  for (int row = row0; row <= row1; ++row) {
    for (int col = col0; col <= col1; ++col) setCell(r, col, row, c);
  }
}

// A 3 m x 4 m hall (cells 1..29 x 1..38 at 0.1 m) with
// - its right wall open over 3.1 m (rows 5..35) onto a closed pocket 0.4 m deep: a long
//   frontier with little behind it;
// - a 1.1 m door (cols 10..20) in its top wall onto an unknown room and beyond: a short
//   frontier with a lot behind it.
// The robot stands in the hall at (1.55, 2.05), cell (15, 20).
inline LayerRaster hallWithPocketAndDoor() {
  LayerRaster r = blankRaster(60, 80, 0.1);
  fillBox(&r, 0, 0, 59, 39, '#');
  fillBox(&r, 1, 1, 29, 38, '.');
  fillBox(&r, 30, 5, 33, 35, '?');   // the pocket, walls around it
  fillBox(&r, 10, 39, 20, 39, '.');  // the door
  return r;
}

}  // namespace testing_exploration
}  // namespace evidential_slam
