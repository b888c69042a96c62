// shapedb bench: the physical-fidelity benchmark. Every shape (a directory of meshes, or the fragments of
// a fracture) is queried with each descriptor and its data computed directly; the errors of the
// retrieved data and of two inertia-equivalent baselines go to a CSV, a Markdown summary and two plots.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include <shapedb/bench/evaluation.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/modal.h>

#include "commands.h"
#include "material_flags.h"

namespace shapedb::cli {
namespace {

struct BenchCommandOptions {
  MeshLoadFlags load;
  std::string database;
  std::string queries;
  std::string fractureMesh;
  volume::FractureOptions fracture;
  std::string out;
  MaterialFlags material;
  std::string directElements = "quadratic";
  bool noWarmUp = false;
  bench::EvaluationOptions evaluation;
};

Result<std::vector<io::NamedMesh>> loadShapes(const BenchCommandOptions& o) {
  std::vector<io::NamedMesh> shapes;
  if (!o.queries.empty()) {
    Result<std::vector<std::filesystem::path>> files = io::listMeshFiles(o.queries);
    if (!files) return files.error();
    for (const std::filesystem::path& file : *files) {
      Result<io::LoadedMesh> loaded = loadMeshFile(file, o.load);
      if (!loaded) return loaded.error();  // names the file
      shapes.push_back({file.stem().string(), file.string(), std::move(loaded->mesh)});
    }
    return shapes;
  }
  Result<volume::FractureResult> pieces = fractureMeshFile(o.fractureMesh, o.load, o.fracture);
  if (!pieces) return pieces.error();
  for (std::size_t i = 0; i < pieces->fragments.size(); ++i)
    shapes.push_back({volume::fragmentName(i), o.fractureMesh, std::move(pieces->fragments[i])});
  return shapes;
}

int runBench(BenchCommandOptions& o, const CLI::App& app) {
  const std::optional<core::Material> material = resolveMaterial(o.material, app);
  if (!material) return kExitUsage;
  o.evaluation.material = *material;
  if (o.queries.empty() == o.fractureMesh.empty()) {
    printError("give --queries DIR or --fracture MESH --pieces N, not both");
    return kExitUsage;
  }
  const std::optional<volume::ElementOrder> directElements = volume::parseElementOrder(o.directElements);
  if (!directElements) {
    printError("--direct-elements must be linear or quadratic, not '" + o.directElements + "'");
    return kExitUsage;
  }
  o.evaluation.directElements = *directElements;
  auto db = io::Database::open(o.database);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }
  Result<std::vector<io::NamedMesh>> shapes = loadShapes(o);
  if (!shapes) {
    printError(shapes.error().message);
    return kExitInputError;
  }
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) {
    printError(o.out + ": " + ec.message());
    return kExitInputError;
  }

  // The warm-up's instance: a cache of its own, so that the timed queries find no entry fetched or planned.
  std::optional<io::Database> warmUp;
  if (!o.noWarmUp) {
    Result<io::Database> opened = io::Database::open(o.database);
    if (!opened) {
      printError(opened.error().message);
      return kExitInputError;
    }
    warmUp.emplace(std::move(opened).value());
    o.evaluation.warmUp = &*warmUp;
  }

  const auto start = std::chrono::steady_clock::now();
  std::fprintf(stderr, "bench: %zu shapes: %seach shape's queries, then the direct computations...\n",
               shapes->size(), o.noWarmUp ? "" : "a warm-up round, then ");
  o.evaluation.progress = [start](std::size_t done, std::size_t total, const std::string& name) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "bench: %zu/%zu direct computations done (%s), %.0f s\n", done, total, name.c_str(),
                 seconds);
  };
  Result<std::vector<bench::FragmentEvaluation>> evaluations =
      bench::evaluateShapes(*db, *shapes, o.evaluation);
  if (!evaluations) {
    printError(evaluations.error().message);
    return kExitUsage;
  }

  const std::filesystem::path out(o.out);
  const std::string source = o.queries.empty()
                                 ? o.fractureMesh + " broken into " + std::to_string(shapes->size()) +
                                       " fragments (seed " + std::to_string(o.fracture.seed) +
                                       ", --max-triangles " + std::to_string(o.fracture.maxTriangles) + ")"
                                 : o.queries;
  char refinement[32];
  std::snprintf(refinement, sizeof refinement, "%g", o.evaluation.truthRefinement);
  const std::string title =
      "shapedb bench: " + source + ", against " + o.database + " (" + std::to_string(db->entries().size()) +
      " entries, " + volume::toString(db->parameters().entry.modal.order) + " tets), " + material->name +
      "; truth and baselines on " + volume::toString(o.evaluation.directElements) +
      " tets, the truth's with a TetGen volume bound " + refinement +
      std::string("x smaller than the entries'") +
      (o.evaluation.correctionCandidates == io::QueryOptions{}.correctionCandidates
           ? std::string()
           : "; the correction morphs " + std::to_string(o.evaluation.correctionCandidates) + " candidates") +
      (o.noWarmUp ? "; queries timed in a cold process (--no-warm-up)" : "");
  for (Status st : {bench::writeEvaluationCsv(*evaluations, out / "evaluation.csv"),
                    bench::writeEvaluationSummary(*evaluations, title, out / "summary.md"),
                    bench::writeEvaluationPlots(*evaluations, out)})
    if (!st) {
      printError(st.error().message);
      return kExitInputError;
    }
  std::ifstream summary(out / "summary.md");
  std::printf("%s", std::string(std::istreambuf_iterator<char>(summary), {}).c_str());
  std::size_t failed = 0;
  for (const bench::FragmentEvaluation& e : *evaluations)
    failed += !e.ok();
  std::fprintf(stderr, "bench: wrote %s/{evaluation.csv, summary.md, time.png, error.png}\n", o.out.c_str());
  return failed == evaluations->size() ? kExitInputError : kExitOk;
}

}  // namespace

