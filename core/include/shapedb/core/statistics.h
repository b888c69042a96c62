#pragma once

// The summary statistics every report in shapedb uses (benchmarks, the fidelity evaluation, the haptic
// loop's report), with one definition each.

#include <vector>

namespace shapedb::core {

/// The q-quantile by the nearest-rank definition: the smallest value with at least ⌈q·n⌉ of the n
/// values at or below it (so the p99 of 100 values is the second largest, not the largest). q in
/// (0, 1]. Non-finite values are left out; NaN when none is left.
double percentile(std::vector<double> values, double q);

/// The median: the middle value, or the mean of the two middle values for an even count. Non-finite
/// values are left out; NaN when none is left.
double median(std::vector<double> values);

/// Spearman's rank correlation of two paired samples: Pearson's correlation of their ranks, ties given
/// their mean rank. Pairs with a non-finite value are left out; NaN when fewer than two pairs are left,
/// or either side is constant. Throws nothing; sizes must match (else NaN).
double spearman(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace shapedb::core
