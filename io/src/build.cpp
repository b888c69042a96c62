// buildDatabase and addToDatabase (build.h): the catalog computed in parallel, committed in order.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <set>

#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/io/build.h>
#include <shapedb/volume/describe.h>

namespace shapedb::io {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

Status validateParameters(const BuildParameters& p) {
  if (p.entries == 0) return Error{ErrorCode::kInvalidArgument, "a database needs at least one entry"};
  if (p.families.empty()) return Error{ErrorCode::kInvalidArgument, "no family to build"};
  if (!volume::validFamilyWeights(p.families.size(), p.weights))
    return Error{ErrorCode::kInvalidArgument, "the family weights must be one per family, each from 1 to " +
                                                  std::to_string(volume::kMaxFamilyWeight)};
  if (Status st = volume::validateDescriptorOptions(p.entry.descriptor); !st) return st;
  if (p.entry.modal.modes < 1 || p.entry.modal.modes > 200)
    return Error{ErrorCode::kInvalidArgument, "modes must be in [1, 200]"};
  if (!core::validPoissonRatio(p.entry.modal.material.poissonRatio))
    return Error{ErrorCode::kInvalidArgument, "Poisson ratio must be in (-1, 0.5)"};
  return Ok{};
}

/// One catalog entry's outcome, carried from the parallel stage to the writer.
struct Computed {
  EntryRecord record;
  std::optional<volume::EntryData> data;
  std::optional<FailureRecord> failure;
};

Computed computeCatalogEntry(const volume::ShapeSpec& spec, core::EntryId id, const BuildParameters& p) {
  Computed c;
  c.record.id = id;
  c.record.name = spec.name();
  c.record.family = spec.family;
  c.record.params = spec.params;
  auto mesh = volume::makeFamilyShape(spec, p.resolution);
  auto data = mesh ? volume::computeEntry(*mesh, p.entry) : Result<volume::EntryData>(mesh.error());
  if (!data) {
    c.failure = FailureRecord{c.record.name, data.error().message};
    return c;
  }
  c.record.nodes = data->physics.tetMesh.nodeCount();
  c.record.tets = data->physics.tetMesh.tetCount();
  c.record.times = data->times;
  c.data = std::move(data).value();
  return c;
}

void addTimes(volume::StageTimes& sum, const volume::StageTimes& t) {
  sum.normalize += t.normalize;
  sum.tetrahedralize += t.tetrahedralize;
  sum.describe += t.describe;
  sum.modes += t.modes;
  sum.collision += t.collision;
}

}  // namespace

