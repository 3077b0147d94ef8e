#include "evidential_slam/core/measures.h"

#include <algorithm>
#include <cmath>

namespace evidential_slam {
namespace {
constexpr double kLn2 = 0.69314718055994530942;

double plogp2(double p) { return p > 0.0 ? p * std::log2(p) : 0.0; }
}  // namespace

double pignistic(const Cell& c) { return c.occupied() + 0.5 * c.unknown(); }

double entropyBits(const Cell& c) {
  const double p = pignistic(c);
  return -plogp2(p) - plogp2(1.0 - p);
}

double nonSpecificity(const Cell& c) { return c.toMass().unknown; }

double internalConflict(const Cell& c) {
  // Normalised masses are stored directly; pl̃(o) = m̃(o) + m̃(Θ) = 1 - m̃(e). In float, 1 - m̃(e)
  // can round below m̃(o) (even to 0); pl̃(o) >= m̃(o) always, so clamp there: no log2(0).
  const double mo = c.occupied(), me = c.free();
  const double term_o = mo > 0.0 ? mo * std::log2(std::max(1.0 - me, mo)) : 0.0;
  const double term_e = me > 0.0 ? me * std::log2(std::max(1.0 - mo, me)) : 0.0;
  return -c.oneMinusConflict() * (term_o + term_e);
}

double externalConflict(const Cell& c) { return c.lambda() / kLn2; }

const std::array<std::string, kLayerCount>& layerNames() {
  static const std::array<std::string, kLayerCount> names = {
      "occupied",  "free",           "unknown",           "conflict",
      "pignistic", "nonspecificity", "internal_conflict", "external_conflict",
      "entropy",   "anomaly"};
  return names;
}

const std::string& layerName(Layer layer) { return layerNames()[static_cast<int>(layer)]; }

double layerValue(const Cell& c, Layer layer) {
  switch (layer) {
    case Layer::kOccupied:
      return c.toMass().occupied;
    case Layer::kFree:
      return c.toMass().free;
    case Layer::kUnknown:
      return c.toMass().unknown;
    case Layer::kConflict:
      return c.toMass().conflict;
    case Layer::kPignistic:
      return pignistic(c);
    case Layer::kNonspecificity:
      return nonSpecificity(c);
    case Layer::kInternalConflict:
      return internalConflict(c);
    case Layer::kExternalConflict:
      return externalConflict(c);
    case Layer::kEntropy:
      return entropyBits(c);
    case Layer::kAnomaly:
      return 0.0;  // not held by the cell (anomaly.h); extractLayers fills it from an AnomalyGrid
  }
  return 0.0;
}

}  // namespace evidential_slam
