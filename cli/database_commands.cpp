// shapedb build, info, add: the database file's subcommands.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <shapedb/io/database.h>
#ifdef SHAPEDB_HAVE_MPI
#include <shapedb/io/build_mpi.h>
#endif
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/describe.h>
#include <shapedb/volume/families.h>

#include "commands.h"

namespace shapedb::cli {
namespace {

std::string formatDuration(double seconds) {
  char buffer[32];
  const long s = std::lround(seconds);
  if (s >= 3600)
    std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", s / 3600, (s / 60) % 60);
  else if (s >= 60)
    std::snprintf(buffer, sizeof buffer, "%ldm%02lds", s / 60, s % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%.1fs", seconds);
  return buffer;
}

/// A progress bar with ETA on a terminal (redrawn in place on stderr), plain lines every 5 % otherwise.
class ProgressPrinter {
 public:
  ProgressPrinter() : mTerminal(::isatty(STDERR_FILENO) != 0) {}
  void operator()(const io::BuildProgress& p) {
    const double fraction = p.total ? static_cast<double>(p.done) / static_cast<double>(p.total) : 1.0;
    const double eta =
        p.done ? p.elapsedSeconds * static_cast<double>(p.total - p.done) / static_cast<double>(p.done) : 0.0;
    const double rate = p.elapsedSeconds > 0 ? static_cast<double>(p.done) / p.elapsedSeconds : 0.0;
    if (mTerminal) {
      const int width = 30, filled = static_cast<int>(fraction * width);
      std::fprintf(stderr, "\r[%s%s] %zu/%zu %5.1f%%  %.1f entries/s  ETA %s  %s   ",
                   std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(width - filled), '.').c_str(), p.done, p.total,
                   100.0 * fraction, rate, formatDuration(eta).c_str(), p.lastName.c_str());
      if (p.done == p.total) std::fprintf(stderr, "\n");
    } else {
      const int step = static_cast<int>(fraction * 20.0);
      if (step == mLastStep && p.done != p.total) return;
      mLastStep = step;
      std::fprintf(stderr, "build: %zu/%zu entries (%.0f%%), %zu failed, %.1f entries/s, ETA %s\n", p.done,
                   p.total, 100.0 * fraction, p.failed, rate, formatDuration(eta).c_str());
    }
    std::fflush(stderr);
  }

 private:
  bool mTerminal;
  int mLastStep = -1;
};

struct BuildCommandOptions {
  std::string path;
  std::size_t entries = io::BuildParameters{}.entries;
  std::string families = "all";
  int modes = 20;
  std::string elements = "quadratic";
  double wallEdgeFraction = 0.0;
  int threads = 0;
  int grid = 10;
  std::string sampling = "area";
  double poisson = 0.3;
  std::size_t batch = 16;
  std::string shard;
  bool mpi = false;
  bool resume = false;
  bool quiet = false;
};

int runBuild(const BuildCommandOptions& o, const CLI::App& app) {
  io::BuildOptions options;
  options.threads = o.threads;
  options.batchSize = o.batch;
  options.resume = o.resume;
  if (!o.shard.empty()) {
    const Result<io::Shard> shard = io::parseShard(o.shard);
    if (!shard) {
      printError("--shard: " + shard.error().message);
      return kExitUsage;
    }
    options.shard = *shard;
  }
  io::BuildParameters& p = options.parameters;
  p.entries = o.entries;
  auto mix = volume::parseFamilyMix(o.families);
  if (!mix) {
    printError("--families: " + mix.error().message);
    return kExitUsage;
  }
  p.families = std::move(mix->families);
  p.weights = std::move(mix->weights);
  const auto elements = volume::parseElementOrder(o.elements);
  if (!elements) {
    printError("--elements must be linear or quadratic, not '" + o.elements + "'");
    return kExitUsage;
  }
  p = io::withElements(p, *elements);
  if (app.count("--wall-edge-fraction")) p.entry.tetgen.wallEdgeFraction = o.wallEdgeFraction;
  p.entry.modal.modes = o.modes;
  p.entry.modal.material.poissonRatio = o.poisson;
  p.entry.descriptor.gridSize = o.grid;
  p.entry.descriptor.sampling = *core::parseSampling(o.sampling);

  if (o.resume)
    // A resumed build continues with the file's own parameters; one given here that differs is an error.
    options.checkResume = [&](const io::Store& store) -> Status {
      const io::BuildParameters& have = store.parameters();
      std::string conflict;
      const auto check = [&](const char* flag, bool differs) {
        if (app.count(flag) && differs && conflict.empty()) conflict = flag;
      };
      check("--entries", have.entries != p.entries);
      const auto evenIfNone = [](const io::BuildParameters& q) {
        return q.weights.empty() ? std::vector<unsigned>(q.families.size(), 1) : q.weights;
      };
      check("--families", have.families != p.families || evenIfNone(have) != evenIfNone(p));
      check("--modes", have.entry.modal.modes != p.entry.modal.modes);
      check("--elements", have.entry.modal.order != p.entry.modal.order);
      check("--wall-edge-fraction", have.entry.tetgen.wallEdgeFraction != p.entry.tetgen.wallEdgeFraction);
      check("--grid", have.entry.descriptor.gridSize != p.entry.descriptor.gridSize);
      check("--sampling", have.entry.descriptor.sampling != p.entry.descriptor.sampling);
      check("--poisson", have.entry.modal.material.poissonRatio != p.entry.modal.material.poissonRatio);
      const Result<io::Shard> stored = io::storedShard(store);
      check("--shard", !stored || *stored != options.shard);
      if (conflict.empty()) return Ok{};
      return Error{ErrorCode::kInvalidArgument, o.path + ": was built with another " + conflict.substr(2) +
                                                    " (its parameters: " + io::toJson(have) +
                                                    "); a resumed build keeps them"};
    };

    // With --mpi, rank 0 writes and reports; the other ranks compute and stay quiet.
#ifdef SHAPEDB_HAVE_MPI
  std::optional<io::MpiEnvironment> mpi;
  if (o.mpi) mpi.emplace();
  const bool reporting = !mpi || mpi->rank() == 0;
#else
  if (o.mpi) {
    printError("--mpi: this shapedb was built without MPI (install libopenmpi-dev, then build it again)");
    return kExitUsage;
  }
  const bool reporting = true;
#endif
  ProgressPrinter printer;
  if (!o.quiet && reporting)
    options.progress = [&printer](const io::BuildProgress& progress) { printer(progress); };
#ifdef SHAPEDB_HAVE_MPI
  auto report = mpi ? io::buildDatabaseMpi(o.path, options) : io::buildDatabase(o.path, options);
#else
  auto report = io::buildDatabase(o.path, options);
#endif
  if (!reporting) {
    if (report || report.error().code == ErrorCode::kCancelled) return kExitOk;  // rank 0 tells
    printError(report.error().message);
    return kExitInputError;
  }
  if (!report) {
    printError(report.error().message);
    return report.error().code == ErrorCode::kInvalidArgument ? kExitUsage : kExitInputError;
  }
#ifdef SHAPEDB_HAVE_MPI
  if (mpi && mpi->size() > 1)
    std::printf("%s: on %d MPI ranks (rank 0 writing, %d computing)\n", o.path.c_str(), mpi->size(),
                mpi->size() - 1);
#endif
  const volume::StageTimes& t = report->stageSeconds;
  const double built = static_cast<double>(std::max<std::size_t>(1, report->built));
  std::printf("%s: %zu entries built, %zu failed, %zu already there, in %s (%.1f entries/s)\n",
              o.path.c_str(), report->built, report->failed, report->skipped,
              formatDuration(report->seconds).c_str(),
              static_cast<double>(report->built) / std::max(1e-9, report->seconds));
  std::printf(
      "per entry: tetrahedralize %.0f ms, modes %.0f ms, collision %.0f ms, describe %.0f ms, normalize %.2f "
      "ms\n",
      1e3 * t.tetrahedralize / built, 1e3 * t.modes / built, 1e3 * t.collision / built,
      1e3 * t.describe / built, 1e3 * t.normalize / built);
  if (report->failed) std::printf("see 'shapedb info %s' for the failures\n", o.path.c_str());
  return kExitOk;
}

struct InfoOptions {
  std::string path;
  bool json = false;
  bool check = false;
};

/// `info --check`: the report as JSON.
nlohmann::json checkJson(const io::IntegrityReport& report) {
  nlohmann::json damaged = nlohmann::json::array();
  for (const io::IntegrityReport::Damage& d : report.damaged)
    damaged.push_back({{"entry_id", d.entry}, {"name", d.name}, {"part", d.part}});
  return {{"ok", report.ok()},
          {"blobs_checked", report.blobsChecked},
          {"sqlite_problems", report.sqliteProblems},
          {"damaged", damaged}};
}

/// `info --check`: the report as text, one line per problem.
void printCheck(const io::IntegrityReport& report) {
  std::printf("check: SQLite's integrity check %s; %zu blobs read, %zu damaged\n",
              report.sqliteProblems.empty() ? "passed" : "found problems", report.blobsChecked,
              report.damaged.size());
  for (const std::string& line : report.sqliteProblems)
    std::printf("  sqlite: %s\n", line.c_str());
  for (const io::IntegrityReport::Damage& d : report.damaged)
    std::printf("  damaged: %s (entry %u): %s does not match its checksum\n", d.name.c_str(), d.entry,
                d.part.c_str());
}

/// What info reports of a database file.
struct InfoSummary {
  std::string status, created;
  std::string shard;  ///< "K/N" for a shard, empty for a whole catalog
  std::size_t entries = 0;
  std::vector<io::FailureRecord> failures;
  std::map<std::string, std::size_t> perFamily;
  double meanNodes = 0.0, meanTets = 0.0;
  std::uintmax_t bytes = 0;  ///< the file and its write-ahead log
  double buildSeconds = 0.0;
  io::BuildParameters parameters;
  std::optional<io::IntegrityReport> check;  ///< with --check
};

Result<InfoSummary> summarizeDatabase(const std::string& path, bool check) {
  auto store = io::Store::open(path);
  if (!store) return store.error();
  auto entries = store->entries();
  if (!entries) return entries.error();
  auto failures = store->failures();
  if (!failures) return failures.error();
  InfoSummary s;
  if (check) {
    auto report = store->check();
    if (!report) return report.error();
    s.check = std::move(report).value();
  }
  s.entries = entries->size();
  s.failures = std::move(failures).value();
  std::size_t nodes = 0, tets = 0;
  for (const io::EntryRecord& r : *entries) {
    ++s.perFamily[volume::toString(r.family)];
    nodes += r.nodes;
    tets += r.tets;
  }
  if (s.entries > 0) {
    s.meanNodes = static_cast<double>(nodes) / static_cast<double>(s.entries);
    s.meanTets = static_cast<double>(tets) / static_cast<double>(s.entries);
  }
  std::error_code ec;
  s.bytes = std::filesystem::file_size(path, ec);
  const std::filesystem::path wal = path + "-wal";
  if (std::filesystem::exists(wal, ec)) s.bytes += std::filesystem::file_size(wal, ec);
  s.buildSeconds = std::stod(store->meta("build_seconds").value_or("0"));
  s.status = store->meta("status").value_or("unknown");
  s.created = store->meta("created").value_or("");
  s.shard = store->meta("shard").value_or("");
  s.parameters = store->parameters();
  return s;
}

double bytesPerEntry(const InfoSummary& s) {
  return s.entries ? static_cast<double>(s.bytes) / static_cast<double>(s.entries) : 0.0;
}

nlohmann::json infoJson(const std::string& path, const InfoSummary& s) {
  nlohmann::json failed = nlohmann::json::array();
  for (const io::FailureRecord& f : s.failures)
    failed.push_back({{"name", f.name}, {"message", f.message}});
  nlohmann::json out = {{"file", path},
                        {"schema_version", io::kSchemaVersion},
                        {"status", s.status},
                        {"created", s.created},
                        {"entries", s.entries},
                        {"families", s.perFamily},
                        {"failures", failed},
                        {"parameters", nlohmann::json::parse(io::toJson(s.parameters))},
                        {"size_bytes", s.bytes},
                        {"bytes_per_entry", bytesPerEntry(s)},
                        {"build_seconds", s.buildSeconds},
                        {"mean_nodes", s.meanNodes},
                        {"mean_tets", s.meanTets}};
  if (!s.shard.empty()) out["shard"] = s.shard;
  if (s.check) out["check"] = checkJson(*s.check);
  return out;
}

void printInfo(const std::string& path, const InfoSummary& s) {
  const io::BuildParameters& p = s.parameters;
  std::printf("%s: shapedb database, schema %d, %s, created %s\n", path.c_str(), io::kSchemaVersion,
              s.status.c_str(), s.created.empty() ? "?" : s.created.c_str());
  if (!s.shard.empty())
    std::printf("shard %s of its catalog (join the shards with 'shapedb merge')\n", s.shard.c_str());
  std::printf("entries: %zu", s.entries);
  for (const auto& [family, count] : s.perFamily)
    std::printf("  %s %zu", family.c_str(), count);
  std::printf("\nfailed: %zu\n", s.failures.size());
  for (std::size_t i = 0; i < s.failures.size() && i < 10; ++i)
    std::printf("  %s: %s\n", s.failures[i].name.c_str(), s.failures[i].message.c_str());
  std::printf("size on disk: %.1f MiB (%.1f KiB per entry)\n", static_cast<double>(s.bytes) / 1048576.0,
              bytesPerEntry(s) / 1024.0);
  std::printf("build time: %s\n", formatDuration(s.buildSeconds).c_str());
  std::printf("tet meshes: %.0f nodes, %.0f tets on average\n", s.meanNodes, s.meanTets);
  char wallBound[64] = "";
  if (p.entry.tetgen.wallEdgeFraction > 0.0)
    std::snprintf(wallBound, sizeof wallBound, " (edges ≤ %.3g of the wall thickness)",
                  p.entry.tetgen.wallEdgeFraction);
  // Families with a volume bound of their own, those of one bound together: "(ring, stone ≤ 0.03)".
  std::map<double, std::string> byBound;
  for (const auto& [family, fraction] : p.volumeFractions) {
    std::string& names = byBound[fraction];
    names += (names.empty() ? "" : ", ") + std::string(volume::toString(family));
  }
  std::string ownBounds;
  for (const auto& [fraction, names] : byBound) {
    char bound[32];
    std::snprintf(bound, sizeof bound, " ≤ %.3g", fraction);
    ownBounds += (ownBounds.empty() ? " (" : "; ") + names + bound;
  }
  if (!ownBounds.empty()) ownBounds += ")";
  std::printf(
      "parameters: catalog of %zu, descriptor grid %d (%s sampling), %d modes at Poisson ratio %.3g\n"
      "  on %s tets, TetGen q%.3g with tets ≤ 1/%.0f of the volume%s%s,\n"
      "  collision ≤ %d shapes, Rayleigh α %.3g β %.3g\n",
      p.entries, p.entry.descriptor.gridSize, core::toString(p.entry.descriptor.sampling),
      p.entry.modal.modes, p.entry.modal.material.poissonRatio, volume::toString(p.entry.modal.order),
      p.entry.tetgen.maxRadiusEdgeRatio,
      p.entry.tetgen.maxVolumeFraction > 0 ? 1.0 / p.entry.tetgen.maxVolumeFraction : 0.0, ownBounds.c_str(),
      wallBound, p.entry.collision.maxShapes, p.entry.damping.alpha, p.entry.damping.beta);
  if (s.check) printCheck(*s.check);
}

int runInfo(const InfoOptions& o) {
  Result<InfoSummary> summary = summarizeDatabase(o.path, o.check);
  if (!summary) {
    printError(summary.error().message);
    return kExitInputError;
  }
  if (o.json)
    std::printf("%s\n", infoJson(o.path, *summary).dump(2).c_str());
  else
    printInfo(o.path, *summary);
  // A damaged file is reported in full, then fails the command.
  return !summary->check || summary->check->ok() ? kExitOk : kExitInputError;
}

struct AddOptions {
  MeshLoadFlags load;
  std::string path;
  std::vector<std::string> meshes;
  io::AddOptions add;
};

int runAdd(const AddOptions& o) {
  std::vector<io::NamedMesh> meshes;
  for (const std::string& file : o.meshes) {
    auto loaded = loadMeshFile(file, o.load);
    if (!loaded) {
      printError(loaded.error().message);
      return kExitInputError;
    }
    const std::size_t triangles = loaded->mesh.triangleCount();
    if (o.add.maxTriangles > 0 && triangles > o.add.maxTriangles)
      std::fprintf(stderr,
                   "shapedb: note: %s: its %zu triangles are simplified to at most %zu for the tets (within "
                   "1e-3 of its size; --max-triangles 0 keeps them all)\n",
                   file.c_str(), triangles, o.add.maxTriangles);
    meshes.push_back({std::filesystem::path(file).filename().string(), file, std::move(loaded->mesh)});
  }
  // Each mesh as it is computed (a thin or large one takes minutes): what it came to and how long it took.
  io::AddOptions add = o.add;
  std::size_t done = 0;
  bool computeFailed = false;
  add.computed = [&](std::size_t i, const Result<volume::EntryData>& computed) {
    ++done;
    if (!computed) {
      computeFailed = true;
      std::fprintf(stderr, "shapedb: [%zu/%zu] %s: failed, so none will be added\n", done, meshes.size(),
                   meshes[i].source.c_str());
      return;
    }
    const volume::StageTimes& t = computed->times;
    std::fprintf(stderr,
                 "shapedb: [%zu/%zu] %s: %zu tets, %zu modes in %.1f s (TetGen %.1f s, modes %.1f s)\n", done,
                 meshes.size(), meshes[i].source.c_str(), computed->physics.tetMesh.tetCount(),
                 computed->physics.modes.modeCount(), t.total(), t.tetrahedralize, t.modes);
  };
  auto ids = io::addToDatabase(o.path, meshes, add);
  if (!ids) {
    std::string hint = flagHint(ids.error());
    // TetGen refused or crashed on a surface: the level set --repair makes of it is a clean one, which
    // meshes where this did not (a scan whose surface folds through itself, say).
    if (hint.empty() && computeFailed && !o.load.repair &&
        (ids.error().code == ErrorCode::kParse || ids.error().code == ErrorCode::kIo))
      hint =
          "; --repair remeshes the surface as the solid it encloses, which TetGen may mesh where it could "
          "not mesh this one";
    printError(ids.error().message + hint);
    return kExitInputError;
  }
  for (std::size_t i = 0; i < ids->size(); ++i)
    std::printf("%s: added as entry %u '%s'\n", meshes[i].source.c_str(), (*ids)[i], meshes[i].name.c_str());
  return kExitOk;
}

}  // namespace

Command addBuildCommand(CLI::App& parent) {
  auto o = std::make_shared<BuildCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "build",
      "Build a shape database (paper §3.1) into one SQLite file: for each shape of the families' sweeps, a\n"
      "TetGen tet mesh, mass properties, the three descriptors, the first M vibration modes (FEM on linear\n"
      "or quadratic tets, unit density and Young's modulus), a collision compound and sound data. Runs on\n"
      "all cores; commits every --batch entries, so an interrupted build loses little: continue it with\n"
      "--resume.");
  app->add_option("DB", o->path, "Database file to create (or to continue, with --resume)")->required();
  app->add_option("--entries", o->entries, "Entries in the catalog, shared out over the families by weight")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{10'000'000}));
  const auto join = [](auto families) {
    std::string names;
    for (volume::Family f : families)
      names += (names.empty() ? "" : ", ") + std::string(volume::toString(f));
    return names;
  };
  const auto all = volume::generatedFamilies(), convex = volume::convexFamilies();

  app->add_option(
         "--families", o->families,
         "Comma-separated families, each with an optional weight: its share of the entries relative to\n"
         "the others' (\"box,fragment:3\": three fragments to a box; 1 unless given). Or all: the sixteen,\n"
         "evenly. Convex (the catalog of older databases):\n" +
             join(convex) +
             ".\nWith the handles, hooks, webs, holes, cavities, limbs and lumps of real objects:\n" +
             join(all.subspan(convex.size())))
      ->capture_default_str();
  app->add_option("--modes", o->modes, "Non-rigid vibration modes per entry")
      ->capture_default_str()
      ->check(CLI::Range(1, 200));
  app->add_option(
         "--elements", o->elements,
         "Tets of the modal analysis: quadratic (10-node: no locking in bending, so the frequencies of\n"
         "thin and slender entries are right on coarse meshes, within a median 0.2 % of a mesh three\n"
         "times finer: docs/accuracy.md), or linear (the older databases: constant-strain tets on\n"
         "meshes ~6x finer, whose frequencies still come out up to 2x too high in bending; the query's\n"
         "--stretch needs them)")
      ->capture_default_str();
  app->add_option(
         "--wall-edge-fraction", o->wallEdgeFraction,
         "More tets across thin walls: where an entry is thinner than the volume bound's tets, its\n"
         "tets there get edges of at most about this fraction of the thickness (never under a third\n"
         "of the volume bound's edge). 0.7 takes the H-section beam furthest from a finer mesh from\n"
         "+14.5 % to +2.0 % at 6.6x its tets, and the default catalog from 3 to 9 minutes, its\n"
         "entries from 1.0x to 8.3x the tets, and every correction with them (docs/accuracy.md).\n"
         "0: none")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  app->add_option("--threads", o->threads, "Worker threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  app->add_option("--grid", o->grid, "Descriptor grid size N")
      ->capture_default_str()
      ->check(CLI::Range(2, core::kMaxGridSize));
  app->add_option("--sampling", o->sampling, "Descriptor sampling: area or vertices")
      ->capture_default_str()
      ->check(CLI::IsMember({"area", "vertices"}));
  app->add_option("--poisson", o->poisson, "Poisson ratio of the modal analysis, in (-1, 0.5)")
      ->capture_default_str();
  app->add_option("--batch", o->batch, "Entries per transaction")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  app->add_option(
      "--shard", o->shard,
      "Build only part K of N of the catalog (K from 0 to N-1: the entries whose index is K mod N),\n"
      "into a file of its own, as a Slurm array task or a Kubernetes indexed job would; then\n"
      "'shapedb merge' joins the N files into the database one build would have made");
  app->add_flag("--mpi", o->mpi,
                "Spread the build over MPI ranks (mpirun -np N shapedb build DB --mpi ..., or srun): rank 0\n"
                "writes DB and hands out entries one at a time, the others compute them (--threads each);\n"
                "the file is the one a single build would write. A rank that dies ends the job; --resume\n"
                "finishes it, on MPI or not. OpenMPI binds one or two ranks to a core each: give mpirun\n"
                "--bind-to none for a rank to use all the cores of its node");
  app->add_flag("--resume", o->resume, "Continue an interrupted build of DB with its own parameters");
  app->add_flag("--quiet", o->quiet, "No progress output");
  return {app, [o, app] { return runBuild(*o, *app); }};
}

