// buildDatabase and addToDatabase (build.h): the catalog computed in parallel, committed in order.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <mutex>
#include <set>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/io/build.h>
#include <shapedb/volume/describe.h>
#include <shapedb/volume/simplify.h>

#include "build_session.h"
#include "codec.h"

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
  if (!volume::validStoneSubdivisions(p.resolution.stoneSubdivisions))
    return Error{ErrorCode::kInvalidArgument, "the stones' subdivisions must be " +
                                                  std::to_string(volume::kMinStoneSubdivisions) + " to " +
                                                  std::to_string(volume::kMaxStoneSubdivisions)};
  if (p.resolution.unionTrianglesPerSegment < 1)
    return Error{ErrorCode::kInvalidArgument, "the unions' triangles per segment must be at least 1"};
  for (const auto& [family, fraction] : p.volumeFractions)
    if (!validVolumeFraction(fraction))
      return Error{ErrorCode::kInvalidArgument, std::string("the volume bound of the ") +
                                                    volume::toString(family) + " family must be in (0, 1]"};
  return Ok{};
}

void addTimes(volume::StageTimes& sum, const volume::StageTimes& t) {
  sum.normalize += t.normalize;
  sum.tetrahedralize += t.tetrahedralize;
  sum.describe += t.describe;
  sum.modes += t.modes;
  sum.collision += t.collision;
}

}  // namespace

Result<Shard> parseShard(std::string_view text) {
  const std::size_t slash = text.find('/');
  const auto number = [](std::string_view digits) -> std::optional<std::size_t> {
    if (digits.empty() || digits.size() > 7) return std::nullopt;
    std::size_t value = 0;
    for (char c : digits) {
      if (c < '0' || c > '9') return std::nullopt;
      value = 10 * value + static_cast<std::size_t>(c - '0');
    }
    return value;
  };
  const auto k = slash == std::string_view::npos ? std::nullopt : number(text.substr(0, slash));
  const auto n = slash == std::string_view::npos ? std::nullopt : number(text.substr(slash + 1));
  if (!k || !n)
    return Error{ErrorCode::kInvalidArgument,
                 "shard '" + std::string(text) + "' is not K/N (say 0/4: the first of four)"};
  if (*n < 1 || *n > 1000000 || *k >= *n)
    return Error{ErrorCode::kInvalidArgument,
                 "shard '" + std::string(text) + "': N from 1 to 1,000,000 and K from 0 to N − 1"};
  return Shard{*k, *n};
}

std::string toString(const Shard& shard) {
  return std::to_string(shard.index) + "/" + std::to_string(shard.count);
}

