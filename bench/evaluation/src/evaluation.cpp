#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <shapedb/bench/evaluation.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/statistics.h>
#include <shapedb/core/stretch.h>
#include <shapedb/io/plot.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/simplify.h>

namespace shapedb::bench {

namespace {

using Clock = std::chrono::steady_clock;
using core::median;
using core::percentile;
/// The queries of each shape: the three descriptors as a query makes them (`momentWeight` and
/// `neighbours` unset: the defaults), then the centroid-voxel descriptor by the paper's distance alone
/// and the nearest entry's spectrum alone (the paper's method), then the centroid-voxel query with the
/// geometry correction, then the centroid-voxel query answered by the nearest entry's spectrum alone.
struct QueryMethod {
  core::DescriptorKind kind;
  std::optional<double> momentWeight;
  bool correct = false;
  std::optional<int> neighbours;
};
constexpr std::array<QueryMethod, 6> kQueries{
    {{core::DescriptorKind::kMoment, std::nullopt, false, std::nullopt},
     {core::DescriptorKind::kVoxel, std::nullopt, false, std::nullopt},
     {core::DescriptorKind::kCentroidVoxel, std::nullopt, false, std::nullopt},
     {core::DescriptorKind::kCentroidVoxel, 0.0, false, 1},
     {core::DescriptorKind::kCentroidVoxel, std::nullopt, true, std::nullopt},
     {core::DescriptorKind::kCentroidVoxel, std::nullopt, false, 1}}};
constexpr std::size_t kDescriptorQueries = 3, kPaperQuery = 3, kCorrectedQuery = 4, kNearestQuery = 5;
constexpr std::size_t kCentroidVoxelIndex = 2, kEllipsoidIndex = 3, kBoxIndex = 4, kCorrectedIndex = 7;

/// The relative errors of `f` against `truth` over their first n frequencies.
void frequencyErrors(MethodEvaluation& m, const Eigen::VectorXd& f, const Eigen::VectorXd& truth, int n) {
  n = std::min<int>({n, static_cast<int>(f.size()), static_cast<int>(truth.size())});
  m.frequenciesHz = f.head(n);
  m.firstFrequencyError = m.meanFrequencyError = m.maxFrequencyError = MethodEvaluation::kNaN;
  if (n == 0) return;
  m.firstFrequencyError = (f[0] - truth[0]) / truth[0];
  double sum = 0.0, worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const double e = std::abs(f[i] - truth[i]) / truth[i];
    sum += e;
    worst = std::max(worst, e);
  }
  m.meanFrequencyError = sum / n;
  m.maxFrequencyError = worst;
}

/// Frequencies (Hz) of a surface's solid in `material`, computed directly: TetGen, then modes for unit
/// E and ρ at the surface's own size, scaled by sqrt(E/ρ).
Result<Eigen::VectorXd> directFrequencies(const core::TriangleMesh& surface,
                                          const volume::EntryOptions& entry, const core::Material& material) {
  Result<core::TetMesh> tets = volume::tetrahedralize(surface, entry.tetgen);
  if (!tets) return tets.error();
  Result<core::ModalData> modes = volume::computeModes(*tets, entry.modal);
  if (!modes) return modes.error();
  return Eigen::VectorXd(modes->frequenciesHz() * std::sqrt(material.youngsModulus / material.density));
}

/// Fills one baseline: the inertia-equivalent solid `surface` (made in its principal frame, centred),
/// placed at the shape's centre of mass along its principal axes for the overlap.
void evaluateBaseline(MethodEvaluation& m, const core::TriangleMesh& surface,
                      const core::SampledSolid& placed, const core::SampledSolid& shape,
                      const volume::EntryOptions& entry, const EvaluationOptions& options,
                      const Eigen::VectorXd& truth, std::string& error) {
  Result<Eigen::VectorXd> f = directFrequencies(surface, entry, options.material);
  if (!f) {
    error = std::string(toString(m.method)) + " baseline: " + f.error().message;
    return;
  }
  frequencyErrors(m, *f, truth, options.frequencies);
  m.overlap = core::sampleOverlap(shape, placed, options.overlapResolution);
}

io::PlotSeries makeSeries(std::string label, std::array<std::uint8_t, 3> color,
                          io::PlotSeries::Style style = io::PlotSeries::Style::kDots) {
  io::PlotSeries s;
  s.label = std::move(label);
  s.color = color;
  s.style = style;
  return s;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s)
    out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

}  // namespace

