#pragma once
// How wrong an answer probably is: a calibrated estimate of the first-frequency error of a query's
// physical data, from what the query knows about its match (the fidelity report, the link, the geometry
// correction's morph). What decides whether an object is worth learning exactly (io/enrich.h).

#include <array>
#include <optional>

namespace shapedb::core {

/// The evidence an estimate is made of, all relative to the query's size L = V^(1/3) where lengths.
struct ErrorEvidence {
  double meanDeviation = 0.0;       ///< Fidelity::meanDeviation
  double maxDeviation = 0.0;        ///< Fidelity::maxDeviation
  double maxMomentError = 0.0;      ///< Fidelity::maxMomentError
  double descriptorDistance = 0.0;  ///< Fidelity::descriptorDistance (the grid's part of the distance)
  double outsideShare = 0.0;        ///< share of the query's vertices outside the adapted tets (the link)
  /// Corrected answers only: volume::MorphReport::meanTargetDistance.
  std::optional<double> morphTargetDistance;
  /// Corrected answers only: volume::CorrectionReport::massScale, the query's volume over the morphed
  /// tets'. Far from 1, much of the query's mass is lumped where the tets do not reach (or the tets hold
  /// more than the query), and the answer is less sure.
  std::optional<double> massScale;
  /// Corrected answers only: volume::CorrectionReport::strayShare, the share of the morphed tets' volume
  /// outside the query's surface (material across a gap the query has).
  std::optional<double> strayShare;
};

struct Fidelity;

/// The evidence of a fidelity report alone (no link, not corrected).
ErrorEvidence evidenceOf(const Fidelity& fidelity);

inline constexpr int kErrorFeatures = 9;
using ErrorFeatures = std::array<double, kErrorFeatures>;

/// The model's features: 1, ln(meanDeviation + 1e-3), ln(maxDeviation + 1e-3), ln(maxMomentError +
/// 1e-3), ln(descriptorDistance + 1e-2), outsideShare, ln(morphTargetDistance + 1e-3), |ln massScale| and
/// strayShare (each 0 when not known). Logarithms: the errors span three decades and grow with the evidence's
/// own scale.
ErrorFeatures errorFeatures(const ErrorEvidence& evidence);

/// Weights of the features for the nearest entry's answer and the corrected one: ln|error| ≈ w · f.
struct ErrorModel {
  ErrorFeatures nearest{};
  ErrorFeatures corrected{};
};

/// The model shapedb ships, fitted on benchmark data (its provenance, fit and held-out quality in
/// docs/accuracy.md, "Predicted error"; refit with bench/error_model_fit.cpp).
const ErrorModel& defaultErrorModel();

/// The largest estimate made: 10, an error of 1,000 %. The model is a straight line in the logarithm,
/// fitted on errors up to about 7 (+693 %, a knot); far past its data (tets that hold a quarter of the
/// query and lie almost all outside it) the line gave thousands, which only meant "far off".
inline constexpr double kMaxPredictedError = 10.0;

/// exp(w · f), the weights chosen by whether the evidence is of a corrected answer, at most
/// kMaxPredictedError: the predicted magnitude of the first non-rigid frequency's relative error (0.1:
/// 10 %).
double predictFrequencyError(const ErrorEvidence& evidence, const ErrorModel& model = defaultErrorModel());

}  // namespace shapedb::core