namespace detail {

ComputedEntry computeCatalogEntry(const std::vector<volume::ShapeSpec>& catalog, std::size_t index,
                                  const BuildParameters& p) {
  const volume::ShapeSpec& spec = catalog[index];
  ComputedEntry c;
  c.record.id = static_cast<core::EntryId>(index);
  c.record.name = spec.name();
  c.record.family = spec.family;
  c.record.params = spec.params;
  auto mesh = volume::makeFamilyShape(spec, p.resolution);
  auto data = mesh ? volume::computeEntry(*mesh, entryOptionsFor(p, spec.family))
                   : Result<volume::EntryData>(mesh.error());
  if (!data) {
    c.failure = FailureRecord{c.record.name, data.error().message};
    return c;
  }
  c.record.nodes = data->physics.tetMesh.nodeCount();
  c.record.tets = data->physics.tetMesh.tetCount();
  c.record.times = data->times;
  c.data = encodeEntry(*data);
  return c;
}

namespace {

void putBytes(ByteWriter& w, const std::vector<std::uint8_t>& bytes) {
  w.put<std::uint64_t>(bytes.size());
  for (std::uint8_t b : bytes)
    w.put(b);
}

bool getBytes(ByteReader& r, std::vector<std::uint8_t>& bytes) {
  std::uint64_t size = 0;
  if (!r.get(size) || !r.has(size, 1)) return false;
  bytes.resize(size);
  for (std::uint8_t& b : bytes)
    r.get(b);
  return r.ok();
}

void putText(ByteWriter& w, const std::string& text) {
  putBytes(w, {text.begin(), text.end()});
}

bool getText(ByteReader& r, std::string& text) {
  std::vector<std::uint8_t> bytes;
  if (!getBytes(r, bytes)) return false;
  text.assign(bytes.begin(), bytes.end());
  return true;
}

}  // namespace

std::vector<std::uint8_t> toWire(const ComputedEntry& entry) {
  ByteWriter w;
  const EntryRecord& r = entry.record;
  w.put<std::uint32_t>(r.id);
  putText(w, r.name);
  w.put<std::uint8_t>(entry.data ? 1 : 0);
  if (!entry.data) {
    putText(w, entry.failure ? entry.failure->message : std::string());
    return std::move(w).take();
  }
  putText(w, volume::toString(r.family));
  for (double x : {r.params.x(), r.params.y(), r.params.z(), r.times.normalize, r.times.tetrahedralize,
                   r.times.describe, r.times.modes, r.times.collision})
    w.put(x);
  w.put<std::uint64_t>(r.nodes);
  w.put<std::uint64_t>(r.tets);
  for (const auto& blob : entry.data->descriptors)
    putBytes(w, blob);
  for (const auto& blob : entry.data->physics)
    putBytes(w, blob);
  return std::move(w).take();
}

Result<ComputedEntry> fromWire(const void* data, std::size_t size) {
  ByteReader r(data, size);
  ComputedEntry c;
  std::uint8_t computed = 0;
  const Error bad{ErrorCode::kParse, "a computed entry's bytes are truncated or garbled"};
  if (!r.get(c.record.id) || !getText(r, c.record.name) || !r.get(computed)) return bad;
  if (computed == 0) {
    std::string message;
    if (!getText(r, message) || !r.atEnd()) return bad;
    c.failure = FailureRecord{c.record.name, message};
    return c;
  }
  std::string family;
  if (!getText(r, family)) return bad;
  const auto parsed = volume::parseFamily(family);
  if (!parsed) return bad;
  c.record.family = *parsed;
  std::array<double, 8> x{};
  for (double& v : x)
    r.get(v);
  c.record.params = core::Vec3(x[0], x[1], x[2]);
  c.record.times = {x[3], x[4], x[5], x[6], x[7]};
  std::uint64_t nodes = 0, tets = 0;
  r.get(nodes);
  r.get(tets);
  c.record.nodes = nodes;
  c.record.tets = tets;
  EncodedEntry e;
  for (auto& blob : e.descriptors)
    if (!getBytes(r, blob)) return bad;
  for (auto& blob : e.physics)
    if (!getBytes(r, blob)) return bad;
  if (!r.atEnd()) return bad;
  c.data = std::move(e);
  return c;
}

struct BuildSession::State {
  BuildOptions options;
  std::optional<Store> store;
  std::vector<volume::ShapeSpec> catalog;
  std::vector<std::size_t> todo;
  Clock::time_point start;
  BuildReport report;
  BuildProgress progress;
  std::vector<EntryRecord> records;
  std::vector<EncodedEntry> data;
  std::vector<FailureRecord> failures;
  std::optional<Error> writeError;

  void flush() {
    if (writeError || (records.empty() && failures.empty())) return;
    if (Status st = store->write(records, data, failures); !st) writeError = st.error();
    records.clear();
    data.clear();
    failures.clear();
  }
};

BuildSession::BuildSession(std::unique_ptr<State> state) : mState(std::move(state)) {}
BuildSession::BuildSession(BuildSession&&) noexcept = default;
BuildSession& BuildSession::operator=(BuildSession&&) noexcept = default;
BuildSession::~BuildSession() = default;

Result<BuildSession> BuildSession::start(const std::filesystem::path& path, const BuildOptions& options) {
  auto state = std::make_unique<State>();
  state->options = options;
  state->start = Clock::now();
  std::optional<Store>& opened = state->store;
  if (options.resume) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      return Error{ErrorCode::kIo, path.string() + ": no database to resume (build it without --resume)"};
    auto store = Store::open(path, /*writable=*/true);
    if (!store) return store.error();
    opened.emplace(std::move(store).value());
    if (options.checkResume)
      if (Status st = options.checkResume(*opened); !st) return st.error();
  } else {
    if (Status st = validateParameters(options.parameters); !st) return st.error();
    if (options.shard.count == 0 || options.shard.index >= options.shard.count)
      return Error{ErrorCode::kInvalidArgument, "shard " + toString(options.shard) + ": K must be below N"};
    auto store = Store::create(path, options.parameters);
    if (!store) return store.error();
    opened.emplace(std::move(store).value());
    if (Status st = opened->setMeta("created", utcNow()); !st) return st.error();
    if (!options.shard.whole())
      if (Status st = opened->setMeta("shard", toString(options.shard)); !st) return st.error();
  }
  Store& store = *opened;
  const BuildParameters& p = store.parameters();
  const Result<Shard> shard = storedShard(store);
  if (!shard) return shard.error();
  if (options.resume && !options.shard.whole() && options.shard != *shard)
    return Error{ErrorCode::kInvalidArgument, path.string() + " holds shard " + toString(*shard) +
                                                  " of its catalog, not " + toString(options.shard)};
  if (Status st = store.setMeta("status", "building"); !st) return st.error();