const char* toString(EvaluationMethod method) {
  switch (method) {
    case EvaluationMethod::kMoment:
      return "moment";
    case EvaluationMethod::kVoxel:
      return "voxel";
    case EvaluationMethod::kCentroidVoxel:
      return "centroid-voxel";
    case EvaluationMethod::kEllipsoid:
      return "ellipsoid";
    case EvaluationMethod::kBox:
      return "box";
    case EvaluationMethod::kCentroidVoxelStretched:
      return "centroid-voxel-stretched";
    case EvaluationMethod::kCentroidVoxelPaper:
      return "centroid-voxel-paper";
    case EvaluationMethod::kCentroidVoxelCorrected:
      return "centroid-voxel-corrected";
    case EvaluationMethod::kCentroidVoxelNearest:
      return "centroid-voxel-nearest";
  }
  return "?";
}

namespace {

/// The direct computation's time over the query time of the method at `index`.
double speedupOf(const FragmentEvaluation& e, std::size_t index) {
  if (e.methods.size() <= index) return MethodEvaluation::kNaN;
  const double query = e.methods[index].queryMicros;
  return query > 0.0 ? e.truthSeconds * 1e6 / query : MethodEvaluation::kNaN;
}

}  // namespace

double FragmentEvaluation::speedup() const {
  return speedupOf(*this, kCentroidVoxelIndex);
}

double FragmentEvaluation::correctedSpeedup() const {
  return speedupOf(*this, kCorrectedIndex);
}

namespace {

/// The truth's entry options: the direct computation's elements, meshed finer than the entries.
volume::EntryOptions truthOptions(const volume::EntryOptions& entry, const EvaluationOptions& options) {
  volume::EntryOptions truth = volume::withElements(entry, options.directElements);
  // Smaller tets, not better-shaped ones: a tighter quality bound made TetGen refine the sharp features of
  // CAD parts without end (a 1,488-triangle part took 11 minutes at q1.5).
  truth.tetgen.maxVolumeFraction /= options.truthRefinement;
  truth.tetgen.wallEdgeFraction /= std::cbrt(options.truthRefinement);  // sizes are lengths
  truth.tetgen.timeoutSeconds = 600.0;
  return truth;
}

}  // namespace

