#pragma once
// How the geometry correction shares the mass its morph misses among the morphed tets' nodes
// (volume/correction.h, MorphedEntry::pointMasses). Private to the volume module.

#include <span>
#include <vector>

namespace shapedb::volume::detail {

/// `mass` shared among the nodes in proportion to `weights` (≥ 0; the nodes of weight 0 take none), none
/// more than kPointMassLimit times its `own` mass as long as the others can take the rest (the nodes whose
/// limit is least for their weight reach it first, and the others share what they leave, in the same
/// proportion); where every weighted node is at its limit, the rest over all the nodes in proportion to
/// `own`. Sums to `mass` (to round-off) unless every weight and every own mass is 0.
std::vector<double> limitedShares(std::span<const double> weights, std::span<const double> own, double mass);

}  // namespace shapedb::volume::detail
