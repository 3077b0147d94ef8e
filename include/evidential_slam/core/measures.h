// Decision and uncertainty measures of a cell (paper §4) and the names of the map layers.
#pragma once

#include <array>
#include <string>

#include "evidential_slam/core/mass.h"

namespace evidential_slam {

// BetP(o), eq. (10). A vacuous cell gives 0.5.
double pignistic(const Cell& c);
// Shannon entropy of BetP in bits, eq. (11).
double entropyBits(const Cell& c);
// Non-specificity NS = m(Θ), eq. (13).
double nonSpecificity(const Cell& c);
// Internal conflict IC, eq. (15)/(16), in bits; equals entropy for a Bayesian mass.
double internalConflict(const Cell& c);
// External conflict EC = -log2(1 - m(∅)), eq. (18), in bits; unbounded.
double externalConflict(const Cell& c);

// The ten layers, in this order everywhere (files, topics, messages). The first nine are measures
// of a cell's belief; the anomaly is accumulated beside the map (anomaly.h).
enum class Layer : int {
  kOccupied = 0,      // m(o)
  kFree,              // m(e)
  kUnknown,           // m(Θ)
  kConflict,          // m(∅)
  kPignistic,         // BetP(o)
  kNonspecificity,    // NS
  kInternalConflict,  // IC
  kExternalConflict,  // EC (bits, unbounded)
  kEntropy,           // H(BetP)
  kAnomaly,           // evidence contradicting the map's confident belief (bits, unbounded)
};
constexpr int kLayerCount = 10;
const std::array<std::string, kLayerCount>& layerNames();
const std::string& layerName(Layer layer);
// Value of one layer for a cell. Unobserved (vacuous) cells give the vacuous value of each layer;
// kAnomaly, which the cell does not hold, gives 0.
double layerValue(const Cell& c, Layer layer);

}  // namespace evidential_slam