Result<std::vector<FragmentEvaluation>> evaluateShapes(const io::Database& database,
                                                       std::span<const io::NamedMesh> shapes,
                                                       const EvaluationOptions& options) {
  const volume::EntryOptions& entry = database.parameters().entry;
  const volume::EntryOptions direct = volume::withElements(entry, options.directElements);
  const volume::EntryOptions truthEntry = truthOptions(entry, options);
  if (!(options.truthRefinement >= 1.0 && options.truthRefinement <= 1000.0))
    return Error{ErrorCode::kInvalidArgument, "the truth's refinement must be 1 to 1,000"};
  if (options.truthMaxTriangles < 100)
    return Error{ErrorCode::kInvalidArgument, "the truth needs at least 100 triangles a shape"};
  if (options.frequencies < 1 || options.frequencies > entry.modal.modes)
    return Error{ErrorCode::kInvalidArgument, "frequencies to compare must be 1 to the database's " +
                                                  std::to_string(entry.modal.modes) + " modes, not " +
                                                  std::to_string(options.frequencies)};
  if (options.overlapResolution < 8 || options.overlapResolution > 512)
    return Error{ErrorCode::kInvalidArgument, "the overlap resolution must be 8 to 512 cells, not " +
                                                  std::to_string(options.overlapResolution)};
  if (options.correctionCandidates < 1 || options.correctionCandidates > io::kMaxCorrectionCandidates)
    return Error{ErrorCode::kInvalidArgument, "the correction's candidates must be 1 to " +
                                                  std::to_string(io::kMaxCorrectionCandidates) + ", not " +
                                                  std::to_string(options.correctionCandidates)};
  if (Status st = core::validateMaterial(options.material); !st) return st.error();

  if (options.warmUp == &database)
    return Error{ErrorCode::kInvalidArgument,
                 "the warm-up needs a database instance of its own: its queries would cache the entries of "
                 "the timed ones"};
  if (options.warmUp && options.warmUp->entries().size() != database.entries().size())
    return Error{ErrorCode::kInvalidArgument,
                 "the warm-up database holds " + std::to_string(options.warmUp->entries().size()) +
                     " entries and the evaluated one " + std::to_string(database.entries().size()) +
                     ": it must be another instance of the same file"};

  const auto queryOptions = [&](const QueryMethod& method) {
    io::QueryOptions q;
    q.descriptor = method.kind;
    q.search.k = 1;
    if (method.momentWeight) q.search.momentWeight = *method.momentWeight;
    q.correct = method.correct;
    q.correctionCandidates = options.correctionCandidates;
    if (method.neighbours) q.neighbours = *method.neighbours;
    q.material = options.material;
    q.fidelity = true;  // its evidence is recorded; its time is not counted
    return q;
  };

  // 0. The process warmed on an instance of its own (EvaluationOptions::warmUp); nothing of it is kept.
  if (options.warmUp)
    for (const io::NamedMesh& shape : shapes)
      for (const QueryMethod& method : kQueries)
        static_cast<void>(options.warmUp->query(shape.mesh, queryOptions(method)));

  std::vector<FragmentEvaluation> out(shapes.size());
  // 1. The queries, one at a time: their timings are those of a machine doing nothing else.
  std::vector<std::array<std::optional<io::QueryResult>, kQueries.size()>> queries(shapes.size());
  struct Stretched {
    Eigen::VectorXd frequenciesHz;
    double micros = 0.0;
  };
  std::vector<Stretched> stretched(shapes.size());
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    FragmentEvaluation& e = out[i];
    e.name = shapes[i].name;
    e.triangles = shapes[i].mesh.triangles.size();
    for (std::size_t k = 0; k < kQueries.size() && e.ok(); ++k) {
      Result<io::QueryResult> r = database.query(shapes[i].mesh, queryOptions(kQueries[k]));
      if (!r)
        e.error = std::string("query (") + core::toString(kQueries[k].kind) + "): " + r.error().message;
      else
        queries[i][k] = std::move(r).value();
    }
    if (e.ok()) e.volume = queries[i][0]->massProperties.volume;
    // The centroid-voxel match adapted again with the stretch correction, timed as a cold query would
    // pay it: the entry's stretch basis, then the adaptation. Linear-tet databases only: for the others
    // the column stays empty (no frequencies, errors NaN, left out of the medians).
    if (e.ok() && database.supportsStretchCorrection()) {
      const io::QueryResult& q = *queries[i][kCentroidVoxelIndex];
      const Clock::time_point start = Clock::now();
      const core::StretchBasis basis =
          core::computeStretchBasis(q.entryPhysics->tetMesh, q.entryPhysics->modes);
      Result<core::AdaptedPhysics> a =
          core::adapt(*q.entryPhysics, q.normalization, q.massProperties, q.answeredMatch().match.orientation,
                      options.material, entry.damping, &basis);
      stretched[i].micros = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
      if (!a)
        e.error = "stretched adaptation: " + a.error().message;
      else
        stretched[i].frequenciesHz = a->frequenciesHz();
    }
  }

  // 2. The direct computations and the baselines, in parallel.
  std::mutex progressMutex;
  std::size_t done = 0;
  auto evaluateOne = [&](std::size_t i) {
    FragmentEvaluation& e = out[i];
    const core::TriangleMesh& mesh = shapes[i].mesh;
    if (e.ok()) {
      // The truth's surface: the shape, simplified if it is too large for a quadratic solve.
      core::TriangleMesh simplified;
      const core::TriangleMesh* truthSurface = &mesh;
      if (mesh.triangleCount() > options.truthMaxTriangles) {
        Result<core::TriangleMesh> s = volume::simplify(
            mesh, {.maxTriangles = options.truthMaxTriangles, .maxError = 1e-3 * std::cbrt(e.volume)});
        if (s) {
          simplified = std::move(s).value();
          truthSurface = &simplified;
        } else {
          e.error = "direct computation: simplifying the shape: " + s.error().message;
        }
      }
      e.truthTriangles = truthSurface->triangleCount();
      Result<volume::EntryData> truth =
          e.ok() ? volume::computeEntry(*truthSurface, truthEntry)
                 : Result<volume::EntryData>(Error{ErrorCode::kInvalidArgument, e.error});
      if (!truth) {
        if (e.ok()) e.error = "direct computation: " + truth.error().message;
      } else {
        const volume::StageTimes& t = truth->times;
        e.truthSeconds = t.normalize + t.tetrahedralize + t.modes + t.collision;  // describing is not needed
        e.truthTets = truth->physics.tetMesh.tetCount();
        Result<core::AdaptedPhysics> exact =
            core::adapt(truth->physics, truth->normalization, truth->surfaceMassProperties,
                        core::Mat3::Identity(), options.material, entry.damping);
        if (!exact) {
          e.error = "direct computation: " + exact.error().message;
        } else {
          e.truthFrequenciesHz = exact->frequenciesHz().head(
              std::min<Eigen::Index>(options.frequencies, exact->eigenvalues.size()));
          // The shape's solid, through the tets of its own direct computation.
          const core::TetLocator locator(truth->physics.tetMesh);
          const core::Mat4 toCanonical = truth->normalization.canonicalFromMesh;
          const core::SampledSolid shape{[&](const core::Vec3& p) {
                                           const core::Vec3 c = (toCanonical * p.homogeneous()).head<3>();
                                           return locator.locate(c).inside();
                                         },
                                         core::computeBounds(mesh)};

          const auto retrieved = [&](std::size_t k, EvaluationMethod method) {
            const io::QueryResult& q = *queries[i][k];
            MethodEvaluation m;
            m.method = method;
            const io::MatchReport& best = q.answeredMatch();
            m.match = best.entry->name;
            m.family = volume::toString(best.entry->family);
            m.distance = best.match.distance;
            frequencyErrors(m, q.physics->frequenciesHz(), e.truthFrequenciesHz, options.frequencies);
            m.overlap = core::sampleOverlap(shape, core::sampledSolid(q.physics->collision),
                                            options.overlapResolution);
            m.queryMicros = q.times.total - q.times.fidelity;
            if (best.fidelity) {
              m.meanDeviation = best.fidelity->meanDeviation;
              m.maxDeviation = best.fidelity->maxDeviation;
              m.maxMomentError = best.fidelity->maxMomentError;
              m.descriptorDistance = best.fidelity->descriptorDistance;
            }
            if (!q.link.locations.empty())
              m.outsideShare =
                  static_cast<double>(q.link.outsideCount) / static_cast<double>(q.link.locations.size());
            if (q.correction) {
              m.morphTargetDistance = q.correction->morph.meanTargetDistance;
              m.massScale = q.correction->massScale;
              m.strayShare = q.correction->strayShare;
              m.pointMassPeak = q.correction->pointMassPeak;
              m.lumpedModeShare = q.correction->lumpedModeShare;
              const volume::MorphReport& morph = q.correction->morph;
              m.worstQuality = morph.worstQuality;
              m.entryWorstQuality = morph.entryWorstQuality;
              m.maxBoundaryMove = morph.maxBoundaryMove;
              m.meanBoundaryMove = morph.meanBoundaryMove;
              m.projected = morph.projected;
              m.prestretch = morph.stretch.array().log().abs().maxCoeff();
            }
            if (q.predictedFrequencyError) m.predictedError = *q.predictedFrequencyError;
            m.matchMicros = q.times.validate + q.times.massProperties + q.times.describe + q.times.search;
            return m;
          };
          for (std::size_t k = 0; k < kDescriptorQueries; ++k)
            e.methods.push_back(retrieved(k, kEvaluationMethods[k]));

          // The baselines, at the shape's centre of mass along its principal axes.
          const core::Normalization& n = truth->normalization;
          const core::Vec3 centre = truth->surfaceMassProperties.centerOfMass;
          const double mass = truth->surfaceMassProperties.mass;
          const core::Mat3 axes = n.principalAxes;

          MethodEvaluation ellipsoid;
          ellipsoid.method = EvaluationMethod::kEllipsoid;
          const core::Vec3 radii = core::inertiaEquivalentEllipsoid(n.principalMoments, mass);
          const core::Vec3 reach =
              (axes.array().square().matrix() * radii.array().square().matrix()).cwiseSqrt();
          const core::SampledSolid placedEllipsoid{
              [&](const core::Vec3& p) {
                return ((axes.transpose() * (p - centre)).array() / radii.array()).matrix().squaredNorm() <=
                       1.0;
              },
              core::Bounds{centre - reach, centre + reach}};
          const volume::ShapeResolution& res = database.parameters().resolution;
          evaluateBaseline(ellipsoid,
                           core::makeUvEllipsoid(radii, std::max(res.segments, 24), std::max(res.stacks, 12)),
                           placedEllipsoid, shape, direct, options, e.truthFrequenciesHz, e.error);
          e.methods.push_back(std::move(ellipsoid));

          MethodEvaluation box;
          box.method = EvaluationMethod::kBox;
          core::CollisionCompound boxSolid;
          core::CollisionShape boxShape;
          boxShape.type = core::CollisionShape::Type::kBox;
          boxShape.center = centre;
          boxShape.rotation = axes;
          boxShape.halfExtents = core::inertiaEquivalentBox(n.principalMoments, mass);
          boxSolid.shapes.push_back(boxShape);
          if (e.ok())
            evaluateBaseline(box, core::makeBox(2.0 * boxShape.halfExtents), core::sampledSolid(boxSolid),
                             shape, direct, options, e.truthFrequenciesHz, e.error);
          e.methods.push_back(std::move(box));

          // The centroid-voxel match, stretched to the shape's proportions before it is adapted.
          MethodEvaluation stretch = e.methods[kCentroidVoxelIndex];
          stretch.method = EvaluationMethod::kCentroidVoxelStretched;
          stretch.queryMicros = database.supportsStretchCorrection()
                                    ? stretch.queryMicros + stretched[i].micros
                                    : MethodEvaluation::kNaN;  // not evaluated: no time, no errors
          frequencyErrors(stretch, stretched[i].frequenciesHz, e.truthFrequenciesHz, options.frequencies);
          e.methods.push_back(std::move(stretch));

          e.methods.push_back(retrieved(kPaperQuery, EvaluationMethod::kCentroidVoxelPaper));
          e.methods.push_back(retrieved(kCorrectedQuery, EvaluationMethod::kCentroidVoxelCorrected));
          e.methods.push_back(retrieved(kNearestQuery, EvaluationMethod::kCentroidVoxelNearest));
        }
      }
    }
    if (options.progress) {
      const std::lock_guard lock(progressMutex);
      options.progress(++done, shapes.size(), e.name);
    }
  };
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] { tbb::parallel_for(std::size_t{0}, shapes.size(), evaluateOne); });
  return out;
}