Result<BuildReport> buildDatabase(const std::filesystem::path& path, const BuildOptions& options) {
  const auto start = Clock::now();
  std::optional<Store> opened;
  if (options.resume) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      return Error{ErrorCode::kIo, path.string() + ": no database to resume (build it without --resume)"};
    auto store = Store::open(path, /*writable=*/true);
    if (!store) return store.error();
    opened.emplace(std::move(store).value());
  } else {
    if (Status st = validateParameters(options.parameters); !st) return st.error();
    auto store = Store::create(path, options.parameters);
    if (!store) return store.error();
    opened.emplace(std::move(store).value());
    if (Status st = opened->setMeta("created", utcNow()); !st) return st.error();
  }
  Store& store = *opened;
  const BuildParameters& p = store.parameters();
  if (Status st = store.setMeta("status", "building"); !st) return st.error();

  // What is left to do: catalog entries neither stored nor recorded as failed.
  auto stored = store.entries();
  if (!stored) return stored.error();
  auto failed = store.failures();
  if (!failed) return failed.error();
  std::set<std::string> done;
  for (const EntryRecord& r : *stored)
    done.insert(r.name);
  for (const FailureRecord& f : *failed)
    done.insert(f.name);
  const std::vector<volume::ShapeSpec> catalog = volume::buildCatalog(p.entries, p.families, p.weights);
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < catalog.size(); ++i)
    if (!done.count(catalog[i].name())) todo.push_back(i);

  BuildReport report;
  report.skipped = catalog.size() - todo.size();
  BuildProgress progress;
  progress.total = todo.size();
  progress.skipped = report.skipped;

  std::vector<EntryRecord> batchRecords;
  std::vector<volume::EntryData> batchData;
  std::vector<FailureRecord> batchFailures;
  std::optional<Error> writeError;
  std::atomic<bool> stop{false};
  const auto flush = [&] {
    if (writeError || (batchRecords.empty() && batchFailures.empty())) return;
    if (Status st = store.write(batchRecords, batchData, batchFailures); !st) {
      writeError = st.error();
      stop = true;
    }
    batchRecords.clear();
    batchData.clear();
    batchFailures.clear();
  };

  const int threads = options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    std::size_t next = 0;
    tbb::parallel_pipeline(
        static_cast<std::size_t>(threads) * 2,
        tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                            [&](tbb::flow_control& control) -> std::size_t {
                                              if (next >= todo.size() || stop) {
                                                control.stop();
                                                return 0;
                                              }
                                              return todo[next++];
                                            }) &
            tbb::make_filter<std::size_t, Computed>(tbb::filter_mode::parallel,
                                                    [&](std::size_t i) {
                                                      return computeCatalogEntry(
                                                          catalog[i], static_cast<core::EntryId>(i), p);
                                                    }) &
            tbb::make_filter<Computed, void>(tbb::filter_mode::serial_in_order, [&](Computed c) {
              progress.lastName = c.record.name;
              if (c.failure) {
                batchFailures.push_back(std::move(*c.failure));
                ++report.failed;
                ++progress.failed;
              } else {
                addTimes(report.stageSeconds, c.record.times);
                batchRecords.push_back(std::move(c.record));
                batchData.push_back(std::move(*c.data));
                ++report.built;
              }
              if (batchRecords.size() + batchFailures.size() >= std::max<std::size_t>(1, options.batchSize))
                flush();
              ++progress.done;
              progress.elapsedSeconds = secondsSince(start);
              if (options.progress) options.progress(progress);
            }));
  });
  flush();
  if (writeError) return *writeError;

  report.seconds = secondsSince(start);
  const double previous = std::stod(store.meta("build_seconds").value_or("0"));
  if (Status st = store.setMeta("build_seconds", std::to_string(previous + report.seconds)); !st)
    return st.error();
  if (Status st = store.setMeta("status", "complete"); !st) return st.error();
  // Best effort: a reader holding the file open keeps it in WAL mode, which is as valid.
  static_cast<void>(store.finish());
  return report;
}

Result<std::vector<core::EntryId>> addToDatabase(const std::filesystem::path& path,
                                                 std::span<const NamedMesh> meshes) {
  auto store = Store::open(path, /*writable=*/true);
  if (!store) return store.error();
  BuildParameters p = store->parameters();
  p.entry.tetgen.guarded = true;
  auto stored = store->entries();
  if (!stored) return stored.error();
  // User ids follow the catalog's and every id already taken.
  core::EntryId next = static_cast<core::EntryId>(p.entries);
  for (const EntryRecord& r : *stored)
    next = std::max(next, r.id + 1);

  std::vector<Result<volume::EntryData>> results(meshes.size(), Error{ErrorCode::kInvalidArgument, ""});
  tbb::parallel_for(std::size_t{0}, meshes.size(),
                    [&](std::size_t i) { results[i] = volume::computeEntry(meshes[i].mesh, p.entry); });
  std::vector<EntryRecord> records;
  std::vector<volume::EntryData> data;
  std::vector<core::EntryId> ids;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (!results[i]) return withContext(results[i].error(), meshes[i].source);
    EntryRecord r;
    r.id = next++;
    r.name = meshes[i].name;
    r.family = volume::Family::kUser;
    r.source = meshes[i].source;
    r.nodes = results[i]->physics.tetMesh.nodeCount();
    r.tets = results[i]->physics.tetMesh.tetCount();
    r.times = results[i]->times;
    ids.push_back(r.id);
    records.push_back(std::move(r));
    data.push_back(std::move(results[i]).value());
  }
  if (Status st = store->write(records, data); !st) return st.error();
  static_cast<void>(store->finish());  // best effort, as at the end of a build
  return ids;
}

}  // namespace shapedb::io
