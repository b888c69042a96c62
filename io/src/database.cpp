#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <list>
#include <mutex>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <shapedb/core/error_model.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/io/database.h>
#include <shapedb/volume/describe.h>

namespace shapedb::io {
namespace {

using Clock = std::chrono::steady_clock;

/// What the cache keeps per entry: its physical data, the locator built on its tets, and the stretch
/// basis of its modes, computed by the first query that wants it.
struct CachedEntry {
  core::PhysicalData data;
  core::TetLocator locator;
  /// What the geometry corrections with the entry share, kept by the first for the next ones: the layout
  /// of its tets' morph, and the symbolic analysis of their K − σM.
  mutable volume::MorphPlan morphPlan;
  mutable volume::ModalPlan modalPlan;
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

/// How many entries' eigenvalues a Database keeps for QueryOptions::neighbours beyond its entry cache
/// (about 10 MB of them).
constexpr std::size_t kSpectraKept = 1 << 16;

/// The entries nearest by shape alone that a correction's fallback morphs (QueryOptions::correctionFallback).
constexpr std::size_t kShapeFallbacks = 3;

/// An entry the correction may turn to beyond the search's matches (QueryOptions::correctionFallback):
/// its match against the query and its data.
struct Fallback {
  core::Match match;
  std::shared_ptr<const CachedEntry> entry;
};

/// The geometry correction of a query: the corrected data and the index of the match they are of (or the
/// fallback whose they are), or why there are none.
struct Correction {
  std::optional<volume::CorrectedEntry> corrected;
  std::size_t answered = 0;
  std::optional<Fallback> fallback;  ///< set when the fallback answered
  std::string error;                 ///< the first failure's, when nothing was corrected
};

/// Morphs of a correction, by index, each set once its task has ended.
using Morphs = std::vector<std::optional<Result<volume::MorphedEntry>>>;

/// The morph a correction answers with among those of `morphs` that are `done` and did not fail (and,
/// with `warningFree`, draw no volume::correctionWarnings: the fallback's rule): the best by
/// volume::betterMorph, the better rank among equals.
std::optional<std::size_t> bestMorph(const Morphs& morphs, std::span<const char> done,
                                     bool warningFree = false) {
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < morphs.size(); ++i)
    if (done[i] && *morphs[i] && (!warningFree || volume::correctionWarnings((*morphs[i])->report).empty()) &&
        (!best || volume::betterMorph((*morphs[i])->report, (*morphs[*best])->report)))
      best = i;
  return best;
}

/// The chosen morph's correction: its missing mass placed (and the time that took), then its modes.
struct Corrected {
  Result<volume::CorrectedEntry> entry;
  double placingSeconds = 0.0;
};

/// Runs `morph(i)` for every i < count at once, one task each, with a guess on a core that would otherwise
/// wait: once all but one have ended and the last is running on another thread, `pick(done)` names the
/// morph whose correction would answer were the last not to change the choice (none: no guess), `copy(k)`
/// copies it (both under the race's lock), and `guess(k, copy, cancel)` computes that correction on this
/// thread. Once all have ended, `conclude` is called once: where `pick` over all of them names the guessed
/// morph again, with the guess's correction, after the guess has ended; else with none, at once, on the
/// last morph's thread, the guess (if any) cancelled through `cancel`.
template <class Morph, class Pick, class Copy, class Guess, class Conclude>
void morphAtOnce(std::size_t count, const Morph& morph, const Pick& pick, const Copy& copy,
                 const Guess& guess, const Conclude& conclude) {
  if (count == 0) return conclude(std::optional<Corrected>());
  std::mutex progress;  // guards all that follows but the cancel flag and the guess's correction
  std::vector<char> done(count, 0);
  std::size_t started = 0, ended = 0;
  std::optional<std::size_t> guessed;
  bool stands = false;
  std::atomic<bool> cancel{false};
  std::optional<Corrected> correction;  // the guess's, written by its task alone
  tbb::task_group group;
  for (std::size_t i = 0; i < count; ++i)
    group.run([&, i] {
      {
        const std::lock_guard lock(progress);
        ++started;
      }
      morph(i);
      std::optional<volume::MorphedEntry> taken;
      bool last = false;
      {
        const std::lock_guard lock(progress);
        done[i] = 1;
        last = ++ended == count;
        if (last && guessed) {
          stands = pick(std::span<const char>(done)) == guessed;
          if (!stands) cancel = true;
        } else if (!last && ended + 1 == count && started == count) {
          // The one morph left is running on another thread.
          guessed = pick(std::span<const char>(done));
          if (guessed) taken = copy(*guessed);
        }
      }
      if (taken) correction = guess(*guessed, std::move(*taken), &cancel);
      if (last && !stands) conclude(std::optional<Corrected>());
    });
  group.wait();
  if (stands) conclude(std::move(correction));
}

/// Morphs the entries of `q`'s first `candidates` matches (`entries`, in match order) onto `mesh`, each
/// carried into its entry's canonical frame, and computes the modes of the morph that reaches `mesh`'s
/// surface best (the smallest mean target distance; the first of equals) among those whose tets do not
/// stray across a gap of it (volume::kStrayShareWarning), if any do not. Candidates whose morph fails
/// are passed over. Where the chosen morph leaves much of `mesh` unfilled (volume::kMassScaleWarning),
/// `fallback` (if given) is asked for more entries: the best of their morphs that draw no warning answers
/// instead.
///
/// The morphs run at once, each its own task, the fallback's after the candidates'. A core that has
/// finished its morph while the last one is still running on another would wait for it; it computes the
/// modes of what would answer if the last did not change the choice instead (morphAtOnce), on the guess
/// that it will not (the last is one of three or four, as a rule). Where it does, the guess is cancelled
/// and the modes computed for the morph chosen, as without the guess. The answer is the same either way,
/// to the bit: the guess's modes are kept only where they are the chosen morph's.
Correction correctAmongCandidates(const core::TriangleMesh& mesh, const QueryResult& q,
                                  std::span<const std::shared_ptr<const CachedEntry>> entries,
                                  std::size_t candidates, const volume::ModalOptions& modal,
                                  const volume::CorrectionOptions& options,
                                  const std::function<std::vector<Fallback>()>& fallback) {
  Correction out;
  // The query's surface in its canonical frame, prepared once (its closest-point tree, side test, moments):
  // each candidate sees it through its own orientation, which carries that frame into the entry's.
  const Clock::time_point start = Clock::now();
  core::TriangleMesh canonical = mesh;
  const core::Placement unoriented = core::placementOf(q.normalization, core::Mat3::Identity());
  for (core::Vec3& p : canonical.vertices)
    p = unoriented.toEntry(p);
  auto target = volume::MorphTarget::prepare(std::move(canonical));
  if (!target) {
    out.error = target.error().message;
    return out;
  }
  double morphSeconds = 1e-6 * microsecondsSince(start);

  const auto correct = [&](volume::MorphedEntry morphed, const CachedEntry& entry,
                           const core::Mat3& orientation, const std::atomic<bool>* cancel) {
    const Clock::time_point placing = Clock::now();
    volume::placeMissingMass(morphed, volume::MorphTarget::View(*target, orientation));
    const double placed = 1e-6 * microsecondsSince(placing);
    volume::ModalOptions solve = modal;
    solve.cancel = cancel;
    solve.plan = &entry.modalPlan;
    return Corrected{volume::correctMorphed(entry.data, std::move(morphed), solve), placed};
  };
  const auto morphInto = [&](Morphs& into, const CachedEntry& entry, const core::Mat3& orientation,
                             std::size_t i) {
    volume::CorrectionOptions morph = options;
    morph.morph.plan = &entry.morphPlan;
    into[i] = volume::morphEntry(entry.data, volume::MorphTarget::View(*target, orientation), morph,
                                 volume::MissingMass::kDeferred);
  };
  const auto sendsToFallback = [&](const volume::MorphedEntry& m) {
    return fallback && m.report.massScale > volume::kMassScaleWarning;
  };

  Morphs morphs(candidates);
  std::optional<Corrected> c;  // the answer's correction
  std::size_t fallbacksMorphed = 0;
  bool guessed = false;

  // The fallback entries' morphs at once, after the candidates' best, `chosen`, left the query unfilled:
  // the best of those that draw no warning answers instead, if any does.
  const auto correctWithFallback = [&](volume::MorphedEntry chosen) {
    std::vector<Fallback> more = fallback();
    fallbacksMorphed = more.size();
    Morphs extra(more.size());
    const std::size_t theCandidate = more.size();
    const auto pick = [&](std::span<const char> done) -> std::optional<std::size_t> {
      return bestMorph(extra, done, /*warningFree=*/true).value_or(theCandidate);
    };
    const auto entryOf = [&](std::size_t k) -> const CachedEntry& {
      return k == theCandidate ? *entries[out.answered] : *more[k].entry;
    };
    const auto orientationOf = [&](std::size_t k) -> const core::Mat3& {
      return k == theCandidate ? q.matches[out.answered].match.orientation : more[k].match.orientation;
    };
    morphAtOnce(
        more.size(), [&](std::size_t i) { morphInto(extra, entryOf(i), orientationOf(i), i); }, pick,
        [&](std::size_t k) { return k == theCandidate ? chosen : (*extra[k]).value(); },
        [&](std::size_t k, volume::MorphedEntry m, const std::atomic<bool>* cancel) {
          return correct(std::move(m), entryOf(k), orientationOf(k), cancel);
        },
        [&](std::optional<Corrected> guess) {
          for (const auto& m : extra)
            if (*m) morphSeconds += (*m)->report.morphSeconds;
          const std::vector<char> all(extra.size(), 1);
          const std::size_t k = *pick(all);       // never empty: the candidate at least
          const CachedEntry& entry = entryOf(k);  // kept alive by out.fallback's entry below
          const core::Mat3 orientation = orientationOf(k);
          if (k != theCandidate) {
            chosen = std::move(*extra[k]).value();
            out.fallback = std::move(more[k]);
          }
          guessed = guess.has_value();
          c = guess ? std::move(guess) : correct(std::move(chosen), entry, orientation, nullptr);
        });
  };

  morphAtOnce(
      candidates, [&](std::size_t i) { morphInto(morphs, *entries[i], q.matches[i].match.orientation, i); },
      // No guess where the best so far, if it stays the best, sends the correction to its fallback.
      [&](std::span<const char> done) -> std::optional<std::size_t> {
        const std::optional<std::size_t> best = bestMorph(morphs, done);
        return best && !sendsToFallback((*morphs[*best]).value()) ? best : std::nullopt;
      },
      [&](std::size_t k) { return (*morphs[k]).value(); },
      [&](std::size_t k, volume::MorphedEntry m, const std::atomic<bool>* cancel) {
        return correct(std::move(m), *entries[k], q.matches[k].match.orientation, cancel);
      },
      [&](std::optional<Corrected> guess) {
        for (std::size_t i = 0; i < candidates; ++i) {
          const Result<volume::MorphedEntry>& m = *morphs[i];
          if (m)
            morphSeconds += m->report.morphSeconds;
          else if (out.error.empty())
            out.error = m.error().message;
        }
        const std::vector<char> all(candidates, 1);
        const std::optional<std::size_t> best = bestMorph(morphs, all);
        if (!best) return;
        out.answered = *best;
        if (guess) {
          guessed = true;
          c = std::move(guess);
          return;
        }
        volume::MorphedEntry chosen = std::move(*morphs[*best]).value();
        if (sendsToFallback(chosen))
          correctWithFallback(std::move(chosen));
        else
          c = correct(std::move(chosen), *entries[*best], q.matches[*best].match.orientation, nullptr);
      });

  if (!c) return out;
  if (!c->entry) {
    out.error = c->entry.error().message;
    out.answered = 0;
    out.fallback.reset();
    return out;
  }
  out.corrected = std::move(c->entry).value();
  volume::CorrectionReport& report = out.corrected->report;
  report.morphs = static_cast<int>(candidates + fallbacksMorphed);
  report.fallback = out.fallback.has_value();
  report.morphSeconds = morphSeconds + c->placingSeconds;
  report.speculative = guessed;
  return out;
}

}  // namespace

/// The writing connection of a Database opened to learn. Left, it leaves the file in rollback-journal
/// mode again, as a build does (best effort: another connection may still hold it in WAL mode).
struct LearningWriter {
  explicit LearningWriter(Store s) : store(std::move(s)) {}
  LearningWriter(const LearningWriter&) = delete;
  LearningWriter& operator=(const LearningWriter&) = delete;
  ~LearningWriter() { static_cast<void>(store.finish()); }
  Store store;
};

struct Database::Impl {
  Impl(std::unique_ptr<LearningWriter> w, Store s) : writer(std::move(w)), store(std::move(s)) {}
  Result<std::shared_ptr<const CachedEntry>> cachedEntry(core::EntryId id);
  /// An entry's eigenvalues: from its cached data if the cache holds them (without counting a hit or
  /// refreshing it), else from the file's modes alone, kept in `spectra`.
  Result<std::shared_ptr<const Eigen::VectorXd>> spectrum(core::EntryId id);
  volume::Describer& describer(core::DescriptorKind kind);