Command addInfoCommand(CLI::App& parent) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* app = parent.add_subcommand(
      "info",
      "Describe a database file: entries per family, failures, build parameters, size on disk, build time.\n"
      "A file that holds a trigger, view, table or index shapedb does not create is refused (untrusted).");
  app->add_option("DB", o->path, "Database file")->required();
  app->add_flag("--json", o->json, "Print one JSON object instead of text");
  app->add_flag("--check", o->check,
                "Also check the whole file: SQLite's integrity check, and every blob against its checksum\n"
                "(a damaged entry is named; exit status 1 if anything is damaged)");
  return {app, [o] { return runInfo(*o); }};
}

struct MergeOptions {
  std::string out;
  std::vector<std::string> shards;
  bool quiet = false;
};

int runMerge(const MergeOptions& o) {
  const std::vector<std::filesystem::path> shards(o.shards.begin(), o.shards.end());
  const bool terminal = isatty(fileno(stderr)) != 0;
  const auto progress = [&](std::size_t done, std::size_t total) {
    if (!o.quiet && terminal) std::fprintf(stderr, "\rmerge: %zu/%zu entries", done, total);
  };
  const Result<io::MergeReport> report = io::mergeDatabases(o.out, shards, progress);
  if (!o.quiet && terminal) std::fprintf(stderr, "\n");
  if (!report) {
    printError(report.error().message);
    return report.error().code == ErrorCode::kInvalidArgument ? kExitUsage : kExitInputError;
  }
  std::printf("%s: %zu entries and %zu failures from %zu shards, in %s\n", o.out.c_str(), report->entries,
              report->failures, report->shards, formatDuration(report->seconds).c_str());
  return kExitOk;
}

