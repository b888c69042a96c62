// Building the shape database: throughput at 1 and 2 threads, time per stage, bytes on disk.
// Targets on the 2-core reference machine: the default database (1,400 entries, 20 modes) in <= 10 min,
// i.e. >= 2.33 entries/s on 2 threads; the demo's database in <= 2 min.
//   build/release/bin/build_bench
// Each run builds a 64-entry catalog of the default mix (every family, 4 of each) into a fresh file.
// Counters: entries_per_s (wall), <stage>_ms (mean CPU-time per entry: tetrahedralize, modes, collision,
// describe), kib_per_entry (file size over entries), target_entries_per_s.

#include <filesystem>
#include <unistd.h>

#include <benchmark/benchmark.h>

#include <shapedb/io/database.h>

namespace {

using shapedb::io::BuildOptions;

void BM_Build(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const std::size_t entries = 64;
  const auto path =
      std::filesystem::temp_directory_path() / ("shapedb-build-bench-" + std::to_string(::getpid()) + ".db");
  shapedb::io::BuildReport report;
  double bytes = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    for (const char* suffix : {"", "-wal", "-shm"})
      std::filesystem::remove(path.string() + suffix);
    BuildOptions options;
    options.parameters.entries = entries;
    shapedb::volume::FamilyMix mix = shapedb::volume::defaultFamilyMix();
    options.parameters.families = std::move(mix.families);
    options.parameters.weights = std::move(mix.weights);
    options.threads = threads;
    state.ResumeTiming();
    auto r = shapedb::io::buildDatabase(path, options);
    if (!r) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    report = *r;
    state.PauseTiming();
    bytes = static_cast<double>(std::filesystem::file_size(path));
    if (std::filesystem::exists(path.string() + "-wal"))
      bytes += static_cast<double>(std::filesystem::file_size(path.string() + "-wal"));
    state.ResumeTiming();
  }
  const double n = static_cast<double>(report.built);
  state.counters["entries_per_s"] = n / report.seconds;
  state.counters["target_entries_per_s"] =
      static_cast<double>(shapedb::io::BuildParameters{}.entries) / 600.0;
  state.counters["tetrahedralize_ms"] = 1e3 * report.stageSeconds.tetrahedralize / n;
  state.counters["modes_ms"] = 1e3 * report.stageSeconds.modes / n;
  state.counters["collision_ms"] = 1e3 * report.stageSeconds.collision / n;
  state.counters["describe_ms"] = 1e3 * report.stageSeconds.describe / n;
  state.counters["kib_per_entry"] = bytes / 1024.0 / n;
  for (const char* suffix : {"", "-wal", "-shm"})
    std::filesystem::remove(path.string() + suffix);
}
BENCHMARK(BM_Build)->Arg(1)->Arg(2)->Iterations(3)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