std::vector<MethodSummary> summarize(std::span<const FragmentEvaluation> evaluations) {
  std::vector<MethodSummary> out;
  for (std::size_t k = 0; k < kEvaluationMethods.size(); ++k) {
    MethodSummary s;
    s.method = kEvaluationMethods[k];
    std::vector<double> first, mean, iou, query;
    for (const FragmentEvaluation& e : evaluations) {
      if (!e.ok() || e.methods.size() <= k) continue;
      const MethodEvaluation& m = e.methods[k];
      if (!std::isfinite(m.firstFrequencyError)) continue;  // not evaluated (the stretch, on quadratic tets)
      ++s.count;
      first.push_back(std::abs(m.firstFrequencyError));
      mean.push_back(m.meanFrequencyError);
      iou.push_back(m.overlap.iou);
      query.push_back(m.queryMicros);
    }
    s.medianFirstError = median(first);
    s.p90FirstError = percentile(first, 0.9);
    s.medianMeanError = median(mean);
    s.medianIou = median(iou);
    s.medianQueryMicros = median(query);
    out.push_back(s);
  }
  return out;
}

Status writeEvaluationCsv(std::span<const FragmentEvaluation> evaluations,
                          const std::filesystem::path& path) {
  std::ofstream file(path);
  if (!file) return Error{ErrorCode::kIo, path.string() + ": cannot open for writing"};
  constexpr std::string_view kHeader =
      "shape,triangles,volume_m3,truth_tets,truth_s,method,match,family,distance,f1_hz,f1_truth_hz,"
      "f1_error,mean_error,max_error,frequencies,iou,coverage,overshoot,query_us,match_us,speedup,"
      "mean_deviation,max_deviation,max_moment_error,descriptor_distance,outside_share,"
      "morph_target_distance,mass_scale,stray_share,point_mass_peak,lumped_mode_share,worst_quality,"
      "entry_worst_quality,max_boundary_move,mean_boundary_move,projected,prestretch,predicted_error,status";
  // A shape that failed has its five shape columns, every method column empty, and its status.
  constexpr std::size_t kShapeColumns = 5;
  const std::string noMethod(
      static_cast<std::size_t>(std::count(kHeader.begin(), kHeader.end(), ',')) - kShapeColumns, ',');
  file << kHeader << "\n";
  for (const FragmentEvaluation& e : evaluations) {
    const std::string head = csvField(e.name) + "," + std::to_string(e.triangles) + "," + number(e.volume) +
                             "," + std::to_string(e.truthTets) + "," + number(e.truthSeconds) + ",";
    if (e.methods.empty()) {
      file << head << noMethod << csvField(e.error) << "\n";
      continue;
    }
    for (const MethodEvaluation& m : e.methods) {
      const double f1 = m.frequenciesHz.size() > 0 ? m.frequenciesHz[0] : MethodEvaluation::kNaN;
      const double t1 = e.truthFrequenciesHz.size() > 0 ? e.truthFrequenciesHz[0] : MethodEvaluation::kNaN;
      const bool descriptor = std::isfinite(m.queryMicros);
      file << head << toString(m.method) << "," << csvField(m.match) << "," << m.family << ","
           << number(m.distance) << "," << number(f1) << "," << number(t1) << ","
           << number(m.firstFrequencyError) << "," << number(m.meanFrequencyError) << ","
           << number(m.maxFrequencyError) << "," << m.frequenciesHz.size() << "," << number(m.overlap.iou)
           << "," << number(m.overlap.coverage) << "," << number(m.overlap.overshoot) << ","
           << number(m.queryMicros) << "," << number(m.matchMicros) << ","
           << (descriptor ? number(e.truthSeconds * 1e6 / m.queryMicros) : std::string()) << ","
           << number(m.meanDeviation) << "," << number(m.maxDeviation) << "," << number(m.maxMomentError)
           << "," << number(m.descriptorDistance) << "," << number(m.outsideShare) << ","
           << number(m.morphTargetDistance) << "," << number(m.massScale) << "," << number(m.strayShare)
           << "," << number(m.pointMassPeak) << "," << number(m.lumpedModeShare) << ","
           << number(m.worstQuality) << "," << number(m.entryWorstQuality) << "," << number(m.maxBoundaryMove)
           << "," << number(m.meanBoundaryMove) << "," << number(m.projected) << "," << number(m.prestretch)
           << "," << number(m.predictedError) << "," << (e.ok() ? std::string("ok") : csvField(e.error))
           << "\n";
    }
  }
  file.flush();
  if (!file) return Error{ErrorCode::kIo, path.string() + ": write failed"};
  return Ok{};
}