  // What is left to do: entries of this file's part neither stored nor recorded as failed.
  auto stored = store.entries();
  if (!stored) return stored.error();
  auto failed = store.failures();
  if (!failed) return failed.error();
  std::set<std::string> done;
  for (const EntryRecord& r : *stored)
    done.insert(r.name);
  for (const FailureRecord& f : *failed)
    done.insert(f.name);
  state->catalog = volume::buildCatalog(p.entries, p.families, p.weights);
  std::size_t part = 0;
  for (std::size_t i = 0; i < state->catalog.size(); ++i) {
    if (!shard->holds(i)) continue;
    ++part;
    if (!done.count(state->catalog[i].name())) state->todo.push_back(i);
  }
  state->report.skipped = part - state->todo.size();
  state->progress.total = state->todo.size();
  state->progress.skipped = state->report.skipped;
  return BuildSession(std::move(state));
}

const BuildParameters& BuildSession::parameters() const {
  return mState->store->parameters();
}
const std::vector<volume::ShapeSpec>& BuildSession::catalog() const {
  return mState->catalog;
}
const std::vector<std::size_t>& BuildSession::todo() const {
  return mState->todo;
}

bool BuildSession::accept(ComputedEntry c) {
  State& s = *mState;
  s.progress.lastName = c.record.name;
  if (c.failure) {
    s.failures.push_back(std::move(*c.failure));
    ++s.report.failed;
    ++s.progress.failed;
  } else {
    addTimes(s.report.stageSeconds, c.record.times);
    s.records.push_back(std::move(c.record));
    s.data.push_back(std::move(*c.data));
    ++s.report.built;
  }
  if (s.records.size() + s.failures.size() >= std::max<std::size_t>(1, s.options.batchSize)) s.flush();
  ++s.progress.done;
  s.progress.elapsedSeconds = secondsSince(s.start);
  if (s.options.progress) s.options.progress(s.progress);
  return !s.writeError;
}

Result<BuildReport> BuildSession::finish() {
  State& s = *mState;
  s.flush();
  if (s.writeError) return *s.writeError;
  Store& store = *s.store;
  s.report.seconds = secondsSince(s.start);
  const double previous = std::stod(store.meta("build_seconds").value_or("0"));
  if (Status st = store.setMeta("build_seconds", std::to_string(previous + s.report.seconds)); !st)
    return st.error();
  if (Status st = store.setMeta("status", "complete"); !st) return st.error();
  // Best effort: a reader holding the file open keeps it in WAL mode, which is as valid.
  static_cast<void>(store.finish());
  return s.report;
}

}  // namespace detail

Result<BuildReport> buildDatabase(const std::filesystem::path& path, const BuildOptions& options) {
  Result<detail::BuildSession> started = detail::BuildSession::start(path, options);
  if (!started) return started.error();
  detail::BuildSession& session = *started;
  const std::vector<std::size_t>& todo = session.todo();
  const BuildParameters& p = session.parameters();
  // Set by the writer stage, read by the input stage: two serial stages that may run on two threads.
  std::atomic<bool> stop{false};
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
            tbb::make_filter<std::size_t, detail::ComputedEntry>(
                tbb::filter_mode::parallel,
                [&](std::size_t i) { return detail::computeCatalogEntry(session.catalog(), i, p); }) &
            tbb::make_filter<detail::ComputedEntry, void>(tbb::filter_mode::serial_in_order,
                                                          [&](detail::ComputedEntry c) {
                                                            if (!session.accept(std::move(c))) stop = true;
                                                          }));
  });
  return session.finish();
}

Result<Shard> storedShard(const Store& store) {
  const std::optional<std::string> text = store.meta("shard");
  if (!text) return Shard{};
  Result<Shard> shard = parseShard(*text);
  if (!shard)
    return Error{ErrorCode::kParse, store.path().string() + ": unreadable shard: " + shard.error().message};
  return shard;
}

