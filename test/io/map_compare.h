// Comparing two evidential maps cell by cell (the map continuation tests): the share of the cells
// observed in either map whose BetP class agrees, with map_server's thresholds (occupied
// BetP > 0.65, free < 0.196, else unknown: LayerWriterConfig's defaults).
#pragma once

#include <cstddef>

#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/io/layer_writer.h"

namespace evidential_slam {
namespace test {

// 0 free, 1 unknown, 2 occupied.
inline int betpClass(const Cell& c, const io::LayerWriterConfig& t) {
  const double p = pignistic(c);
  return p > t.occupied_thresh ? 2 : p < t.free_thresh ? 0 : 1;
}

// Fraction of the cells observed in either map whose class agrees; `compared` gets their count.
inline double classAgreement(const EvidentialGridMap& a, const EvidentialGridMap& b,
                             size_t* compared) {
  const io::LayerWriterConfig thresholds;
  CellBox box = a.observedBox();
  box.extend(b.observedBox());
  size_t same = 0, n = 0;
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      const Cell& ca = a.cell(x, y);
      const Cell& cb = b.cell(x, y);
      if (!ca.observed() && !cb.observed()) continue;
      ++n;
      if (betpClass(ca, thresholds) == betpClass(cb, thresholds)) ++same;
    }
  }
  *compared = n;
  return n == 0 ? 0.0 : static_cast<double>(same) / static_cast<double>(n);
}

}  // namespace test
}  // namespace evidential_slam