Status writeEvaluationSummary(std::span<const FragmentEvaluation> evaluations, const std::string& title,
                              const std::filesystem::path& path) {
  std::ofstream file(path);
  if (!file) return Error{ErrorCode::kIo, path.string() + ": cannot open for writing"};
  std::size_t ok = 0;
  std::vector<double> truth, tets, speedups, correctedSpeedups, triangles;
  std::size_t simplified = 0;
  for (const FragmentEvaluation& e : evaluations) {
    if (!e.ok()) continue;
    ++ok;
    truth.push_back(e.truthSeconds);
    tets.push_back(static_cast<double>(e.truthTets));
    speedups.push_back(e.speedup());
    correctedSpeedups.push_back(e.correctedSpeedup());
    triangles.push_back(static_cast<double>(e.triangles));
    simplified += e.truthTriangles < e.triangles ? 1 : 0;
  }
  char line[512];
  file << "# " << title << "\n\n";
  file << ok << " of " << evaluations.size()
       << " shapes evaluated. Errors are against the data computed directly on each shape (the truth) with "
          "the database's own pipeline (TetGen, FEM on the tets the title names, shift-invert Lanczos), "
          "meshed finer than the database's entries";
  if (simplified) file << "; " << simplified << " shapes of many triangles were simplified first (see below)";
  file << ".\n\n";
  Eigen::Index frequencyCount = 0;
  for (const FragmentEvaluation& e : evaluations)
    if (e.ok()) frequencyCount = std::max(frequencyCount, e.truthFrequenciesHz.size());
  file << "| method | shapes | median abs. first-frequency error | p90 | median mean error, first "
       << frequencyCount << " | median collision-proxy IoU | median query |\n";
  file << "|---|---:|---:|---:|---:|---:|---:|\n";
  for (const MethodSummary& s : summarize(evaluations)) {
    if (s.count == 0) {
      file << "| " << toString(s.method) << " | 0 | n/a | n/a | n/a | n/a | n/a |\n";
      continue;
    }
    std::snprintf(line, sizeof line, "| %s | %zu | %.1f %% | %.1f %% | %.1f %% | %.3f | %s |\n",
                  toString(s.method), s.count, 100.0 * s.medianFirstError, 100.0 * s.p90FirstError,
                  100.0 * s.medianMeanError, s.medianIou,
                  std::isfinite(s.medianQueryMicros)
                      ? (std::to_string(static_cast<long>(std::lround(s.medianQueryMicros))) + " µs").c_str()
                      : "(computed)");
    file << line;
  }
  // How often a method beats both baselines, shape by shape.
  for (const std::size_t index : {kCentroidVoxelIndex, kCorrectedIndex}) {
    std::size_t wins = 0, compared = 0;
    for (const FragmentEvaluation& e : evaluations) {
      if (!e.ok() || e.methods.size() < kEvaluationMethods.size()) continue;
      const double error = std::abs(e.methods[index].firstFrequencyError);
      ++compared;
      wins += error < std::abs(e.methods[kEllipsoidIndex].firstFrequencyError) &&
              error < std::abs(e.methods[kBoxIndex].firstFrequencyError);
    }
    std::snprintf(
        line, sizeof line,
        "%sThe %s method has a smaller first-frequency error than both baselines on %zu of %zu shapes.\n",
        index == kCentroidVoxelIndex ? "\n" : "", toString(kEvaluationMethods[index]), wins, compared);
    file << line;
  }
  const auto least = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
  };
  std::snprintf(
      line, sizeof line,
      "\nDirect computation (tetrahedralize, modes, collision compound): median %.3g s, %.0f tets, for "
      "a median %.0f triangles. The whole centroid-voxel query (match, fetch, adapt, link) is a "
      "median %.0f× faster (min %.0f×); with the geometry correction, %.0f× (min %.0f×).\n",
      median(truth), median(tets), median(triangles), median(speedups), least(speedups),
      median(correctedSpeedups), least(correctedSpeedups));
  file << line;
  if (simplified) {
    file << "\nSimplified for the truth (triangles: the shape's, the truth's):";
    for (const FragmentEvaluation& e : evaluations)
      if (e.ok() && e.truthTriangles < e.triangles)
        file << " " << e.name << " (" << e.triangles << ", " << e.truthTriangles << ")";
    file << ".\n";
  }
  bool header = false;
  for (const FragmentEvaluation& e : evaluations) {
    if (e.ok()) continue;
    if (!header) file << "\n## Shapes not evaluated\n\n";
    header = true;
    file << "- " << e.name << ": " << e.error << "\n";
  }
  file << "\nPer shape and method: evaluation.csv. Plots: time.png, error.png.\n";
  file.flush();
  if (!file) return Error{ErrorCode::kIo, path.string() + ": write failed"};
  return Ok{};
}

