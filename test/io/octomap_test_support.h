// Shared bits of the OctoMap tests: a grid with every kind of cell (runProgram is in test_util.h).
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "evidential_slam/core/anomaly.h"
#include "evidential_slam/core/evidential_grid.h"
#include "evidential_slam/core/mass.h"
#include "test_util.h"

namespace evidential_slam {
namespace test {

// A 0.05 m grid with free cells, walls, balanced and heavily conflicted cells, cells on both sides
// of the origin and across tile borders, and unobserved holes. Deterministic.
inline EvidentialGridMap makeTestGrid(double resolution = 0.05) {
  EvidentialGridMap grid(resolution);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int y = -23; y < 19; ++y) {
    for (int x = -37; x < 41; ++x) {
      if ((x * 7 + y * 3) % 11 == 0) continue;  // unobserved holes
      Cell& c = grid.mutableCell(x, y);
      const int updates = 1 + static_cast<int>(u(rng) * 6);
      for (int k = 0; k < updates; ++k) {
        ScanMass s;
        if (x == 30 || y == -20) {  // walls
          s.occupied = 0.63f;
        } else if (u(rng) < 0.15f) {  // noise
          s.occupied = 0.5f * u(rng);
          s.free = 0.4f * u(rng);
        } else {
          s.free = 0.8f;
        }
        updateCell(c, s);
      }
    }
  }
  // 2x2 blocks of identical free cells (prunable in a two-layer slab).
  for (int y = 0; y < 4; ++y) {
    for (int x = 50; x < 54; ++x) updateCell(grid.mutableCell(x, y), ScanMass{0.0f, 0.8f});
  }
  // Contradicted many times: a large lambda.
  Cell& conflicted = grid.mutableCell(-40, 25);
  for (int k = 0; k < 2000; ++k)
    updateCell(conflicted, ScanMass{k % 2 ? 0.63f : 0.0f, k % 2 ? 0.0f : 0.8f});
  // Balanced evidence: BetP exactly 0.5.
  grid.mutableCell(45, -10) = Cell::fromStored(0.25f, 0.25f, 0.0f);
  return grid;
}

// An anomaly layer for makeTestGrid(): hand values on four observed cells (a wall, a free cell,
// the heavily conflicted one, the balanced one) and on one unobserved hole, which no voxel holds.
constexpr int kTestAnomalyObservedCells = 4;
inline AnomalyGrid makeTestAnomaly() {
  AnomalyGrid anomaly;
  anomaly.add(30, 5, 2.5f);
  anomaly.add(10, 10, 0.125f);
  anomaly.add(-40, 25, 17.75f);
  anomaly.add(45, -10, 1.0f);
  anomaly.add(0, 0, 9.0f);  // unobserved
  return anomaly;
}

struct Observed {
  CellIndex index;
  Cell cell;
};

inline std::vector<Observed> observedCells(const EvidentialGridMap& grid) {
  std::vector<Observed> out;
  const CellBox box = grid.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      if (grid.cell(x, y).observed()) out.push_back({{x, y}, grid.cell(x, y)});
    }
  }
  return out;
}

}  // namespace test
}  // namespace evidential_slam