  // Before the reading connection: closed after it, so that it can leave the file's WAL mode.
  std::unique_ptr<LearningWriter> writer;  ///< with OpenOptions::learn
  Store store;
  /// One Describer per thread and kind: describing reuses its grid's memory instead of allocating.
  tbb::enumerable_thread_specific<Describers> describers;
  std::vector<EntryRecord> entries;  ///< the file's when opened; never changes
  std::unordered_map<core::EntryId, std::size_t> byId;
  std::unordered_map<std::string_view, std::size_t> byName;
  std::vector<core::EntryId> boxes;  ///< the box entries' ids, ascending: the correction's fallback
  std::array<std::unique_ptr<core::LiveIndex>, 3> indexes;

  // Learned entries: records at stable addresses (a deque only grows at its end), found by id and name
  // under learnedMutex, which is held for lookups and insertions only, never while the file is written.
  std::mutex learnMutex;  ///< one learn() at a time
  mutable std::mutex learnedMutex;
  std::deque<EntryRecord> learned;
  std::unordered_map<core::EntryId, const EntryRecord*> learnedById;
  std::unordered_map<std::string, const EntryRecord*> learnedByName;
  core::EntryId nextId = 0;  ///< the next learned entry's (under learnMutex)
  std::size_t cacheCapacity = 64;
  mutable std::mutex cacheMutex;
  mutable std::list<std::pair<core::EntryId, std::shared_ptr<const CachedEntry>>> lru;  // front: newest
  mutable std::unordered_map<core::EntryId, decltype(lru)::iterator> cached;
  mutable std::size_t hits = 0, misses = 0;
  /// Eigenvalues read for QueryOptions::neighbours: 20 numbers an entry, dropped all at once past
  /// kSpectraKept entries.
  std::mutex spectraMutex;
  std::unordered_map<core::EntryId, std::shared_ptr<const Eigen::VectorXd>> spectra;
};

Database::Database(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
Database::Database(Database&&) noexcept = default;
Database& Database::operator=(Database&&) noexcept = default;
Database::~Database() = default;

Result<Database> Database::open(const std::filesystem::path& path, const OpenOptions& options) {
  // The writer first: it puts the file in WAL mode, in which the reader then reads beside its writes.
  std::unique_ptr<LearningWriter> writer;
  if (options.learn) {
    auto w = Store::open(path, /*writable=*/true);
    if (!w) return w.error();
    writer = std::make_unique<LearningWriter>(std::move(w).value());
  }
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
  auto impl = std::make_unique<Impl>(std::move(writer), std::move(store).value());
  impl->cacheCapacity = std::max<std::size_t>(1, options.cacheEntries);
  auto entries = impl->store.entries();
  if (!entries) return entries.error();
  impl->entries = std::move(entries).value();
  // Learned ids follow the catalog's and every id already taken, as user entries' do (addToDatabase).
  impl->nextId = static_cast<core::EntryId>(impl->store.parameters().entries);
  for (std::size_t i = 0; i < impl->entries.size(); ++i) {
    const EntryRecord& e = impl->entries[i];
    impl->byId.emplace(e.id, i);
    impl->byName.emplace(e.name, i);
    impl->nextId = std::max(impl->nextId, e.id + 1);
    if (e.family == volume::Family::kBox) impl->boxes.push_back(e.id);
  }
  std::sort(impl->boxes.begin(), impl->boxes.end());
  if (options.descriptors.empty())
    return Error{ErrorCode::kInvalidArgument, path.string() + ": no descriptor kind to index"};
  for (core::DescriptorKind kind : options.descriptors) {
    if (impl->indexes[static_cast<std::size_t>(kind)]) continue;  // named twice
    core::DescriptorOptions o = impl->store.parameters().entry.descriptor;
    o.kind = kind;
    core::IndexBuilder builder(o);
    builder.reserve(impl->entries.size());
    const Status read =
        impl->store.forEachDescriptor(kind, [&](core::EntryId id, const core::Descriptor& d) -> Status {
          if (Status st = builder.add(id, d); !st)
            return withContext(st.error(), path.string() + ": entry " + std::to_string(id));
          return Ok{};
        });
    if (!read) return read.error();
    auto index = std::move(builder).build();
    if (!index) return withContext(index.error(), path.string());
    impl->indexes[static_cast<std::size_t>(kind)] =
        std::make_unique<core::LiveIndex>(std::move(index).value());
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
std::vector<EntryRecord> Database::learnedEntries() const {
  std::lock_guard lock(mImpl->learnedMutex);
  return {mImpl->learned.begin(), mImpl->learned.end()};
}
std::size_t Database::size() const {
  std::lock_guard lock(mImpl->learnedMutex);
  return mImpl->entries.size() + mImpl->learned.size();
}
const EntryRecord* Database::entry(core::EntryId id) const {
  if (const auto it = mImpl->byId.find(id); it != mImpl->byId.end()) return &mImpl->entries[it->second];
  std::lock_guard lock(mImpl->learnedMutex);
  const auto it = mImpl->learnedById.find(id);
  return it == mImpl->learnedById.end() ? nullptr : it->second;
}
const EntryRecord* Database::entry(std::string_view name) const {
  if (const auto it = mImpl->byName.find(name); it != mImpl->byName.end()) return &mImpl->entries[it->second];
  std::lock_guard lock(mImpl->learnedMutex);
  const auto it = mImpl->learnedByName.find(std::string(name));
  return it == mImpl->learnedByName.end() ? nullptr : it->second;
}
bool Database::hasIndex(core::DescriptorKind kind) const {
  return mImpl->indexes[static_cast<std::size_t>(kind)] != nullptr;
}
const core::LiveIndex& Database::index(core::DescriptorKind kind) const {
  return *mImpl->indexes[static_cast<std::size_t>(kind)];
}

Result<core::EntryId> Database::learn(const std::string& name, const std::string& source,
                                      const volume::EntryData& data) {
  Impl& s = *mImpl;
  if (!s.writer)
    return Error{
        ErrorCode::kInvalidArgument,
        s.store.path().string() + ": opened for reading only; open it with OpenOptions::learn to learn"};
  std::lock_guard lock(s.learnMutex);
  if (entry(name) != nullptr)
    return Error{ErrorCode::kInvalidArgument,
                 s.store.path().string() + ": already holds an entry '" + name + "'"};
  const core::EntryId id = s.nextId;
  EntryRecord r;
  r.id = id;
  r.name = name;
  r.family = volume::Family::kLearned;
  r.source = source;
  r.nodes = data.physics.tetMesh.nodeCount();
  r.tets = data.physics.tetMesh.tetCount();
  r.times = data.times;
  if (Status st = s.writer->store.write(std::span<const EntryRecord>(&r, 1),
                                        std::span<const volume::EntryData>(&data, 1));
      !st)
    return st.error();
  ++s.nextId;
  {
    std::lock_guard published(s.learnedMutex);
    const EntryRecord& stored = s.learned.emplace_back(std::move(r));
    s.learnedById.emplace(stored.id, &stored);
    s.learnedByName.emplace(stored.name, &stored);
  }
  // The record first, then the descriptors: a search that finds the entry finds its record too.
  for (std::size_t k = 0; k < s.indexes.size(); ++k) {
    if (!s.indexes[k]) continue;  // not opened: the file has its descriptors for another open
    const std::pair<core::EntryId, core::Descriptor> added(id, data.descriptors[k]);
    if (Status st = s.indexes[k]->add(std::span(&added, 1)); !st)
      return withContext(st.error(), s.store.path().string() + ": learned entry '" + name +
                                         "' (written to the file, not searchable until it is opened again)");
  }
  return id;
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

Result<std::shared_ptr<const Eigen::VectorXd>> Database::Impl::spectrum(core::EntryId id) {
  {
    std::lock_guard lock(cacheMutex);
    if (const auto it = cached.find(id); it != cached.end()) {
      const std::shared_ptr<const CachedEntry>& e = it->second->second;
      return std::shared_ptr<const Eigen::VectorXd>(e, &e->data.modes.eigenvalues);
    }
  }
  {
    std::lock_guard lock(spectraMutex);
    if (const auto it = spectra.find(id); it != spectra.end()) return it->second;
  }
  auto read = store.eigenvalues(id);
  if (!read) return read.error();
  auto eigenvalues = std::make_shared<const Eigen::VectorXd>(std::move(read).value());
  std::lock_guard lock(spectraMutex);
  if (spectra.size() >= kSpectraKept) spectra.clear();
  return spectra.try_emplace(id, std::move(eigenvalues)).first->second;
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

namespace {

/// Whether a match's entry is one the catalog generated (a single solid without cavities), not a user's or
/// a learned one.
bool generatedEntry(const MatchReport& match) {
  return match.entry && match.entry->family != volume::Family::kUser &&
         match.entry->family != volume::Family::kLearned;
}

}  // namespace

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
  if (options.adapt && (options.neighbours < 1 || options.neighbours > 100))
    return Error{ErrorCode::kInvalidArgument,
                 "the neighbours whose spectra are blended must be 1 to 100, not " +
                     std::to_string(options.neighbours)};
  const bool correcting = options.adapt && options.correct;
  if (correcting &&
      (options.correctionCandidates < 1 || options.correctionCandidates > kMaxCorrectionCandidates))
    return Error{ErrorCode::kInvalidArgument, "the geometry correction's candidates must be 1 to " +
                                                  std::to_string(kMaxCorrectionCandidates) + ", not " +
                                                  std::to_string(options.correctionCandidates)};
  if (!hasIndex(options.descriptor))
    return Error{ErrorCode::kInvalidArgument, mImpl->store.path().string() + ": opened without its " +
                                                  core::toString(options.descriptor) +
                                                  " index (Database::OpenOptions::descriptors)"};

  Clock::time_point t = Clock::now();
  if (Status valid = core::validateMesh(mesh); !valid) return valid.error();
  const core::TopologyReport topology = core::analyzeTopology(mesh);
  // A surface of several shells: separate solids, or cavities inside one (only a closed, oriented one
  // says which). The entries the catalog generates are one solid each, without cavities.
  core::ShellCount shells{.solids = 1};
  bool shellsCross = false;  // several solids that pass through each other: parts that overlap
  if (topology.components > 1 && topology.isClosed() && topology.isConsistentlyOriented()) {
    shells = core::countShells(core::findShells(mesh));
    if (shells.solids > 1) shellsCross = !core::findSelfIntersections(mesh).empty();
  }
  out.times.validate = microsecondsSince(t);

  t = Clock::now();
  core::MassPropertiesOptions massOptions;
  massOptions.allowApproximate = options.approximate;
  auto mass = core::computeMassProperties(mesh, topology, massOptions);
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
  core::SearchOptions search = options.search;
  if (correcting) search.k = std::max(search.k, options.correctionCandidates);
  const bool blending = options.adapt && !options.stretchCorrection && options.neighbours > 1;
  if (blending) search.k = std::max(search.k, options.neighbours);
  auto matches = index(options.descriptor).search(*candidates, search);
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
  const std::size_t candidateCount =
      correcting ? std::min(out.matches.size(), static_cast<std::size_t>(options.correctionCandidates)) : 1;
  // The fidelity report covers the matches asked for (and the correction's candidates), not the further
  // ones a spectrum is blended from: it would fetch their tets.
  const std::size_t reportCount = std::min(
      out.matches.size(),
      static_cast<std::size_t>(std::max(options.search.k, correcting ? options.correctionCandidates : 1)));
  const std::size_t fetchCount = options.fidelity ? std::max(reportCount, candidateCount) : candidateCount;
  for (std::size_t i = 0; i < fetchCount; ++i) {
    auto e = mImpl->cachedEntry(out.matches[i].match.entry);
    if (!e) return e.error();
    entries.push_back(std::move(e).value());
  }
  out.times.fetch = microsecondsSince(t);
  out.entryPhysics = std::shared_ptr<const core::PhysicalData>(entries.front(), &entries.front()->data);

  if (options.adapt) {
    // The geometry correction first, in the entries' canonical frames: the query's surface carried into
    // each candidate's, the candidate's tets morphed onto it, and the modes computed again for the one
    // that reaches the query's surface best.
    std::optional<volume::CorrectedEntry> corrected;
    std::shared_ptr<const core::TetLocator> correctedLocator;
    std::vector<std::string> correctionWarnings;
    if (options.correct) {
      t = Clock::now();
      // The modes are computed again anyway: with the material's own Poisson ratio (validated above).
      volume::ModalOptions modal = parameters().entry.modal;
      modal.material.poissonRatio = options.material.poissonRatio;
      // The fallback: the three nearest entries by shape alone (no moment term: the morph's prestretch
      // gives the query's proportions) and the nearest box, each unless it was morphed already.
      std::function<std::vector<Fallback>()> fallback;
      if (options.correctionFallback)
        fallback = [&] {
          std::vector<core::EntryId> seen;
          for (std::size_t i = 0; i < candidateCount; ++i)
            seen.push_back(out.matches[i].match.entry);
          std::vector<Fallback> more;
          const auto take = [&](const core::Match& m) {
            if (std::find(seen.begin(), seen.end(), m.entry) != seen.end()) return;
            seen.push_back(m.entry);
            if (auto e = mImpl->cachedEntry(m.entry)) more.push_back({m, std::move(e).value()});
          };
          core::SearchOptions shape = search;
          shape.k = static_cast<int>(candidateCount + kShapeFallbacks);
          shape.momentWeight = 0.0;
          if (auto found = index(options.descriptor).search(*candidates, shape))
            for (const core::Match& m : *found)
              if (more.size() < kShapeFallbacks) take(m);
          if (!mImpl->boxes.empty()) {
            core::SearchOptions box = search;
            box.k = 1;
            box.among = mImpl->boxes;
            if (auto found = index(options.descriptor).search(*candidates, box); found && !found->empty())
              take(found->front());
          }
          return more;
        };
      Correction c =
          correctAmongCandidates(mesh, out, entries, candidateCount, modal, options.correction, fallback);
      if (c.fallback) {
        // The fallback's match follows the search's; entries keeps matches' indices.
        entries.resize(out.matches.size());
        entries.push_back(c.fallback->entry);
        out.matches.push_back({c.fallback->match, entry(c.fallback->match.entry), std::nullopt});
        c.answered = out.matches.size() - 1;
      }
      if (c.corrected) {
        out.answered = c.answered;
        out.correction = c.corrected->report;
        corrected = std::move(c.corrected);
        correctedLocator = std::make_shared<const core::TetLocator>(corrected->physics.tetMesh);
        correctionWarnings = volume::correctionWarnings(*out.correction);
      } else {
        correctionWarnings = {"geometry correction not applied (the entry's own data stand): " + c.error};
      }
      out.times.correct = microsecondsSince(t);
    }
    const CachedEntry& answered = *entries[out.answered];
    out.entryPhysics = std::shared_ptr<const core::PhysicalData>(entries[out.answered], &answered.data);
    const core::PhysicalData& data = corrected ? corrected->physics : answered.data;
    out.locator = corrected
                      ? correctedLocator
                      : std::shared_ptr<const core::TetLocator>(entries[out.answered], &answered.locator);
    const core::TetLocator& locator = *out.locator;

    t = Clock::now();
    auto adapted = core::adapt(
        data, out.normalization, out.massProperties, out.answeredMatch().match.orientation, options.material,
        parameters().entry.damping, options.stretchCorrection ? &answered.stretchBasis() : nullptr);
    if (!adapted) return adapted.error();
    out.physics = std::move(adapted).value();
    if (!corrected) {
      // The nearest tier's eigenvalues from the spectra of the first matches (k-nearest-neighbour
      // regression), the shapes the nearest's; the answered match is the first when uncorrected.
      const std::size_t n = blending ? std::min<std::size_t>(options.neighbours, out.matches.size()) : 1;
      std::vector<std::shared_ptr<const Eigen::VectorXd>> spectra{
          std::shared_ptr<const Eigen::VectorXd>(entries.front(), &answered.data.modes.eigenvalues)};
      std::vector<core::SpectrumSample> samples{{spectra.front().get(), out.matches.front().match.distance}};
      for (std::size_t k = 1; k < n; ++k) {
        auto e = mImpl->spectrum(out.matches[k].match.entry);
        if (!e) return e.error();
        spectra.push_back(std::move(e).value());
        samples.push_back({spectra.back().get(), out.matches[k].match.distance});
      }
      const Eigen::VectorXd blended = core::blendSpectra(samples, &out.spectrumWeights);
      out.physics->eigenvalues.array() *= blended.array() / answered.data.modes.eigenvalues.array();
    }
    out.physics->warnings.insert(out.physics->warnings.end(), correctionWarnings.begin(),
                                 correctionWarnings.end());
    const bool generated = generatedEntry(out.answeredMatch());
    if (shells.solids > 1) {
      char share[32];
      std::snprintf(share, sizeof share, "%.3g", 100.0 * shells.largestSolidShare);
      if (shellsCross)
        out.physics->warnings.push_back(
            "the surface is " + std::to_string(shells.solids) +
            " closed shells wound outward that pass through each other (parts that overlap), not one "
            "solid: its volume and mass count the overlap twice, and the answer is one body's, as if "
            "they were joined, and may be far off; --repair makes them the one solid they overlap into");
      else
        out.physics->warnings.push_back(
            "the surface is " + std::to_string(shells.solids) +
            " closed shells wound outward (separate solids, or parts that touch), not one; the largest "
            "holds " +
            share +
            " % of their volume: the answer is one body's, as if they were joined, and may be far off; a "
            "mesh of each solid gets its own data, and parts that touch become one solid with --repair");
    }
    if (shells.cavities > 0 && generated)
      out.physics->warnings.push_back(
          "the surface encloses " + std::to_string(shells.cavities) +
          (shells.cavities == 1 ? " cavity" : " cavities") +
          " (a closed shell wound inward: the solid is hollow there), which the catalog's entries do not "
          "have: the answer is of a body without them and may be far off; the object's own data, computed "
          "with them, come from enrichment");
    if (out.massProperties.isApproximate)
      out.physics->warnings.push_back(
          "approximate: the surface bounds no well-defined solid, so its mass, centre and inertia are "
          "estimated from vertex point masses (a shell's inertia, larger than the solid's)");
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
      if (i >= reportCount && i != out.answered) continue;
      MatchReport& m = out.matches[i];
      const core::Placement placement = core::placementOf(out.normalization, m.match.orientation);
      m.fidelity = core::assessFidelity(mesh, queryTree, out.normalization, entries[i]->locator,
                                        entries[i]->data.massProperties, placement,
                                        m.match.distance - m.match.momentTerm, options.fidelityOptions);
      m.predictedFrequencyError = core::predictFrequencyError(core::evidenceOf(*m.fidelity));
    }
    out.times.fidelity = microsecondsSince(t);
    if (out.physics && options.link && !mesh.vertices.empty()) {
      core::ErrorEvidence evidence = core::evidenceOf(*out.answeredMatch().fidelity);
      evidence.outsideShare =
          static_cast<double>(out.link.outsideCount) / static_cast<double>(mesh.vertices.size());
      if (out.correction) {
        evidence.morphTargetDistance = out.correction->morph.meanTargetDistance;
        evidence.massScale = out.correction->massScale;
        evidence.strayShare = out.correction->strayShare;
      }
      // The model was fitted on single solids without cavities: outside them it has nothing to say (and an
      // unknown error is one enrichment learns from).
      if (shells.solids == 1 && (shells.cavities == 0 || !generatedEntry(out.answeredMatch())))
        out.predictedFrequencyError = core::predictFrequencyError(evidence);
    }
  }
  out.times.total = microsecondsSince(start);
  return out;
}

std::vector<Result<QueryResult>> Database::queryMany(std::span<const core::TriangleMesh> meshes,
                                                     const QueryOptions& options) const {
  std::vector<std::optional<Result<QueryResult>>> answers(meshes.size());
  // One mesh a task: a fragment's query takes about a millisecond, enough to outweigh a task's cost, and
  // the large ones are not held up behind a batch of others.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, meshes.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        answers[i].emplace(query(meshes[i], options));
                    });
  std::vector<Result<QueryResult>> out;
  out.reserve(meshes.size());
  for (std::optional<Result<QueryResult>>& a : answers)
    out.push_back(std::move(*a));
  return out;
}

Result<std::shared_ptr<const core::PhysicalData>> Database::physics(core::EntryId id) const {
  auto e = mImpl->cachedEntry(id);
  if (!e) return e.error();
  return std::shared_ptr<const core::PhysicalData>(*e, &(*e)->data);
}

std::array<std::size_t, 2> Database::cacheStats() const {
  std::lock_guard lock(mImpl->cacheMutex);
  return {mImpl->hits, mImpl->misses};
}

}  // namespace shapedb::io