namespace {

/// One shard file opened for a merge, with what the merge checks of it.
struct ShardFile {
  std::filesystem::path path;
  Store store;
  Shard shard;
  std::vector<EntryRecord> entries;
  std::vector<FailureRecord> failures;
};

/// "families [...] against [...]; modes ...": the parameters (toJson) that differ, by their top-level keys.
std::string parameterDifference(const std::string& a, const std::string& b) {
  const nlohmann::json x = nlohmann::json::parse(a), y = nlohmann::json::parse(b);
  std::string out;
  for (const auto& [key, value] : x.items())
    if (!y.contains(key) || y.at(key) != value)
      out += (out.empty() ? "" : "; ") + key + " " + value.dump() + " against " +
             (y.contains(key) ? y.at(key).dump() : std::string("none"));
  return out;
}

Result<ShardFile> openShard(const std::filesystem::path& path) {
  Result<Store> store = Store::open(path);
  if (!store) return store.error();
  const Result<Shard> shard = storedShard(*store);
  if (!shard) return shard.error();
  const std::string status = store->meta("status").value_or("unknown");
  if (status != "complete")
    return Error{ErrorCode::kInvalidArgument, path.string() + ": not completely built (status '" + status +
                                                  "'): finish it with `shapedb build " + path.string() +
                                                  " --resume` first"};
  auto entries = store->entries();
  if (!entries) return entries.error();
  auto failures = store->failures();
  if (!failures) return failures.error();
  for (const EntryRecord& r : *entries)
    if (r.id >= store->parameters().entries || !shard->holds(r.id))
      return Error{ErrorCode::kInvalidArgument,
                   path.string() + ": entry '" + r.name + "' (id " + std::to_string(r.id) +
                       ") is not of shard " + toString(*shard) +
                       " of the catalog (an entry added by hand?): only catalog shards merge"};
  return ShardFile{path, std::move(store).value(), *shard, std::move(entries).value(),
                   std::move(failures).value()};
}

}  // namespace