Command addMergeCommand(CLI::App& parent) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* app = parent.add_subcommand(
      "merge",
      "Join the shards of one catalog (each built with 'build --shard K/N', all N of them, complete) into\n"
      "a new database file: the database a single build with the same parameters would have made, entry\n"
      "for entry and byte for byte. Shards of other parameters, a part given twice or missing, or an\n"
      "unfinished shard are refused. OUT appears only when whole.");
  app->add_option("OUT", o->out, "Database file to create")->required();
  app->add_option("SHARD", o->shards, "The shard files, in any order")->required();
  app->add_flag("--quiet", o->quiet, "No progress output");
  return {app, [o] { return runMerge(*o); }};
}

Command addAddCommand(CLI::App& parent) {
  auto o = std::make_shared<AddOptions>();
  CLI::App* app = parent.add_subcommand(
      "add",
      "Add closed surface meshes to a database as 'user' entries (the scenario-specific database of paper\n"
      "§7), computed with the database's own parameters; all are added or none. Each mesh's tets, modes\n"
      "and time are printed on stderr as it is computed: a large or thin-walled object takes minutes.");
  app->add_option("DB", o->path, "Database file")->required();
  app->add_option("MESH", o->meshes,
                  "Closed surface mesh files (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  app->add_option("--max-triangles", o->add.maxTriangles,
                  "A surface of more triangles is simplified to this many before it is meshed (no vertex\n"
                  "moves further than 1e-3 of its size; TetGen keeps every surface triangle, so a fine scan\n"
                  "only multiplies the tets and the seconds of their modes). 0: as given")
      ->capture_default_str();
  addMeshLoadFlags(*app, o->load);
  return {app, [o] { return runAdd(*o); }};
}

}  // namespace shapedb::cli
