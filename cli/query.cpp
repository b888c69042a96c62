// shapedb query: mesh files in, matches and adapted physical data out (paper Algorithm 1).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/error_model.h>
#include <shapedb/io/database.h>
#include <shapedb/io/enrich.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/io/render.h>
#include <shapedb/volume/families.h>

#include "commands.h"
#include "format.h"
#include "material_flags.h"

namespace shapedb::cli {
namespace {

struct QueryCommandOptions {
  MeshLoadFlags load;
  std::string database;
  std::vector<std::string> meshes;
  int k = 1;
  std::string descriptor = "centroid-voxel";
  std::string method = "pruned";
  double momentWeight = core::SearchOptions{}.momentWeight;
  MaterialFlags material;
  bool json = false;
  bool timing = false;
  bool noFidelity = false;
  bool approximate = false;
  bool stretch = false;
  bool correct = false;
  int correctCandidates = io::QueryOptions{}.correctionCandidates;
  int neighbours = io::QueryOptions{}.neighbours;
  bool table = false;
  bool enrich = false;
  double enrichAbove = 0.0;
  std::string exportDir;
  std::string png;
};

nlohmann::json matchJson(const io::MatchReport& m) {
  nlohmann::json out = {{"entry_id", m.match.entry},
                        {"name", m.entry ? m.entry->name : ""},
                        {"family", m.entry ? volume::toString(m.entry->family) : ""},
                        {"distance", m.match.distance},
                        {"moment_term", m.match.momentTerm}};
  if (m.fidelity) {
    const core::Fidelity& f = *m.fidelity;
    out["fidelity"] = {{"descriptor_distance", f.descriptorDistance},
                       {"query_moments", toJson(f.queryMoments)},
                       {"entry_moments", toJson(f.entryMoments)},
                       {"moment_error", toJson(f.momentError)},
                       {"max_moment_error", f.maxMomentError},
                       {"mean_deviation", f.meanDeviation},
                       {"max_deviation", f.maxDeviation},
                       {"samples", f.samples}};
  }
  if (m.predictedFrequencyError) out["predicted_frequency_error"] = *m.predictedFrequencyError;
  return out;
}

nlohmann::json physicsJson(const core::AdaptedPhysics& p) {
  nlohmann::json collision = nlohmann::json::array();
  for (const core::CollisionShape& s : p.collision.shapes) {
    nlohmann::json shape = {
        {"type", core::toString(s.type)}, {"center", toJson(s.center)}, {"rotation", toJson(s.rotation)}};
    if (s.type == core::CollisionShape::Type::kBox) shape["half_extents"] = toJson(s.halfExtents);
    if (s.type != core::CollisionShape::Type::kBox) shape["radius"] = s.radius;
    if (s.type == core::CollisionShape::Type::kCapsule) shape["half_length"] = s.halfLength;
    collision.push_back(std::move(shape));
  }
  const Eigen::SelfAdjointEigenSolver<core::Mat3> principal(p.massProperties.inertia, Eigen::EigenvaluesOnly);
  return {{"material",
           {{"name", p.material.name},
            {"density", p.material.density},
            {"youngs_modulus", p.material.youngsModulus},
            {"poisson_ratio", p.material.poissonRatio}}},
          {"mass", p.massProperties.mass},
          {"volume", p.massProperties.volume},
          {"center_of_mass", toJson(p.massProperties.centerOfMass)},
          {"inertia", toJson(p.massProperties.inertia)},
          {"principal_moments", toJson(principal.eigenvalues())},
          {"entry_mass", p.entryMassProperties.mass},
          {"frequencies_hz", toJson(p.frequenciesHz())},
          {"stretch", toJson(p.stretch)},
          {"damping_ratios", toJson(p.dampingRatios())},
          {"tet_nodes", p.tetMesh.nodeCount()},
          {"tets", p.tetMesh.tetCount()},
          {"collision",
           {{"shapes", collision}, {"coverage", p.collision.coverage}, {"overshoot", p.collision.overshoot}}},
          {"warnings", p.warnings}};
}

nlohmann::json correctionJson(const volume::CorrectionReport& c) {
  return {{"prestretch", toJson(c.morph.stretch)},
          {"entry_worst_quality", c.morph.entryWorstQuality},
          {"worst_quality", c.morph.worstQuality},
          {"max_boundary_move", c.morph.maxBoundaryMove},
          {"mean_boundary_move", c.morph.meanBoundaryMove},
          {"mean_target_distance", c.morph.meanTargetDistance},
          {"projected", c.morph.projected},
          {"mass_scale", c.massScale},
          {"stray_share", c.strayShare},
          {"point_mass_peak", c.pointMassPeak},
          {"lumped_mode_share", c.lumpedModeShare},
          {"mass_spread", c.massSpread},
          {"morphs", c.morphs},
          {"fallback", c.fallback},
          {"speculative", c.speculative},
          {"solves", c.solves},
          {"morph_seconds", c.morphSeconds},
          {"modes_seconds", c.modesSeconds}};
}

nlohmann::json timingJson(const io::QueryTimes& t) {
  return {{"validate", t.validate}, {"mass_properties", t.massProperties},
          {"describe", t.describe}, {"search", t.search},
          {"fetch", t.fetch},       {"correct", t.correct},
          {"adapt", t.adapt},       {"link", t.link},
          {"fidelity", t.fidelity}, {"total", t.total}};
}

std::string percent(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f%%", 100.0 * x);
  return b;
}

void printText(const std::string& file, const core::TriangleMesh& mesh, const io::QueryResult& r,
               bool timing) {
  std::printf("%s: %zu triangles, volume %.6g m³, size L = %.6g m\n", file.c_str(), mesh.triangleCount(),
              r.massProperties.volume, std::cbrt(r.massProperties.volume));
  std::printf("  %-4s %-24s %-10s %12s %12s %12s %12s\n", "rank", "entry", "family", "distance", "moment err",
              "dev. mean", "dev. max");
  for (std::size_t i = 0; i < r.matches.size(); ++i) {
    const io::MatchReport& m = r.matches[i];
    std::printf("  %-4zu %-24s %-10s %12.6g", i + 1, m.entry ? m.entry->name.c_str() : "?",
                m.entry ? volume::toString(m.entry->family) : "?", m.match.distance);
    if (m.fidelity)
      std::printf(" %12s %12s %12s", percent(m.fidelity->maxMomentError).c_str(),
                  percent(m.fidelity->meanDeviation).c_str(), percent(m.fidelity->maxDeviation).c_str());
    // The correction's fallback follows the search's matches, found by a search of its own.
    const bool fallback = r.correction && r.correction->fallback && i + 1 == r.matches.size();
    std::printf("%s\n", fallback ? "  (the correction's fallback)" : "");
  }
  if (r.physics) {
    const core::AdaptedPhysics& p = *r.physics;
    const Eigen::SelfAdjointEigenSolver<core::Mat3> principal(p.massProperties.inertia,
                                                              Eigen::EigenvaluesOnly);
    std::printf("  physics (%s: ρ %.6g kg/m³, E %.6g Pa, ν %.3g)\n", p.material.name.c_str(),
                p.material.density, p.material.youngsModulus, p.material.poissonRatio);
    std::printf("    mass %.6g kg, principal moments %s kg m²\n", p.massProperties.mass,
                toText(principal.eigenvalues()).c_str());
    std::printf("    tet mesh %zu nodes, %zu tets; collision %zu shapes (coverage %.2f, overshoot %.2f)\n",
                p.tetMesh.nodeCount(), p.tetMesh.tetCount(), p.collision.shapes.size(), p.collision.coverage,
                p.collision.overshoot);
    const Eigen::VectorXd hz = p.frequenciesHz();
    if (r.predictedFrequencyError)
      std::printf(*r.predictedFrequencyError < core::kMaxPredictedError
                      ? "    predicted first-frequency error: about %.0f %% (from %s)\n"
                      : "    predicted first-frequency error: %.0f %% or more: far off (from %s)\n",
                  100.0 * *r.predictedFrequencyError,
                  r.correction ? "the correction's morph and the fidelity report" : "the fidelity report");
    std::printf("    frequencies (Hz):");
    for (Eigen::Index i = 0; i < std::min<Eigen::Index>(hz.size(), 8); ++i)
      std::printf(" %.5g", hz[i]);
    std::printf(hz.size() > 8 ? " … (%ld modes)\n" : "\n", static_cast<long>(hz.size()));
    if (r.spectrumWeights.size() > 1) {
      std::printf("    eigenvalues blended from the spectra of the %zu nearest matches, weights",
                  r.spectrumWeights.size());
      for (double w : r.spectrumWeights)
        std::printf(" %.2f", w);
      std::printf(" (mode shapes the nearest's)\n");
    }
    if (p.stretch != core::Vec3::Ones())
      std::printf(
          "    modes of the entry stretched by %.3f, %.3f, %.3f along its axes (to the mesh's proportions)\n",
          p.stretch.x(), p.stretch.y(), p.stretch.z());
    if (r.correction) {
      if (r.correction->fallback)
        std::printf(
            "    corrected from rank %zu, a fallback: the nearest matches' morphs left much of the mesh "
            "unfilled, and this entry's (nearest by shape alone, or the nearest box) fills it (%d "
            "morphs)\n",
            r.answered + 1, r.correction->morphs);
      else if (r.correction->morphs > 1)
        std::printf("    corrected from rank %zu: of the %d best matches' morphs, the one nearest the mesh\n",
                    r.answered + 1, r.correction->morphs);
      const volume::MorphReport& m = r.correction->morph;
      std::printf(
          "    corrected: the entry's tets morphed onto the mesh (boundary moved up to %.3g L, worst tet "
          "quality "
          "%.3g, was %.3g; the mesh lies %.3g L from them on average), modes recomputed (%.1f + %.1f ms)\n",
          m.maxBoundaryMove, m.worstQuality, m.entryWorstQuality, m.meanTargetDistance,
          1e3 * r.correction->morphSeconds, 1e3 * r.correction->modesSeconds);
    }
    if (!r.link.locations.empty())
      std::printf("    linked %zu vertices, %zu outside the tets (max %.3g m)\n", r.link.locations.size(),
                  r.link.outsideCount, r.link.maxOutsideDistance);
    for (const std::string& w : p.warnings)
      std::printf("    warning: %s\n", w.c_str());
  }
  if (timing) {
    const io::QueryTimes& t = r.times;
    std::printf(
        "  timing (µs): validate %.1f, mass properties %.1f, describe %.1f (%zu orientations), search %.1f, "
        "fetch %.1f, correct %.1f, adapt %.1f, link %.1f, fidelity %.1f, total %.1f\n",
        t.validate, t.massProperties, t.describe, r.orientationCandidates, t.search, t.fetch, t.correct,
        t.adapt, t.link, t.fidelity, t.total);
  }
}

Status exportObj(const std::filesystem::path& dir, const std::string& stem, const io::QueryResult& r) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Error{ErrorCode::kIo, dir.string() + ": " + ec.message()};
  const core::AdaptedPhysics& p = *r.physics;
  const std::vector<std::pair<std::string, core::TriangleMesh>> volume{
      {"volume", core::boundarySurface(p.tetMesh)}};
  if (Status st = io::saveObjParts(volume, dir / (stem + ".volume.obj")); !st) return st;
  std::vector<std::pair<std::string, core::TriangleMesh>> parts;
  const std::vector<core::TriangleMesh> shapes = io::tessellate(p.collision);
  for (std::size_t i = 0; i < shapes.size(); ++i)
    parts.emplace_back(std::string(core::toString(p.collision.shapes[i].type)) + "_" + std::to_string(i),
                       shapes[i]);
  return io::saveObjParts(parts, dir / (stem + ".collision.obj"));
}

Status renderPng(const std::filesystem::path& path, const core::TriangleMesh& query,
                 const io::QueryResult& r) {
  const core::TriangleMesh match = core::boundarySurface(r.physics->tetMesh);
  const std::vector<io::Panel> panels{{{&query}, {{{90, 140, 200}}}}, {{&match}, {{{230, 150, 60}}}}};
  // Seen in the query's principal frame, from a three-quarter view: every query is shown the same way.
  const core::Mat3 axes = r.normalization.principalAxes;
  const core::Vec3 back = (axes * core::Vec3(0.5, 0.7, 1.0)).normalized();
  const core::Vec3 right = (axes.col(2).cross(back)).normalized();
  const core::Vec3 up = back.cross(right);
  core::Mat3 view;
  view.row(0) = right.transpose();
  view.row(1) = up.transpose();
  view.row(2) = back.transpose();
  return io::savePng(io::renderPanels(panels, view), path);
}

std::filesystem::path pngPath(const std::string& png, std::size_t index, std::size_t count) {
  const std::filesystem::path base(png);
  if (count == 1) return base;
  return base.parent_path() /
         (base.stem().string() + "-" + std::to_string(index + 1) + base.extension().string());
}

/// One line per query: the best match, its fidelity, and the adapted physics in brief.
/// The table's first column: as wide as the longest file name it will hold, and never under 24.
int tableNameWidth(const std::vector<std::string>& files, bool learning) {
  std::size_t width = 24;
  for (const std::string& file : files)
    width = std::max(width, std::filesystem::path(file).filename().string().size() + (learning ? 10 : 0));
  return static_cast<int>(width);
}

void printTableHeader(int nameWidth) {
  std::printf("%-*s %-24s %9s %9s %9s %9s %11s %10s %10s %10s\n", nameWidth, "mesh", "best match", "distance",
              "dev.mean", "mom.err", "pred.err", "mass (kg)", "f1 (Hz)", "f2 (Hz)", "f3 (Hz)");
}

/// One row: the answered match, its fidelity report, the answer's predicted first-frequency error, and
/// the adapted physics ("-" for what the query did not compute).
void printTableRow(int nameWidth, const std::string& file, const io::QueryResult& r) {
  const io::MatchReport& m = r.answeredMatch();
  std::printf("%-*s %-24s %9.4f", nameWidth, std::filesystem::path(file).filename().string().c_str(),
              m.entry ? m.entry->name.c_str() : "?", m.match.distance);
  if (m.fidelity)
    std::printf(" %9s %9s", percent(m.fidelity->meanDeviation).c_str(),
                percent(m.fidelity->maxMomentError).c_str());
  else
    std::printf(" %9s %9s", "-", "-");
  std::printf(" %9s", r.predictedFrequencyError ? percent(*r.predictedFrequencyError).c_str() : "-");
  if (r.physics) {
    const Eigen::VectorXd hz = r.physics->frequenciesHz();
    std::printf(" %11.4g", r.physics->massProperties.mass);
    for (Eigen::Index i = 0; i < 3; ++i)
      if (i < hz.size())
        std::printf(" %10.1f", hz[i]);
      else
        std::printf(" %10s", "-");
  }
  std::printf("\n");
}

/// A query's answer as JSON: its matches, and the physics and correction of the best one.
nlohmann::json answerJson(const io::QueryResult& r) {
  nlohmann::json q = {{"matches", nlohmann::json::array()}, {"timing_us", timingJson(r.times)}};
  for (const io::MatchReport& m : r.matches)
    q["matches"].push_back(matchJson(m));
  if (!r.matches.empty() && r.answeredMatch().fidelity)
    q["fidelity"] = matchJson(r.answeredMatch())["fidelity"];
  if (!r.matches.empty()) q["answered"] = r.answered;
  if (r.physics) {
    q["physics"] = physicsJson(*r.physics);
    q["physics"]["spectrum_weights"] = r.spectrumWeights;
  }
  if (r.correction) q["correction"] = correctionJson(*r.correction);
  if (r.predictedFrequencyError) q["predicted_frequency_error"] = *r.predictedFrequencyError;
  q["link"] = {{"vertices", r.link.locations.size()},
               {"outside", r.link.outsideCount},
               {"max_outside_distance", r.link.maxOutsideDistance}};
  return q;
}

nlohmann::json queryJson(const std::string& file, const io::LoadedMesh& loaded,
                         const core::TriangleMesh& mesh, const std::optional<volume::RepairReport>& repaired,
                         const io::QueryResult& r, const std::string& descriptor) {
  nlohmann::json q = {{"file", file},
                      {"triangles", mesh.triangleCount()},
                      {"scale", loaded.scale},
                      {"flipped_inside_out", loaded.flippedInsideOut},
                      {"welded_vertices", loaded.verticesWelded},
                      {"specks_dropped", loaded.specksDropped},
                      {"approximate", r.massProperties.isApproximate},
                      {"volume", r.massProperties.volume},
                      {"size", std::cbrt(r.massProperties.volume)},
                      {"descriptor", descriptor}};
  if (repaired)
    q["repaired"] = {{"resolution", repaired->resolution},
                     {"voxel_size", repaired->voxelSize},
                     {"holes", repaired->holes},
                     {"closing_radius", repaired->closingRadius},
                     {"volume_before", repaired->volumeBefore ? nlohmann::json(*repaired->volumeBefore)
                                                              : nlohmann::json(nullptr)},
                     {"volume_after", repaired->volumeAfter},
                     {"area_before", repaired->areaBefore},
                     {"area_after", repaired->areaAfter}};
  q.update(answerJson(r));
  return q;
}

/// What query adds to a refusal of a surface that bounds no solid: the flag that answers it anyway.
std::string approximateHint(const Error& error) {
  if (boundsNoSolid(error)) return "; --approximate answers it from vertex point masses (marked approximate)";
  return "";
}

/// A query's file as read, its mesh moved out into the batch that queryMany answers.
struct LoadedFile {
  std::size_t index = 0;  ///< among the command's files
  std::string file;
  io::LoadedMesh loaded;
  std::optional<volume::RepairReport> repaired;
};

/// A mesh handed to the enricher by query --enrich: answered again once it is learned.
struct PendingLearn {
  std::string file;
  core::TriangleMesh mesh;
  std::size_t jsonIndex = 0;
  std::shared_future<Result<io::Learned>> learned;
};

/// query --enrich's second half: waits for each mesh to be learned, queries it again and prints both.
int answerAgain(const QueryCommandOptions& o, int nameWidth, const io::Database& db,
                const io::QueryOptions& options, std::vector<PendingLearn>& pending,
                nlohmann::json& queries) {
  int status = kExitOk;
  for (PendingLearn& p : pending) {
    const Result<io::Learned>& learned = p.learned.get();
    if (!learned) {
      printError(p.file + ": not learned: " + learned.error().message);
      status = kExitInputError;
      continue;
    }
    auto again = db.query(p.mesh, options);
    if (!again) {
      printError(p.file + ": " + again.error().message);
      status = kExitInputError;
      continue;
    }
    if (o.json) {
      nlohmann::json& q = queries[p.jsonIndex];
      q["learned"] = {{"entry_id", learned->id},
                      {"name", learned->name},
                      {"computed", learned->computed},
                      {"seconds", learned->seconds}};
      q["after_learning"] = answerJson(*again);
    } else if (o.table) {
      printTableRow(nameWidth, p.file + " (learned)", *again);
    } else {
      if (learned->computed)
        std::printf("%s: learned as entry %u '%s' in %.1f s; queried again:\n", p.file.c_str(), learned->id,
                    learned->name.c_str(), learned->seconds);
      else
        std::printf("%s: learned before, entry %u '%s'; queried again:\n", p.file.c_str(), learned->id,
                    learned->name.c_str());
      printText(p.file, p.mesh, *again, o.timing);
    }
  }
  return status;
}

io::QueryOptions queryOptionsOf(const QueryCommandOptions& o) {
  io::QueryOptions options;
  options.descriptor = *core::parseDescriptorKind(o.descriptor);
  options.search.k = o.k;
  options.search.method = o.method == "brute-force" ? core::SearchMethod::kBruteForce
                          : o.method == "buckets"   ? core::SearchMethod::kBuckets
                                                    : core::SearchMethod::kPruned;
  options.search.momentWeight = o.momentWeight;
  options.fidelity = !o.noFidelity;
  options.approximate = o.approximate;
  options.stretchCorrection = o.stretch;
  options.correct = o.correct;
  options.correctionCandidates = o.correctCandidates;
  options.neighbours = o.neighbours;
  return options;
}

/// The files from `next` on, loaded a batch at a time: up to 256 files or 4 million triangles, so that a
/// folder of large scans is never in memory all at once. A file that cannot be read is reported and
/// skipped (status: kExitInputError). batch[b]'s mesh is meshes[b] (moved out of its LoadedMesh).
void loadBatch(const QueryCommandOptions& o, std::size_t& next, std::vector<LoadedFile>& batch,
               std::vector<core::TriangleMesh>& meshes, int& status) {
  constexpr std::size_t kBatchFiles = 256, kBatchTriangles = 4'000'000;
  // Files are read up to kLoadTogether at a time, side by side (TBB), and taken in their order: their
  // warnings and errors are printed as one after another would print them. A group holds files of up to
  // kLoadTogetherBytes on disk in all (a large scan is read alone, as before, in the memory it needs);
  // the triangle budget is checked between groups, so a batch may pass it by a group's small files.
  constexpr std::size_t kLoadTogether = 16;
  constexpr std::uintmax_t kLoadTogetherBytes = 64u << 20;
  struct Loading {
    std::optional<Result<io::LoadedMesh>> mesh;
    std::optional<volume::RepairReport> repaired;
    std::vector<std::string> messages;
  };
  std::size_t triangles = 0;
  while (next < o.meshes.size() && batch.size() < kBatchFiles && triangles < kBatchTriangles) {
    const std::size_t most = std::min({kLoadTogether, o.meshes.size() - next, kBatchFiles - batch.size()});
    std::size_t count = 0;
    for (std::uintmax_t bytes = 0; count < most; ++count) {
      std::error_code unknown;  // a file that cannot be sized counts as empty; reading it says why
      const std::uintmax_t size = std::filesystem::file_size(o.meshes[next + count], unknown);
      bytes += unknown ? 0 : size;
      if (count > 0 && bytes > kLoadTogetherBytes) break;
    }
    std::vector<Loading> group(count);
    tbb::parallel_for(std::size_t{0}, count, [&](std::size_t i) {
      group[i].mesh = loadMeshFile(o.meshes[next + i], o.load, &group[i].repaired, group[i].messages);
    });
    for (std::size_t i = 0; i < count; ++i, ++next) {
      for (const std::string& m : group[i].messages)
        std::fprintf(stderr, "%s\n", m.c_str());
      Result<io::LoadedMesh>& loaded = *group[i].mesh;
      if (!loaded) {
        printError(loaded.error().message + flagHint(loaded.error()));
        status = kExitInputError;
        continue;
      }
      LoadedFile f{next, o.meshes[next], {}, group[i].repaired};
      triangles += loaded->mesh.triangleCount();
      meshes.push_back(std::move(loaded->mesh));
      f.loaded = std::move(loaded).value();
      batch.push_back(std::move(f));
    }
  }
}

/// With --enrich: the mesh handed to the enricher, unless its answer is predicted to be good enough
/// already (--enrich-above) or there is no solid to learn (an approximate answer's open surface cannot
/// be tetrahedralized).
void submitToLearn(const QueryCommandOptions& o, io::Enricher& enricher, const LoadedFile& f,
                   const core::TriangleMesh& mesh, const io::QueryResult& r, std::size_t jsonIndex,
                   std::vector<PendingLearn>& pending) {
  if (r.massProperties.isApproximate) {
    std::fprintf(stderr, "shapedb: %s: not learned: it bounds no solid (answered approximately)\n",
                 f.file.c_str());
    return;
  }
  if (o.enrichAbove > 0.0 && r.predictedFrequencyError && *r.predictedFrequencyError <= o.enrichAbove) {
    if (!o.json)
      std::fprintf(stderr, "shapedb: %s: not learned: predicted error %.1f %% is within --enrich-above\n",
                   f.file.c_str(), 100.0 * *r.predictedFrequencyError);
    return;
  }
  pending.push_back({f.file, mesh, jsonIndex,
                     enricher.submit({std::filesystem::path(f.file).filename().string(), f.file, mesh})});
}

/// One answer out: the files beside it (--export-obj, --png), then JSON, a table row or text.
Status reportAnswer(const QueryCommandOptions& o, int nameWidth, const LoadedFile& f,
                    const core::TriangleMesh& mesh, const io::QueryResult& r, nlohmann::json& queries) {
  if (!o.exportDir.empty())
    if (Status st = exportObj(o.exportDir, std::filesystem::path(f.file).stem().string(), r); !st) return st;
  if (!o.png.empty())
    if (Status st = renderPng(pngPath(o.png, f.index, o.meshes.size()), mesh, r); !st) return st;
  if (o.json)
    queries.push_back(queryJson(f.file, f.loaded, mesh, f.repaired, r, o.descriptor));
  else if (o.table)
    printTableRow(nameWidth, f.file, r);
  else
    printText(f.file, mesh, r, o.timing);
  return Ok{};
}

int runQuery(const QueryCommandOptions& o, const CLI::App& app) {
  io::QueryOptions options = queryOptionsOf(o);
  const std::optional<core::Material> material = resolveMaterial(o.material, app);
  if (!material) return kExitUsage;
  options.material = *material;

  io::Database::OpenOptions open;
  open.learn = o.enrich;
  open.descriptors = {options.descriptor};  // the one index it searches: a third of the reading
  auto db = io::Database::open(o.database, open);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }
  std::optional<io::Enricher> enricher;
  if (o.enrich) {
    io::EnricherOptions enrich;
    enrich.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    enricher.emplace(*db, enrich);
  }
  std::vector<PendingLearn> pending;
  nlohmann::json queries = nlohmann::json::array();
  int status = kExitOk;
  // The table's name column, worked out once: it reads every file name given.
  const int nameWidth = o.table ? tableNameWidth(o.meshes, o.enrich) : 0;
  if (o.table && !o.json) printTableHeader(nameWidth);
  // A batch at a time, its queries spread over the cores (Database::queryMany), printed in the order given.
  for (std::size_t next = 0; next < o.meshes.size();) {
    std::vector<LoadedFile> batch;
    std::vector<core::TriangleMesh> meshes;
    loadBatch(o, next, batch, meshes, status);
    const std::vector<Result<io::QueryResult>> results = db->queryMany(meshes, options);
    for (std::size_t b = 0; b < batch.size(); ++b) {
      if (!results[b]) {
        const Error& e = results[b].error();
        printError(batch[b].file + ": " + e.message + approximateHint(e) + flagHint(e));
        status = kExitInputError;
        continue;
      }
      if (enricher) submitToLearn(o, *enricher, batch[b], meshes[b], *results[b], queries.size(), pending);
      if (Status st = reportAnswer(o, nameWidth, batch[b], meshes[b], *results[b], queries); !st) {
        printError(st.error().message);
        return kExitInputError;
      }
    }
  }
  if (enricher)
    if (answerAgain(o, nameWidth, *db, options, pending, queries) != kExitOk) status = kExitInputError;
  if (o.json)
    std::printf("%s\n", nlohmann::json{{"database", o.database}, {"queries", queries}}.dump(2).c_str());
  return status;
}

}  // namespace

