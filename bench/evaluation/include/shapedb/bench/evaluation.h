#pragma once
// The physical-fidelity benchmark (the measurement the paper leaves as future work, §7): for each query
// shape, the data each descriptor retrieves and adapts, and the data of two simple alternatives, against
// the data computed directly on the shape (TetGen + FEM + modes, the database's own pipeline and
// parameters). Errors are in the quantities a simulation uses: the first non-rigid frequencies and the
// volume of the collision proxy.
#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/adapt.h>
#include <shapedb/core/fidelity.h>
#include <shapedb/core/result.h>
#include <shapedb/io/database.h>

namespace shapedb::bench {

/// What supplies a shape's physical data: each descriptor's query as it answers by default, adapted (the
/// method; the voxel kinds ranked with their moment term, core::SearchOptions::momentWeight; the
/// eigenvalues blended from the nearest matches' spectra, io::QueryOptions::neighbours), or the
/// inertia-equivalent solid ellipsoid (the precomputed sound banks of Zheng & James 2010, at their
/// best: the exact ellipsoid rather than the nearest precomputed one) or box; the centroid-voxel match
/// adapted with the stretch correction (core/stretch.h; its time added to the query's); the centroid-voxel
/// match by the paper's distance alone (eq. 6, no moment term) and its spectrum alone (the paper's
/// method); the centroid-voxel query with the geometry correction (volume/correction.h: the entry's tets
/// morphed onto the shape, modes recomputed); and the centroid-voxel match's own spectrum alone.
enum class EvaluationMethod {
  kMoment,
  kVoxel,
  kCentroidVoxel,
  kEllipsoid,
  kBox,
  kCentroidVoxelStretched,
  kCentroidVoxelPaper,
  kCentroidVoxelCorrected,
  kCentroidVoxelNearest
};
inline constexpr std::array<EvaluationMethod, 9> kEvaluationMethods{EvaluationMethod::kMoment,
                                                                    EvaluationMethod::kVoxel,
                                                                    EvaluationMethod::kCentroidVoxel,
                                                                    EvaluationMethod::kEllipsoid,
                                                                    EvaluationMethod::kBox,
                                                                    EvaluationMethod::kCentroidVoxelStretched,
                                                                    EvaluationMethod::kCentroidVoxelPaper,
                                                                    EvaluationMethod::kCentroidVoxelCorrected,
                                                                    EvaluationMethod::kCentroidVoxelNearest};
/// "moment", "voxel", "centroid-voxel", "ellipsoid", "box", "centroid-voxel-stretched",
/// "centroid-voxel-paper", "centroid-voxel-corrected", "centroid-voxel-nearest".
const char* toString(EvaluationMethod method);

struct MethodEvaluation {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  EvaluationMethod method = EvaluationMethod::kCentroidVoxel;
  std::string match;              ///< the matched entry's name (descriptors); "" for the baselines
  std::string family;             ///< the matched entry's family (descriptors); "" for the baselines
  double distance = kNaN;         ///< the search's distance (descriptors: Match::distance)
  Eigen::VectorXd frequenciesHz;  ///< the first non-rigid frequencies, in the material
  /// Relative frequency errors against the direct computation, (f − f*) / f*: the first (signed), the
  /// mean and the max of |·| over the first EvaluationOptions::frequencies.
  double firstFrequencyError = kNaN;
  double meanFrequencyError = kNaN;
  double maxFrequencyError = kNaN;
  /// The collision proxy (the adapted compound; the baselines' own solid) against the shape's volume.
  core::VolumeOverlap overlap;
  /// Descriptors: the best match's fidelity terms (core::Fidelity) and the share of the shape's vertices
  /// that its link found outside the tets: the evidence a predicted error is made of.
  double meanDeviation = kNaN, maxDeviation = kNaN, maxMomentError = kNaN, descriptorDistance = kNaN;
  double outsideShare = kNaN;
  /// The corrected query: how far the shape's surface stays from the morphed tets, on average (relative
  /// to L; volume::MorphReport::meanTargetDistance).
  double morphTargetDistance = kNaN;
  double massScale = kNaN;        ///< the corrected query: volume::CorrectionReport::massScale
  double strayShare = kNaN;       ///< the corrected query: volume::CorrectionReport::strayShare
  double pointMassPeak = kNaN;    ///< the corrected query: volume::CorrectionReport::pointMassPeak
  double lumpedModeShare = kNaN;  ///< the corrected query: volume::CorrectionReport::lumpedModeShare
  /// The corrected query's morph (volume::MorphReport): the worst tet quality after it and before it, the
  /// largest and mean move of a boundary node (relative to L), the share of the final projection taken,
  /// and the prestretch's largest |ln| along an axis.
  double worstQuality = kNaN, entryWorstQuality = kNaN, maxBoundaryMove = kNaN, meanBoundaryMove = kNaN;
  double projected = kNaN, prestretch = kNaN;
  double predictedError = kNaN;  ///< descriptors: the query's QueryResult::predictedFrequencyError
  double queryMicros = kNaN;  ///< descriptors: the whole query (match, fetch, correct, adapt, link), fidelity
                              ///< report aside
  double matchMicros = kNaN;  ///< descriptors: validate, mass properties, describe, search
};

struct FragmentEvaluation {
  std::string name;
  std::size_t triangles = 0;
  double volume = 0.0;  ///< m³
  /// Empty when every method was evaluated; else why not (the shape was refused, TetGen failed on it):
  /// the fields below are then whatever was reached.
  std::string error;
  Eigen::VectorXd truthFrequenciesHz;  ///< computed directly on the shape
  double truthSeconds = 0.0;           ///< tetrahedralize + modes + collision compound, wall time
  std::size_t truthTets = 0;
  /// Triangles of the surface the truth was computed on: the shape's own, or fewer where it had more
  /// than EvaluationOptions::truthMaxTriangles and was simplified first.
  std::size_t truthTriangles = 0;
  std::vector<MethodEvaluation> methods;  ///< kEvaluationMethods' order
  /// Direct computation over the centroid-voxel query's time: what the database saves.
  double speedup() const;
  /// The same over the corrected query's time.
  double correctedSpeedup() const;
  bool ok() const { return error.empty(); }
};

struct EvaluationOptions {
  core::Material material = core::materialPresets()[0];  ///< steel
  int frequencies = 5;         ///< non-rigid frequencies compared (at most the database's modes)
  int overlapResolution = 48;  ///< sampling grid of the volume overlap, cells along the longest side
  int threads = 0;             ///< for the direct computations; 0: all cores
  /// Elements of the direct computations (the truth and both baselines). Quadratic ones do not lock in
  /// bending, so they are the better truth for a database of either kind.
  volume::ElementOrder directElements = volume::ElementOrder::kQuadratic;
  /// The truth is meshed finer than the database's entries, so that its own error is small against the
  /// errors it measures: TetGen's volume bound (volume::entryMeshing of directElements) divided by this,
  /// at the entries' quality bound. The baselines are meshed as entries are.
  double truthRefinement = 8.0;
  /// A shape of more triangles is simplified to about this many (volume::simplify, within 1e-3 of its
  /// size L) before its truth is computed: the tets of a 100k-triangle scan would not fit the memory of a
  /// quadratic solve. Its queries see the shape as it is.
  std::size_t truthMaxTriangles = 8000;
  /// The corrected method's io::QueryOptions::correctionCandidates.
  int correctionCandidates = io::QueryOptions{}.correctionCandidates;
  /// Another instance of the database evaluated (the same file, opened by the caller: an instance caches
  /// its own entries and what their corrections plan). Where given, every shape's queries run on it once
  /// first, untimed, so that the timed queries are those of a warm process (its heap grown to its working
  /// size and kept, its threads and libraries started), as the direct computations after them are, while
  /// the timed instance has still fetched no entry and planned no correction. Without it the first shapes
  /// of a run pay for the process's start: on the development machine the first shape's corrected query
  /// took 43 ms, the same query last in the run 29 ms.
  const io::Database* warmUp = nullptr;
  /// Called after each shape's direct computation, from one thread at a time: done, total, its name.
  std::function<void(std::size_t, std::size_t, const std::string&)> progress;
};

/// Evaluates every shape (closed meshes, any frame): first the queries (on options.warmUp, untimed, then
/// on `database`), one at a time so that their timings are those of an idle machine; then the direct
/// computations and the baselines in parallel. A shape that fails is reported in its FragmentEvaluation,
/// and the others go on.
/// Errors: kInvalidArgument for options out of range, a material validateMaterial refuses, or a warm-up
/// instance that is `database` itself or holds other entries.
Result<std::vector<FragmentEvaluation>> evaluateShapes(const io::Database& database,
                                                       std::span<const io::NamedMesh> shapes,
                                                       const EvaluationOptions& options = {});

/// Summary statistics of one method over the shapes that were evaluated.
struct MethodSummary {
  EvaluationMethod method = EvaluationMethod::kCentroidVoxel;
  std::size_t count = 0;
  double medianFirstError = 0.0;  ///< median of |first frequency error|
  double medianMeanError = 0.0;   ///< median of the mean error over the first frequencies
  double p90FirstError = 0.0;
  double medianIou = 0.0;
  double medianQueryMicros = MethodEvaluation::kNaN;  ///< descriptors
};
std::vector<MethodSummary> summarize(std::span<const FragmentEvaluation> evaluations);

/// One row per shape and method (CSV with a header; numbers in full precision).
/// Errors: kIo naming the file.
Status writeEvaluationCsv(std::span<const FragmentEvaluation> evaluations, const std::filesystem::path& path);

/// A Markdown summary: the setup (`title` first), the per-method table, the timing and speedup, and the
/// shapes that failed. Errors: kIo naming the file.
Status writeEvaluationSummary(std::span<const FragmentEvaluation> evaluations, const std::string& title,
                              const std::filesystem::path& path);

/// Two PNG plots in `directory`: time.png (direct computation and query time against the shape's
/// volume, log-log, as the paper's Figure 9) and error.png (first-frequency error of each method, one
/// dot per shape, the median marked). Errors: kIo naming the file.
Status writeEvaluationPlots(std::span<const FragmentEvaluation> evaluations,
                            const std::filesystem::path& directory);

}  // namespace shapedb::bench
