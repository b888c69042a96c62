// buildDatabaseMpi (build_mpi.h): rank 0 runs a BuildSession (build_session.h) and hands out its
// entries; the other ranks compute them and send them back as bytes (toWire).
#include <chrono>
#include <cstdint>
#include <mpi.h>
#include <string>
#include <thread>
#include <vector>

#include <tbb/task_arena.h>

#include <shapedb/io/build_mpi.h>

#include "build_session.h"

namespace shapedb::io {
namespace {

using Clock = std::chrono::steady_clock;

enum Tag : int {
  kWork = 1,    ///< rank 0 → worker: one catalog index (uint64)
  kStop = 2,    ///< rank 0 → worker: no more work
  kResult = 3,  ///< worker → rank 0: a computed entry (toWire's bytes)
};

/// Rank 0 tells the others whether the build started and, if so, the parameters it runs with (a resumed
/// build's come from the file, which only rank 0 reads).
std::string broadcastParameters(const std::string& fromRankZero, bool started) {
  std::uint64_t size = started ? fromRankZero.size() + 1 : 0;
  MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  if (size == 0) return {};
  std::string text = fromRankZero;
  text.resize(size - 1);
  MPI_Bcast(text.data(), static_cast<int>(size - 1), MPI_CHAR, 0, MPI_COMM_WORLD);
  return text;
}

void sendWork(int rank, std::uint64_t index) {
  MPI_Send(&index, 1, MPI_UINT64_T, rank, kWork, MPI_COMM_WORLD);
}
void sendStop(int rank) {
  MPI_Send(nullptr, 0, MPI_BYTE, rank, kStop, MPI_COMM_WORLD);
}

/// Waits for any worker's result without spinning a core (MPI's blocking calls poll, which would take
/// a core from the workers on a machine they share).
MPI_Status awaitResult() {
  MPI_Status status{};
  int arrived = 0;
  for (;;) {
    MPI_Iprobe(MPI_ANY_SOURCE, kResult, MPI_COMM_WORLD, &arrived, &status);
    if (arrived) return status;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
}

Result<BuildReport> coordinate(const std::filesystem::path& path, const BuildOptions& options, int ranks) {
  Result<detail::BuildSession> started = detail::BuildSession::start(path, options);
  broadcastParameters(started ? toJson(started->parameters()) : std::string(), started.ok());
  if (!started) return started.error();
  detail::BuildSession& session = *started;
  const std::vector<std::size_t>& todo = session.todo();
  std::size_t next = 0;
  int busy = 0;
  for (int rank = 1; rank < ranks; ++rank) {
    if (next < todo.size()) {
      sendWork(rank, todo[next++]);
      ++busy;
    } else {
      sendStop(rank);
    }
  }
  std::optional<Error> failure;
  std::vector<std::uint8_t> bytes;
  while (busy > 0) {
    const MPI_Status status = awaitResult();
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    bytes.resize(static_cast<std::size_t>(count));
    MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, kResult, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    Result<detail::ComputedEntry> entry = detail::fromWire(bytes.data(), bytes.size());
    if (!entry && !failure)
      failure = Error{ErrorCode::kParse,
                      "rank " + std::to_string(status.MPI_SOURCE) + " sent " + entry.error().message};
    const bool accepted = entry && session.accept(std::move(entry).value());
    if (accepted && !failure && next < todo.size()) {
      sendWork(status.MPI_SOURCE, todo[next++]);
    } else {
      sendStop(status.MPI_SOURCE);
      --busy;
    }
  }
  Result<BuildReport> report = session.finish();  // commits what was accepted, even after a failure
  if (failure) return *failure;
  return report;
}

Result<BuildReport> compute(const BuildOptions& options) {
  const std::string text = broadcastParameters({}, false);
  if (text.empty()) return Error{ErrorCode::kCancelled, "rank 0 did not start the build"};
  Result<BuildParameters> parameters = parseBuildParameters(text);
  if (!parameters) return parameters.error();
  const std::vector<volume::ShapeSpec> catalog =
      volume::buildCatalog(parameters->entries, parameters->families, parameters->weights);
  const auto start = Clock::now();
  BuildReport report;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  for (;;) {
    MPI_Status status{};
    std::uint64_t index = 0;
    MPI_Recv(&index, 1, MPI_UINT64_T, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &status);
    if (status.MPI_TAG != kWork) break;
    if (index >= catalog.size()) MPI_Abort(MPI_COMM_WORLD, 3);  // rank 0 would wait for it forever
    detail::ComputedEntry entry;
    arena.execute([&] { entry = detail::computeCatalogEntry(catalog, index, *parameters); });
    ++(entry.failure ? report.failed : report.built);
    const std::vector<std::uint8_t> bytes = detail::toWire(entry);
    MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, 0, kResult, MPI_COMM_WORLD);
  }
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace

MpiEnvironment::MpiEnvironment() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    mInitializedHere = true;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &mRank);
  MPI_Comm_size(MPI_COMM_WORLD, &mSize);
}

MpiEnvironment::~MpiEnvironment() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (mInitializedHere && !finalized) MPI_Finalize();
}

Result<BuildReport> buildDatabaseMpi(const std::filesystem::path& path, const BuildOptions& options) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1) return buildDatabase(path, options);
  return rank == 0 ? coordinate(path, options, ranks) : compute(options);
}

}  // namespace shapedb::io