Result<MergeReport> mergeDatabases(const std::filesystem::path& out,
                                   std::span<const std::filesystem::path> shards,
                                   const std::function<void(std::size_t, std::size_t)>& progress) {
  const auto start = Clock::now();
  if (shards.empty()) return Error{ErrorCode::kInvalidArgument, "no shard to merge"};
  std::error_code ec;
  if (std::filesystem::exists(out, ec))
    return Error{ErrorCode::kIo, out.string() + ": exists (a merge writes a new file)"};

  // Every shard readable, complete and of the same catalog; every part there exactly once.
  std::vector<ShardFile> parts;
  for (const std::filesystem::path& path : shards) {
    Result<ShardFile> part = openShard(path);
    if (!part) return part.error();
    parts.push_back(std::move(part).value());
  }
  const ShardFile& first = parts.front();
  const std::string parameters = toJson(first.store.parameters());
  std::vector<const ShardFile*> byIndex(first.shard.count, nullptr);
  for (const ShardFile& part : parts) {
    if (const std::string theirs = toJson(part.store.parameters()); theirs != parameters)
      return Error{ErrorCode::kInvalidArgument, part.path.string() + ": built with other parameters than " +
                                                    first.path.string() + " (" +
                                                    parameterDifference(theirs, parameters) + ")"};
    if (part.shard.count != first.shard.count)
      return Error{ErrorCode::kInvalidArgument,
                   part.path.string() + " is shard " + toString(part.shard) + " but " + first.path.string() +
                       " is shard " + toString(first.shard) + ": shards of one catalog share N"};
    if (const ShardFile* other = byIndex[part.shard.index])
      return Error{ErrorCode::kInvalidArgument, other->path.string() + " and " + part.path.string() +
                                                    " are both shard " + toString(part.shard) +
                                                    ": they overlap"};
    byIndex[part.shard.index] = &part;
  }
  std::string missing;
  for (std::size_t k = 0; k < byIndex.size(); ++k)
    if (!byIndex[k]) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
  if (!missing.empty())
    return Error{ErrorCode::kInvalidArgument, "shard(s) " + missing + " of " +
                                                  std::to_string(byIndex.size()) +
                                                  " missing: a merge needs every part of the catalog"};

  // Written beside `out` and renamed onto it once whole (a stale file of an interrupted merge is ours).
  // A merge that fails removes what it wrote.
  std::filesystem::path partial = out;
  partial += ".merging";
  const auto removePartial = [&partial, &ec] {
    for (const char* suffix : {"", "-wal", "-shm", "-journal"})
      std::filesystem::remove(partial.string() + suffix, ec);
  };
  removePartial();
  MergeReport report;
  report.shards = parts.size();
  const Status written = [&]() -> Status {
    Result<Store> created = Store::create(partial, first.store.parameters());
    if (!created) return created.error();
    Store& merged = *created;
    std::size_t total = 0, done = 0;
    double buildSeconds = 0.0;
    std::vector<FailureRecord> failures;
    for (const ShardFile& part : parts) {
      total += part.entries.size();
      buildSeconds += std::stod(part.store.meta("build_seconds").value_or("0"));
      failures.insert(failures.end(), part.failures.begin(), part.failures.end());
    }
    const std::pair<const char*, std::string> meta[] = {
        {"created", utcNow()}, {"status", "merging"}, {"build_seconds", std::to_string(buildSeconds)}};
    for (const auto& [key, value] : meta)
      if (Status st = merged.setMeta(key, value); !st) return st.error();
    constexpr std::size_t kBatch = 64;
    for (const ShardFile* part : byIndex)
      for (std::size_t at = 0; at < part->entries.size(); at += kBatch) {
        const std::span<const EntryRecord> records(part->entries.data() + at,
                                                   std::min(kBatch, part->entries.size() - at));
        std::vector<EncodedEntry> blobs;
        for (const EntryRecord& r : records) {
          Result<EncodedEntry> blob = part->store.encoded(r.id);
          if (!blob) return blob.error();
          blobs.push_back(std::move(blob).value());
        }
        if (Status st = merged.write(records, blobs); !st) return st.error();
        done += records.size();
        if (progress) progress(done, total);
      }
    if (Status st = merged.write({}, std::span<const EncodedEntry>{}, failures); !st) return st.error();
    if (Status st = merged.setMeta("status", "complete"); !st) return st.error();
    static_cast<void>(merged.finish());
    report.entries = total;
    report.failures = failures.size();
    return Ok{};
  }();  // closed: a last connection's close also folds any write-ahead log into the file
  if (!written) {
    removePartial();
    return written.error();
  }
  for (const char* suffix : {"-wal", "-shm"})
    if (std::filesystem::exists(partial.string() + suffix, ec))
      return Error{ErrorCode::kIo, partial.string() + suffix + ": left over after closing; the merge is in " +
                                       partial.string()};
  std::filesystem::rename(partial, out, ec);
  if (ec)
    return Error{ErrorCode::kIo, out.string() + ": cannot rename the merged file onto it: " + ec.message()};
  report.seconds = secondsSince(start);
  return report;
}

Result<std::vector<core::EntryId>> addToDatabase(const std::filesystem::path& path,
                                                 std::span<const NamedMesh> meshes,
                                                 const AddOptions& options) {
  auto store = Store::open(path, /*writable=*/true);
  if (!store) return store.error();
  BuildParameters p = store->parameters();
  p.entry.tetgen.guarded = true;
  auto stored = store->entries();
  if (!stored) return stored.error();
  // User ids follow the catalog's and every id already taken.
  core::EntryId next = static_cast<core::EntryId>(p.entries);
  // A name already taken is refused before anything is computed (minutes, for a large object).
  std::set<std::string> names;
  for (const EntryRecord& r : *stored) {
    next = std::max(next, r.id + 1);
    names.insert(r.name);
  }
  for (const NamedMesh& m : meshes)
    if (!names.insert(m.name).second)
      return Error{ErrorCode::kInvalidArgument, m.source + ": an entry named '" + m.name +
                                                    "' is already in the database (or given twice)"};

  std::vector<Result<volume::EntryData>> results(meshes.size(), Error{ErrorCode::kInvalidArgument, ""});
  std::mutex reporting;
  tbb::parallel_for(std::size_t{0}, meshes.size(), [&](std::size_t i) {
    auto simplified = volume::surfaceForEntry(meshes[i].mesh, options.maxTriangles);
    results[i] = !simplified ? Result<volume::EntryData>(simplified.error())
                             : volume::computeEntry(*simplified ? **simplified : meshes[i].mesh, p.entry);
    if (options.computed) {
      std::lock_guard lock(reporting);
      options.computed(i, results[i]);
    }
  });
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