Status writeEvaluationPlots(std::span<const FragmentEvaluation> evaluations,
                            const std::filesystem::path& directory) {
  io::PlotSeries direct = makeSeries("direct: TetGen + FEM + modes + compound", {214, 39, 40});
  io::PlotSeries query = makeSeries("query, centroid-voxel: match + fetch + adapt + link", {31, 119, 180});
  io::PlotSeries match = makeSeries("describe + search", {44, 160, 44});
  for (const FragmentEvaluation& e : evaluations) {
    if (!e.ok()) continue;
    const double t = e.volume * 1e6;  // cm³
    direct.x.push_back(t);
    direct.y.push_back(e.truthSeconds);
    query.x.push_back(t);
    query.y.push_back(e.methods[kCentroidVoxelIndex].queryMicros * 1e-6);
    match.x.push_back(t);
    match.y.push_back(e.methods[kCentroidVoxelIndex].matchMicros * 1e-6);
  }
  io::PlotAxes timeAxes;
  timeAxes.title = "Physical data for each shape: computed directly, or queried";
  timeAxes.xLabel = "volume of the shape, cm3";
  timeAxes.yLabel = "seconds";
  timeAxes.logX = timeAxes.logY = true;
  const std::vector<io::PlotSeries> timeSeries{direct, query, match};
  if (Status st = io::savePng(io::plotChart(timeAxes, timeSeries), directory / "time.png"); !st) return st;

  io::PlotAxes errorAxes;
  errorAxes.title = "First-frequency error against the direct computation, per shape";
  errorAxes.xLabel = "method (bars: medians)";
  errorAxes.yLabel = "|f1 - f1*| / f1*, %";
  std::vector<io::PlotSeries> errorSeries;
  const std::array<std::array<std::uint8_t, 3>, kEvaluationMethods.size()> colors{{{148, 103, 189},
                                                                                   {255, 127, 14},
                                                                                   {31, 119, 180},
                                                                                   {140, 86, 75},
                                                                                   {127, 127, 127},
                                                                                   {23, 190, 207},
                                                                                   {188, 189, 34},
                                                                                   {214, 39, 40},
                                                                                   {44, 160, 44}}};
  io::PlotSeries medians = makeSeries("", {0, 0, 0}, io::PlotSeries::Style::kTicks);
  for (std::size_t k = 0; k < kEvaluationMethods.size(); ++k) {
    errorAxes.categories.push_back(toString(kEvaluationMethods[k]));
    io::PlotSeries dots = makeSeries("", colors[k]);
    std::size_t j = 0;
    std::vector<double> errors;
    for (const FragmentEvaluation& e : evaluations) {
      if (!e.ok() || e.methods.size() <= k || !std::isfinite(e.methods[k].firstFrequencyError)) continue;
      const double jitter = 0.3 * (std::fmod(0.6180339887 * static_cast<double>(++j), 1.0) - 0.5);
      dots.x.push_back(static_cast<double>(k) + jitter);
      dots.y.push_back(100.0 * std::abs(e.methods[k].firstFrequencyError));
      errors.push_back(dots.y.back());
    }
    if (!errors.empty()) {
      medians.x.push_back(static_cast<double>(k));
      medians.y.push_back(median(errors));
    }
    errorSeries.push_back(std::move(dots));
  }
  errorSeries.push_back(std::move(medians));
  return io::savePng(io::plotChart(errorAxes, errorSeries), directory / "error.png");
}

}  // namespace shapedb::bench
