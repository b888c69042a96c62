#include <bit>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <exception>
#include <latch>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include <shapedb/core/mass_properties.h>
#include <shapedb/io/enrich.h>
#include <shapedb/volume/simplify.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::io {
namespace {

using Clock = std::chrono::steady_clock;

/// FNV-1a, 64 bits, one 64-bit word at a time.
struct Fnv1a {
  std::uint64_t state = 0xcbf29ce484222325ULL;
  void add(std::uint64_t word) {
    for (int i = 0; i < 8; ++i, word >>= 8) {
      state ^= word & 0xff;
      state *= 0x100000001b3ULL;
    }
  }
};

}  // namespace

std::string surfaceKey(const core::TriangleMesh& mesh) {
  Fnv1a h;
  h.add(mesh.vertices.size());
  h.add(mesh.triangles.size());
  for (const core::Vec3& v : mesh.vertices)
    for (int axis = 0; axis < 3; ++axis)
      h.add(std::bit_cast<std::uint64_t>(v[axis] + 0.0));  // + 0.0: −0 hashes as 0
  for (const auto& t : mesh.triangles)
    for (int corner = 0; corner < 3; ++corner)
      h.add(static_cast<std::uint64_t>(t[corner]));
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h.state));
  return text;
}

std::string learnedName(const core::TriangleMesh& mesh) {
  return "learned-" + surfaceKey(mesh);
}

struct Enricher::Impl {
  struct Job {
    std::string name;
    NamedMesh mesh;
    Clock::time_point submitted;
    std::promise<Result<Learned>> promise;
  };

  Impl(Database& db, const EnricherOptions& o) : database(db), options(o) {
    entryOptions = database.parameters().entry;
    entryOptions.tetgen.guarded = true;  // objects from outside: TetGen must not take the process down
  }
  void work();
  void run(Job& job);

  Database& database;
  EnricherOptions options;
  volume::EntryOptions entryOptions;

  mutable std::mutex mutex;
  mutable std::condition_variable wake, idle;
  std::deque<std::unique_ptr<Job>> queue;
  /// Queued or being computed, and failed, by learned name: what keeps an object from being computed twice.
  std::unordered_map<std::string, std::shared_future<Result<Learned>>> inFlight, failed;
  std::size_t running = 0;
  bool stopping = false;
  std::vector<std::thread> workers;
};

void Enricher::Impl::work() {
  for (;;) {
    std::unique_ptr<Job> job;
    {
      std::unique_lock lock(mutex);
      wake.wait(lock, [&] { return stopping || !queue.empty(); });
      if (stopping) return;
      job = std::move(queue.front());
      queue.pop_front();
      ++running;
    }
    run(*job);
    std::lock_guard lock(mutex);
    --running;
    idle.notify_all();
  }
}

void Enricher::Impl::run(Job& job) {
  const std::string where = job.mesh.source.empty() ? job.mesh.name : job.mesh.source;
  const auto compute = [&]() -> Result<Learned> {
    auto simplified = volume::surfaceForEntry(job.mesh.mesh, options.maxTriangles);
    if (!simplified) return withContext(simplified.error(), where);
    const core::TriangleMesh& surface = *simplified ? **simplified : job.mesh.mesh;
    auto data = volume::computeEntry(surface, entryOptions);
    if (!data) return withContext(data.error(), where);
    auto id = database.learn(job.name, where, *data);
    if (!id) return id.error();
    Learned learned;
    learned.id = *id;
    learned.name = job.name;
    learned.computed = true;
    learned.seconds = std::chrono::duration<double>(Clock::now() - job.submitted).count();
    learned.stages = data->times;
    return learned;
  };
  // A worker thread must not end the process: what escapes the computation (memory, say) is its error.
  Result<Learned> result = Error{ErrorCode::kInvalidArgument, where + ": not learned"};
  try {
    result = compute();
  } catch (const std::exception& e) {
    result = Error{ErrorCode::kInvalidArgument, where + ": learning it threw: " + e.what()};
  }
  // The books first, then the answer: whoever sees the answer and submits again finds the entry in the
  // database (or the failure remembered), not a computation that looks as if it were still running.
  {
    std::lock_guard lock(mutex);
    if (!result.ok()) failed.emplace(job.name, inFlight.at(job.name));
    inFlight.erase(job.name);  // learned: the database knows it from now on
  }
  job.promise.set_value(std::move(result));
}

Enricher::Enricher(Database& database, const EnricherOptions& options)
    : mImpl(std::make_unique<Impl>(database, options)) {
  // Each worker forks its TetGen process before the constructor returns, not at its first object: a fork
  // stalls the page faults of every other thread of the process, and turns the pages they write next
  // copy-on-write (volume::startTetGenWorker). A haptic loop started after the Enricher then sees no fork
  // while it runs (docs/architecture.md, "No fork while it runs").
  const int count = std::max(1, options.workers);
  std::latch started(count);
  for (int i = 0; i < count; ++i)
    mImpl->workers.emplace_back([impl = mImpl.get(), &started] {
      // A worker that cannot start one now tries again at its first object, and reports it there.
      static_cast<void>(volume::startTetGenWorker());
      started.count_down();
      impl->work();
    });
  started.wait();
}

Enricher::~Enricher() {
  std::deque<std::unique_ptr<Impl::Job>> abandoned;
  {
    std::lock_guard lock(mImpl->mutex);
    mImpl->stopping = true;
    abandoned.swap(mImpl->queue);
  }
  mImpl->wake.notify_all();
  for (std::thread& t : mImpl->workers)
    t.join();
  for (auto& job : abandoned)
    job->promise.set_value(Error{ErrorCode::kCancelled, job->mesh.name +
                                                            ": not learned: the enricher was shut down "
                                                            "before its turn came"});
}

std::shared_future<Result<Learned>> Enricher::submit(const NamedMesh& mesh) {
  Impl& s = *mImpl;
  const std::string name = learnedName(mesh.mesh);
  std::lock_guard lock(s.mutex);
  if (const auto it = s.inFlight.find(name); it != s.inFlight.end()) return it->second;
  if (const auto it = s.failed.find(name); it != s.failed.end()) return it->second;
  if (const EntryRecord* known = s.database.entry(name)) {
    std::promise<Result<Learned>> ready;
    Learned learned;
    learned.id = known->id;
    learned.name = name;
    ready.set_value(learned);
    return ready.get_future().share();
  }
  auto job = std::make_unique<Impl::Job>();
  job->name = name;
  job->mesh = mesh;
  job->submitted = Clock::now();
  std::shared_future<Result<Learned>> future = job->promise.get_future().share();
  s.inFlight.emplace(name, future);
  s.queue.push_back(std::move(job));
  s.wake.notify_one();
  return future;
}

std::size_t Enricher::pending() const {
  std::lock_guard lock(mImpl->mutex);
  return mImpl->queue.size() + mImpl->running;
}

void Enricher::wait() const {
  std::unique_lock lock(mImpl->mutex);
  mImpl->idle.wait(lock, [&] { return mImpl->queue.empty() && mImpl->running == 0; });
}

}  // namespace shapedb::io
