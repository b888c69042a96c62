#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <list>
#include <mutex>
#include <set>
#include <unordered_map>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/io/database.h>
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
  const std::vector<volume::ShapeSpec> catalog = volume::buildCatalog(p.entries, p.families);
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

namespace {

/// What the cache keeps per entry: its physical data, the locator built on its tets, and the stretch
/// basis of its modes, computed by the first query that wants it.
struct CachedEntry {
  core::PhysicalData data;
  core::TetLocator locator;
  const core::StretchBasis& stretchBasis() const {
    std::call_once(stretchOnce, [&] { stretch = core::computeStretchBasis(data.tetMesh, data.modes); });
    return stretch;
  }

 private:
  mutable std::once_flag stretchOnce;
  mutable core::StretchBasis stretch;
};

using Describers = std::array<std::unique_ptr<volume::Describer>, 3>;

double microsecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

}  // namespace

struct Database::Impl {
  explicit Impl(Store s) : store(std::move(s)) {}
  Result<std::shared_ptr<const CachedEntry>> cachedEntry(core::EntryId id);
  volume::Describer& describer(core::DescriptorKind kind);

  Store store;
  /// One Describer per thread and kind: describing reuses its grid's memory instead of allocating.
  tbb::enumerable_thread_specific<Describers> describers;
  std::vector<EntryRecord> entries;
  std::unordered_map<core::EntryId, std::size_t> byId;
  std::array<std::optional<core::Index>, 3> indexes;
  std::size_t cacheCapacity = 64;
  mutable std::mutex cacheMutex;
  mutable std::list<std::pair<core::EntryId, std::shared_ptr<const CachedEntry>>> lru;  // front: newest
  mutable std::unordered_map<core::EntryId, decltype(lru)::iterator> cached;
  mutable std::size_t hits = 0, misses = 0;
};