Command addBenchCommand(CLI::App& parent) {
  auto o = std::make_shared<BenchCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "bench",
      "The physical-fidelity benchmark: how wrong is the retrieved data? Each shape (the meshes of\n"
      "--queries DIR, or the fragments of --fracture MESH) is queried with each of the three descriptors,\n"
      "and its physical data are also computed directly (TetGen, FEM, modes: the database's own pipeline\n"
      "and parameters, on quadratic tets meshed finer than the entries: the truth), which takes seconds\n"
      "per shape. Reported per shape and method (the three descriptors, the paper's distance alone, the\n"
      "geometry correction): the relative error\n"
      "of the first non-rigid frequencies, the volume IoU of the collision proxy with the shape, the query\n"
      "time and its speedup over the direct computation; beside two baselines, the solid ellipsoid and box\n"
      "with the shape's mass and principal moments. The queries are timed one at a time, after a round of\n"
      "them all, untimed, on another instance of the database (its own cache): a warm process, whose\n"
      "first shapes do not pay for its start, and entries that the timed instance has not yet fetched or\n"
      "planned a correction for. Writes evaluation.csv, summary.md (printed too), time.png and error.png in\n"
      "--out. Exit status 1 if no shape could be evaluated.");
  app->add_option("DB", o->database, "Database file (from shapedb build)")->required();
  CLI::Option* queries = app->add_option(
      "--queries", o->queries,
      "Directory of closed meshes (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae) to evaluate");
  addFractureSourceFlags(
      *app, o->fractureMesh, o->fracture,
      "Instead of --queries: break this closed mesh into fragments (as shapedb fracture) and evaluate them")
      ->excludes(queries);
  addMeshLoadFlags(*app, o->load);
  app->add_option("--out", o->out, "Directory for the results (created)")->required();
  addMaterialFlags(*app, o->material);
  app->add_option("--frequencies", o->evaluation.frequencies, "Non-rigid frequencies compared per shape")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app->add_option("--overlap-resolution", o->evaluation.overlapResolution,
                  "Sampling grid of the collision-proxy IoU, cells along the longest side")
      ->capture_default_str()
      ->check(CLI::Range(8, 512));
  app->add_option("--direct-elements", o->directElements,
                  "Tets of the direct computations (truth and baselines): quadratic or linear (linear ones\n"
                  "lock in bending and ring high: a poor truth)")
      ->capture_default_str();
  app->add_option("--truth-refinement", o->evaluation.truthRefinement,
                  "The truth's TetGen volume bound is the entries' divided by this")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
  app->add_option("--truth-max-triangles", o->evaluation.truthMaxTriangles,
                  "Shapes of more triangles are simplified to about this many for their truth only (a\n"
                  "quadratic solve on the tets of a 100k-triangle scan does not fit in memory)")
      ->capture_default_str()
      ->check(CLI::Range(100, 1000000));
  app->add_option("--correct-candidates", o->evaluation.correctionCandidates,
                  "The corrected method's candidates: how many of the best matches are morphed to choose\n"
                  "from (as query --correct-candidates)")
      ->capture_default_str()
      ->check(CLI::Range(1, io::kMaxCorrectionCandidates));
  app->add_flag(
      "--no-warm-up", o->noWarmUp,
      "Time the queries without the warm-up round: the first shapes then pay for the process's start\n"
      "(its heap, threads and libraries)");
  app->add_option("--threads", o->evaluation.threads, "Threads for the direct computations (0: all cores)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  return {app, [o, app] { return runBench(*o, *app); }};
}

}  // namespace shapedb::cli
