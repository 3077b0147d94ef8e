#include "evidential_slam/core/fusion/map_score.h"

#include <cmath>

#include "evidential_slam/core/measures.h"

namespace evidential_slam {
namespace fusion {
namespace {

bool fail(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

// Per truth cell: which classes its map cells said, and whether any map cell centre fell in it.
constexpr uint8_t kSawFree = 1, kSawOccupied = 2, kHasCentre = 4;

}  // namespace

bool OccupancyRaster::isValid(std::string* why) const {
  if (!(resolution > 0.0)) return fail(why, "ground truth: resolution must be > 0");
  if (width <= 0 || height <= 0) return fail(why, "ground truth: no cells");
  if (cells.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    return fail(why, "ground truth: " + std::to_string(cells.size()) + " cells for " +
                         std::to_string(width) + " x " + std::to_string(height));
  }
  if (!std::isfinite(origin_x) || !std::isfinite(origin_y)) {
    return fail(why, "ground truth: origin is not finite");
  }
  return true;
}

bool ClassifyConfig::isValid(std::string* why) const {
  if (!(occupied_betp > 0.5 && occupied_betp <= 1.0)) {
    return fail(why, "occupied_betp must be in (0.5, 1]");
  }
  if (!(free_betp >= 0.0 && free_betp < 0.5)) return fail(why, "free_betp must be in [0, 0.5)");
  if (!(max_nonspecificity >= 0.0 && max_nonspecificity <= 1.0)) {
    return fail(why, "max_nonspecificity must be in [0, 1]");
  }
  return true;
}

CellClass classify(const Cell& cell, const ClassifyConfig& config) {
  if (!cell.observed() || nonSpecificity(cell) > config.max_nonspecificity) {
    return CellClass::kUnknown;
  }
  const double betp = pignistic(cell);
  if (betp >= config.occupied_betp) return CellClass::kOccupied;
  if (betp <= config.free_betp) return CellClass::kFree;
  return CellClass::kUnknown;
}

bool scoreMap(const EvidentialGridMap& map, const Pose2& map_in_truth, const OccupancyRaster& truth,
              const ClassifyConfig& config, MapScore* score, std::string* why) {
  std::string reason;
  if (!truth.isValid(&reason)) return fail(why, reason);
  if (!config.isValid(&reason)) return fail(why, "invalid classification config: " + reason);
  std::vector<uint8_t> seen(truth.cells.size(), 0);
  auto truthCell = [&](const Eigen::Vector2d& p, size_t* index) {
    const double col = std::floor((p.x() - truth.origin_x) / truth.resolution);
    const double row = std::floor((p.y() - truth.origin_y) / truth.resolution);
    if (col < 0 || row < 0 || col >= truth.width || row >= truth.height) return false;
    *index = static_cast<size_t>(row) * static_cast<size_t>(truth.width) + static_cast<size_t>(col);
    return true;
  };
  const double res = map.resolution();
  const CellBox box = map.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      size_t k = 0;
      if (!truthCell(map_in_truth.transformPoint(Eigen::Vector2d((x + 0.5) * res, (y + 0.5) * res)),
                     &k)) {
        continue;
      }
      seen[k] |= kHasCentre;
      const CellClass c = classify(map.cell(x, y), config);
      if (c == CellClass::kFree) seen[k] |= kSawFree;
      if (c == CellClass::kOccupied) seen[k] |= kSawOccupied;
    }
  }
  const Pose2 truth_in_map = map_in_truth.inverse();
  MapScore s;
  for (int row = 0; row < truth.height; ++row) {
    for (int col = 0; col < truth.width; ++col) {
      const size_t k = static_cast<size_t>(row) * static_cast<size_t>(truth.width) + col;
      CellClass said = CellClass::kUnknown;
      if ((seen[k] & kHasCentre) == 0) {
        const Eigen::Vector2d p = truth_in_map.transformPoint(
            Eigen::Vector2d(truth.origin_x + (col + 0.5) * truth.resolution,
                            truth.origin_y + (row + 0.5) * truth.resolution));
        said = classify(map.cell(map.worldToCell(p.x(), p.y())), config);
      } else if ((seen[k] & kSawOccupied) != 0) {
        said = CellClass::kOccupied;
      } else if ((seen[k] & kSawFree) != 0) {
        said = CellClass::kFree;
      }
      const CellClass is = truth.cells[k];
      ++s.confusion[static_cast<size_t>(is)][static_cast<size_t>(said)];
      if (is == CellClass::kUnknown) continue;
      ++s.known;
      if (said == CellClass::kUnknown) continue;
      ++s.classified;
      if (said == is) ++s.correct;
    }
  }
  *score = s;
  return true;
}

}  // namespace fusion
}  // namespace evidential_slam