Database::Database(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
Database::Database(Database&&) noexcept = default;
Database& Database::operator=(Database&&) noexcept = default;
Database::~Database() = default;

Result<Database> Database::open(const std::filesystem::path& path, const OpenOptions& options) {
  auto store = Store::open(path);
  if (!store) return store.error();
  const BuildParameters& p = store->parameters();
  if (options.expectDescriptor) {
    const core::DescriptorOptions& want = *options.expectDescriptor;
    const core::DescriptorOptions& have = p.entry.descriptor;
    if (want.gridSize != have.gridSize || want.sampling != have.sampling)
      return Error{ErrorCode::kInvalidArgument,
                   path.string() + ": built with descriptor grid " + std::to_string(have.gridSize) + " and " +
                       core::toString(have.sampling) + " sampling, not grid " +
                       std::to_string(want.gridSize) + " and " + core::toString(want.sampling) + " sampling"};
  }
  auto impl = std::make_unique<Impl>(std::move(store).value());
  impl->cacheCapacity = std::max<std::size_t>(1, options.cacheEntries);
  auto entries = impl->store.entries();
  if (!entries) return entries.error();
  impl->entries = std::move(entries).value();
  for (std::size_t i = 0; i < impl->entries.size(); ++i)
    impl->byId.emplace(impl->entries[i].id, i);
  for (core::DescriptorKind kind :
       {core::DescriptorKind::kMoment, core::DescriptorKind::kVoxel, core::DescriptorKind::kCentroidVoxel}) {
    core::DescriptorOptions o = impl->store.parameters().entry.descriptor;
    o.kind = kind;
    core::IndexBuilder builder(o);
    auto descriptors = impl->store.descriptors(kind);
    if (!descriptors) return descriptors.error();
    for (const auto& [id, d] : *descriptors)
      if (Status st = builder.add(id, d); !st)
        return withContext(st.error(), path.string() + ": entry " + std::to_string(id));
    auto index = std::move(builder).build();
    if (!index) return withContext(index.error(), path.string());
    impl->indexes[static_cast<std::size_t>(kind)].emplace(std::move(index).value());
  }
  return Database(std::move(impl));
}

const BuildParameters& Database::parameters() const {
  return mImpl->store.parameters();
}
bool Database::supportsStretchCorrection() const {
  return parameters().entry.modal.order == volume::ElementOrder::kLinear;
}
const std::vector<EntryRecord>& Database::entries() const {
  return mImpl->entries;
}
const EntryRecord* Database::entry(core::EntryId id) const {
  const auto it = mImpl->byId.find(id);
  return it == mImpl->byId.end() ? nullptr : &mImpl->entries[it->second];
}
const core::Index& Database::index(core::DescriptorKind kind) const {
  return *mImpl->indexes[static_cast<std::size_t>(kind)];
}

volume::Describer& Database::Impl::describer(core::DescriptorKind kind) {
  std::unique_ptr<volume::Describer>& slot = describers.local()[static_cast<std::size_t>(kind)];
  if (!slot) {
    core::DescriptorOptions o = store.parameters().entry.descriptor;
    o.kind = kind;
    slot = std::make_unique<volume::Describer>(o);
  }
  return *slot;
}

Result<std::shared_ptr<const CachedEntry>> Database::Impl::cachedEntry(core::EntryId id) {
  {
    std::lock_guard lock(cacheMutex);
    if (const auto it = cached.find(id); it != cached.end()) {
      lru.splice(lru.begin(), lru, it->second);
      ++hits;
      return it->second->second;
    }
    ++misses;
  }
  // Read outside the lock: two threads missing the same entry both read it, and the first insert wins.
  auto data = store.physics(id);
  if (!data) return data.error();
  auto entry = std::make_shared<CachedEntry>();
  entry->data = std::move(data).value();
  entry->locator = core::TetLocator(entry->data.tetMesh);
  std::lock_guard lock(cacheMutex);
  if (const auto it = cached.find(id); it != cached.end()) return it->second->second;
  lru.emplace_front(id, std::move(entry));
  cached[id] = lru.begin();
  std::shared_ptr<const CachedEntry> result = lru.front().second;
  while (lru.size() > cacheCapacity) {
    cached.erase(lru.back().first);
    lru.pop_back();
  }
  return result;
}

Result<std::vector<core::Match>> Database::match(const core::TriangleMesh& mesh, core::DescriptorKind kind,
                                                 const core::SearchOptions& search) const {
  QueryOptions options;
  options.descriptor = kind;
  options.search = search;
  options.adapt = false;
  options.fidelity = false;
  auto result = query(mesh, options);
  if (!result) return result.error();
  std::vector<core::Match> matches;
  for (const MatchReport& m : result->matches)
    matches.push_back(m.match);
  return matches;
}

Result<QueryResult> Database::query(const core::TriangleMesh& mesh, const QueryOptions& options) const {
  const Clock::time_point start = Clock::now();
  QueryResult out;
  if (options.adapt)
    if (Status valid = core::validateMaterial(options.material); !valid) return valid.error();
  if (options.adapt && options.stretchCorrection && options.correct)
    return Error{ErrorCode::kInvalidArgument,
                 "the stretch correction and the geometry correction exclude each other: the geometry "
                 "correction gives the entry the query's whole shape, proportions included"};
  if (options.adapt && options.stretchCorrection && !supportsStretchCorrection())
    return Error{ErrorCode::kInvalidArgument,
                 "the stretch correction needs a database of linear tets; " + mImpl->store.path().string() +
                     " has quadratic ones (its stretch basis would need their mid-edge values)"};

  Clock::time_point t = Clock::now();
  if (Status valid = core::validateMesh(mesh); !valid) return valid.error();
  const core::TopologyReport topology = core::analyzeTopology(mesh);
  out.times.validate = microsecondsSince(t);

  t = Clock::now();
  auto mass = core::computeMassProperties(mesh, topology);
  if (!mass) return mass.error();
  out.massProperties = *mass;
  auto normalization = core::normalize(mesh, *mass);
  if (!normalization) return normalization.error();
  out.normalization = *normalization;
  out.times.massProperties = microsecondsSince(t);

  t = Clock::now();
  auto candidates =
      mImpl->describer(options.descriptor).describeCandidates(mesh, out.normalization, options.orientation);
  if (!candidates) return candidates.error();
  out.orientationCandidates = candidates->size();
  out.times.describe = microsecondsSince(t);

  t = Clock::now();
  auto matches = index(options.descriptor).search(*candidates, options.search);
  if (!matches) return matches.error();
  out.times.search = microsecondsSince(t);
  for (const core::Match& m : *matches)
    out.matches.push_back({m, entry(m.entry), std::nullopt});
  if (out.matches.empty() || (!options.adapt && !options.fidelity)) {
    out.times.total = microsecondsSince(start);
    return out;
  }

  t = Clock::now();
  std::vector<std::shared_ptr<const CachedEntry>> entries;
  const std::size_t fetchCount = options.fidelity ? out.matches.size() : 1;
  for (std::size_t i = 0; i < fetchCount; ++i) {
    auto e = mImpl->cachedEntry(out.matches[i].match.entry);
    if (!e) return e.error();
    entries.push_back(std::move(e).value());
  }
  out.times.fetch = microsecondsSince(t);
  const CachedEntry& best = *entries.front();
  out.entryPhysics = std::shared_ptr<const core::PhysicalData>(entries.front(), &best.data);

  if (options.adapt) {
    // The geometry correction first, in the entry's canonical frame: the query's surface carried there,
    // the entry's tets morphed onto it and their modes computed again.
    const core::Placement placement =
        core::placementOf(out.normalization, out.matches.front().match.orientation);
    std::optional<volume::CorrectedEntry> corrected;
    std::optional<core::TetLocator> correctedLocator;
    std::string correctionWarning;
    if (options.correct) {
      t = Clock::now();
      core::TriangleMesh target = mesh;
      for (core::Vec3& p : target.vertices)
        p = placement.toEntry(p);
      // The modes are computed again anyway: with the material's own Poisson ratio (validated above).
      volume::ModalOptions modal = parameters().entry.modal;
      modal.material.poissonRatio = options.material.poissonRatio;
      auto c = volume::correctGeometry(best.data, target, modal, options.correction);
      if (c) {
        out.correction = c->report;
        corrected = std::move(c).value();
        correctedLocator.emplace(corrected->physics.tetMesh);
      } else {
        correctionWarning =
            "geometry correction not applied (the entry's own data stand): " + c.error().message;
      }
      out.times.correct = microsecondsSince(t);
    }
    const core::PhysicalData& data = corrected ? corrected->physics : best.data;
    const core::TetLocator& locator = corrected ? *correctedLocator : best.locator;

    t = Clock::now();
    auto adapted = core::adapt(
        data, out.normalization, out.massProperties, out.matches.front().match.orientation, options.material,
        parameters().entry.damping, options.stretchCorrection ? &best.stretchBasis() : nullptr);
    if (!adapted) return adapted.error();
    out.physics = std::move(adapted).value();
    if (!correctionWarning.empty()) out.physics->warnings.push_back(correctionWarning);
    out.times.adapt = microsecondsSince(t);
    if (options.link) {
      t = Clock::now();
      out.link = core::linkSurface(locator, out.physics->placement, mesh.vertices);
      out.times.link = microsecondsSince(t);
    }
  }

  if (options.fidelity) {
    t = Clock::now();
    const core::ClosestPointTree queryTree(mesh);
    for (std::size_t i = 0; i < out.matches.size(); ++i) {
      MatchReport& m = out.matches[i];
      const core::Placement placement = core::placementOf(out.normalization, m.match.orientation);
      m.fidelity = core::assessFidelity(mesh, queryTree, out.normalization, entries[i]->locator,
                                        entries[i]->data.massProperties, placement,
                                        m.match.distance - m.match.momentTerm, options.fidelityOptions);
    }
    out.times.fidelity = microsecondsSince(t);
  }
  out.times.total = microsecondsSince(start);
  return out;
}

Result<std::shared_ptr<const core::PhysicalData>> Database::physics(core::EntryId id) const {
  auto e = mImpl->cachedEntry(id);
  if (!e) return e.error();
  return std::shared_ptr<const core::PhysicalData>(*e, &(*e)->data);
}

Result<std::shared_ptr<const core::TetLocator>> Database::locator(core::EntryId id) const {
  auto e = mImpl->cachedEntry(id);
  if (!e) return e.error();
  return std::shared_ptr<const core::TetLocator>(*e, &(*e)->locator);
}

std::array<std::size_t, 2> Database::cacheStats() const {
  std::lock_guard lock(mImpl->cacheMutex);
  return {mImpl->hits, mImpl->misses};
}

}  // namespace shapedb::io