Command addQueryCommand(CLI::App& parent) {
  auto o = std::make_shared<QueryCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "query",
      "Find the database entries most similar to each mesh and give the mesh the best one's physical data\n"
      "(paper Algorithm 1): the entry's tet mesh, modes, collision compound and mass properties carried to\n"
      "the mesh's frame and size and scaled to a material; the mesh's vertices linked to the tets; and a\n"
      "fidelity report per match asked for (principal moments and surface deviation against the mesh, "
      "relative).\n"
      "Meshes must be closed and consistently oriented. Many meshes (the fragments of a fracture, say) are\n"
      "answered together, spread over the machine's cores, and printed in the order given. Exit status 1\n"
      "if any mesh failed.");
  app->add_option("DB", o->database, "Database file (shapedb build)")->required();
  app->add_option("MESH", o->meshes, "Query surface meshes (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  addMeshLoadFlags(*app, o->load);
  app->add_option("-k,--k", o->k,
                  "Matches to report, best first (the search finds at least --neighbours of them, and\n"
                  "--correct-candidates with --correct)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app->add_option("--descriptor", o->descriptor, "Descriptor to match by")
      ->capture_default_str()
      ->check(CLI::IsMember({"moment", "voxel", "centroid-voxel"}));
  app->add_option("--method", o->method,
                  "Search: pruned (exact, fast), brute-force (the oracle), buckets (the paper's heuristic)")
      ->capture_default_str()
      ->check(CLI::IsMember({"pruned", "brute-force", "buckets"}));
  app->add_option("--moment-weight", o->momentWeight,
                  "Voxel descriptors: rank by the grid's distance (eq. 5 or 6) plus this weight times\n"
                  "sum |ln(m/m')| of the principal moments, so that the match has the mesh's shape and its\n"
                  "proportions too; 0 for the paper's distance alone")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  addMaterialFlags(*app, o->material);
  app->add_flag(
      "--json", o->json,
      "Print one JSON object: {database, queries: [{file, matches: [{entry_id, name, family, distance,\n"
      "moment_term, fidelity}], fidelity, physics: {mass, inertia, frequencies_hz, ...}, link, timing_us}]}");
  app->add_option("--export-obj", o->exportDir,
                  "Write <mesh>.volume.obj (the adapted tets' surface) and <mesh>.collision.obj into DIR");
  app->add_option("--png", o->png, "Draw each query beside its match (several meshes: FILE-1.png, ...)");
  app->add_flag("--timing", o->timing, "Print the time of each stage (text output; JSON always has it)");
  app->add_flag("--table", o->table,
                "One line per mesh: best match, fidelity (mean surface deviation, largest moment error),\n"
                "predicted first-frequency error, mass, first three frequencies");
  app->add_flag("--no-fidelity", o->noFidelity, "Skip the fidelity report (it fetches every match's tets)");
  app->add_flag("--approximate", o->approximate,
                "Answer an open or non-manifold surface (a scan with holes) too: its mass properties from\n"
                "vertex point masses (a shell's inertia), the answer marked approximate; --repair closes\n"
                "small holes instead, for exact mass properties");
  app->add_flag("--stretch", o->stretch,
                "Take the frequencies and modes from the entry stretched along its axes to the mesh's\n"
                "proportions (second moments), by Rayleigh-Ritz on its modes, instead of scaling it\n"
                "uniformly as the paper does (~1 ms more per query; databases of linear tets only;\n"
                "docs/architecture.md)");
  app->add_option(
         "--neighbours", o->neighbours,
         "Uncorrected answers: blend the eigenvalues from the spectra of this many nearest\n"
         "matches, weighted by 1/distance (a weighted geometric mean per mode, matches over twice\n"
         "the nearest's distance left out; the mode shapes, tets and collision stay the nearest's).\n"
         "The catalog samples shapes on a grid and a mesh falls between its entries: on the\n"
         "benchmark three took the median first-frequency error on plate fragments from 5.9 % to\n"
         "3.0 % (docs/accuracy.md). The mesh's own shape (its learned entry) answers alone. 1: the\n"
         "nearest entry's own spectrum, as the paper has it")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  CLI::Option* correct =
      app->add_flag(
             "--correct", o->correct,
             "Geometry correction: morph the best entries' tets onto the mesh's own surface (see\n"
             "--correct-candidates), and compute the modes again on the morph that reaches the surface\n"
             "best, so that the data have the mesh's proportions and thin parts, not the entry's (tens to\n"
             "hundreds of ms per query; where no morph keeps every tet positive, the best entry's own data\n"
             "stand, with a warning). JSON gains \"correction\": the morph's quality and cost, and\n"
             "\"answered\": the rank (from 0) of the match whose data the answer carries")
          ->excludes(app->get_option("--stretch"));
  app->add_option("--correct-candidates", o->correctCandidates,
                  "With --correct: how many of the best matches are morphed to choose from (the search\n"
                  "finds at least as many; each costs one morph, a fraction of the modes' cost)")
      ->capture_default_str()
      ->check(CLI::Range(1, io::kMaxCorrectionCandidates))
      ->needs(correct);
  app->add_flag("--enrich", o->enrich,
                "Learn each mesh too: compute its exact data in the background (the database's own\n"
                "pipeline, seconds a mesh, on all cores), add them to DB as a 'learned' entry (DB must be\n"
                "writable; a mesh learned before is not computed again), then query the mesh again and\n"
                "report both answers. JSON gains \"learned\" and \"after_learning\" per mesh");
  app->add_option("--enrich-above", o->enrichAbove,
                  "With --enrich: learn only the meshes whose answer's predicted first-frequency error\n"
                  "(predicted_frequency_error: from the fidelity report, and with --correct from the\n"
                  "correction's morph too) is above this fraction; 0: all")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0))
      ->needs(app->get_option("--enrich"));
  return {app, [o, app] { return runQuery(*o, *app); }};
}

}  // namespace shapedb::cli
