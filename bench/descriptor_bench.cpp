// Describing a mesh and searching the index.
// Targets on the 2-core reference machine:
//   describe + search <= 50 us p50 for a 5k-triangle mesh against 4,500 entries on one core
//   (the paper: 4 ms per fragment); exact search, one query at a time, p50 <= 0.5 ms and p99 <= 2 ms
//   against 10^6 entries, p50 <= 5 ms against 10^7, for every descriptor kind; <= 1 KiB per entry for
//   centroid-voxel at N = 10, and the index built holding one copy of it.
//   build/release/bin/descriptor_bench --benchmark_filter=BM_Search
// Search counters: p50_us / p99_us per query; distances, entry bounds and group bounds computed per
// query; index_bytes_per_entry, what the index holds; build_peak_bytes_per_entry, how far the process's
// resident memory rose above where it stood while the index was built (the builder's arrays and any
// transient copy). The 10^7 runs need about 8 GB (centroid-voxel); their brute force runs 10 queries.
// Entries beyond the 4,500 real shapes are jittered copies of them (synthetic, for scale); queries are
// 500 other random shapes. Results per machine: bench/results/<machine>/descriptor_bench_<family>.csv,
//   for f in Describe Search SearchBuckets DescribeAndSearch; do build/release/bin/descriptor_bench
//     --benchmark_filter="^BM_$f/" --benchmark_out=descriptor_bench_$f.csv --benchmark_out_format=csv; done

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <tuple>

#include <benchmark/benchmark.h>

#include <shapedb/core/index.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/statistics.h>
#include <shapedb/volume/describe.h>

#include "synthetic.h"

namespace {

using shapedb::core::percentile;

using namespace shapedb;

constexpr int kBaseShapes = 4500;

core::DescriptorKind kindOf(std::int64_t arg) {
  return static_cast<core::DescriptorKind>(arg);
}

// ---- Describe ---------------------------------------------------------------------------------------

// A latitude-longitude ellipsoid of exactly 5,000 or 100,000 triangles, as the mass-properties bench.
core::TriangleMesh meshOfTriangles(std::int64_t triangles) {
  return triangles <= 5000 ? core::makeUvEllipsoid({1.0, 1.6, 0.7}, 50, 51)
                           : core::makeUvEllipsoid({1.0, 1.6, 0.7}, 250, 201);
}

void BM_Describe(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  const auto kind = kindOf(state.range(1));
  const auto sampling = static_cast<core::Sampling>(state.range(2));
  const core::Normalization n = *core::normalize(mesh, *core::computeMassProperties(mesh));
  volume::Describer describer(test::descriptorOptions(kind, sampling));
  for (auto _ : state)
    benchmark::DoNotOptimize(describer.describe(mesh, n));
  state.SetLabel(std::string(core::toString(kind)) + "/" + core::toString(sampling));
}
BENCHMARK(BM_Describe)
    ->ArgsProduct({{5000, 100000}, {1, 2}, {0, 1}})
    ->ArgNames({"tris", "kind", "vertices"})
    ->Unit(benchmark::kMicrosecond);

// ---- Index ------------------------------------------------------------------------------------------

// The 4,500 real shapes each descriptor kind starts from, and shapes outside them to query with.
struct Shapes {
  std::vector<core::Descriptor> entries;
  std::vector<core::Descriptor> queries;
};

const Shapes& shapes(core::DescriptorKind kind, core::Sampling sampling = core::Sampling::kArea) {
  static std::map<std::pair<core::DescriptorKind, core::Sampling>, std::unique_ptr<Shapes>> cache;
  auto& slot = cache[{kind, sampling}];
  if (!slot) {
    slot = std::make_unique<Shapes>();
    std::mt19937_64 rng(1);
    for (int i = 0; i < kBaseShapes + 500; ++i) {
      Result<test::DescribedMesh> d =
          test::describeMesh(test::makeRandomShape(rng, 2), test::descriptorOptions(kind, sampling));
      if (!d) continue;
      (slot->entries.size() < kBaseShapes ? slot->entries : slot->queries).push_back(d->descriptor);
    }
  }
  return *slot;
}

// A line of /proc/self/status in bytes ("VmRSS", "VmHWM"); 0 where there is none.
double statusBytes(const std::string& key) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(key + ":", 0) == 0) return 1024.0 * std::stod(line.substr(key.size() + 1));
  return 0.0;
}

// The index of `entries` entries, built on first use; one is held at a time, so that the 10^7 ones do
// not add up.
struct BuiltIndex {
  std::tuple<core::DescriptorKind, std::int64_t, core::Sampling> key;
  std::unique_ptr<core::Index> index;
  /// Resident memory's rise above where it stood, while building: the builder's peak where its arrays
  /// are mapped afresh (large indexes); a small one reuses freed heap and shows less.
  double buildPeakBytes = 0.0;
};

const BuiltIndex& indexOf(core::DescriptorKind kind, std::int64_t entries,
                          core::Sampling sampling = core::Sampling::kArea) {
  static BuiltIndex built;
  if (built.index && built.key == std::tuple(kind, entries, sampling)) return built;
  built = {};
  const Shapes& s = shapes(kind, sampling);
  // Reset the peak to the resident memory of now (Linux: 5 > clear_refs), so that the peak read after
  // the build is this build's.
  std::ofstream("/proc/self/clear_refs") << "5";
  const double before = statusBytes("VmRSS");
  core::IndexBuilder builder(test::descriptorOptions(kind, sampling));
  builder.reserve(static_cast<std::size_t>(entries));
  std::mt19937_64 rng(2);
  std::uniform_int_distribution<int> flips(0, 6);
  for (std::int64_t i = 0; i < entries; ++i) {
    const core::Descriptor& base = s.entries[static_cast<std::size_t>(i % kBaseShapes)];
    const auto id = static_cast<core::EntryId>(i);
    (void)builder.add(id, i < kBaseShapes ? base : test::jitterDescriptor(base, rng, flips(rng), 0.1));
  }
  built.index = std::make_unique<core::Index>(*std::move(builder).build());
  built.key = {kind, entries, sampling};
  built.buildPeakBytes = statusBytes("VmHWM") - before;
  return built;
}

void BM_Search(benchmark::State& state) {
  const auto kind = kindOf(state.range(0));
  const std::int64_t entries = state.range(1);
  const auto method = static_cast<core::SearchMethod>(state.range(2));
  const BuiltIndex& built = indexOf(kind, entries);
  const core::Index& index = *built.index;
  const std::vector<core::Descriptor>& queries = shapes(kind).queries;
  core::SearchOptions options;
  options.method = method;
  options.parallel = state.range(3) != 0;
  std::vector<double> micros;
  core::SearchStats stats;
  std::size_t q = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    auto matches = index.search(queries[q++ % queries.size()], options, &stats);
    const auto stop = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(matches);
    micros.push_back(std::chrono::duration<double, std::micro>(stop - start).count());
  }
  state.counters["p50_us"] = percentile(micros, 0.5);
  state.counters["p99_us"] = percentile(micros, 0.99);
  state.counters["distances_per_query"] =
      static_cast<double>(stats.distanceEvaluations) / static_cast<double>(micros.size());
  state.counters["bounds_per_query"] =
      static_cast<double>(stats.boundEvaluations) / static_cast<double>(micros.size());
  state.counters["group_bounds_per_query"] =
      static_cast<double>(stats.groupBoundEvaluations) / static_cast<double>(micros.size());
  state.counters["index_bytes_per_entry"] =
      static_cast<double>(index.memoryBytes()) / static_cast<double>(index.size());
  state.counters["build_peak_bytes_per_entry"] = built.buildPeakBytes / static_cast<double>(index.size());
  state.SetLabel(std::string(core::toString(kind)) + " " + core::toString(method));
}
// Per kind and size, on the same index (so that it is built once): the pruned search on one core
// (parallel:0), the pruned search as a query runs it by default (parallel:1: once its nearest buckets are
// done, TBB tasks take the rest, which is where a far query's time goes), and brute force (always on TBB;
// at 10^7, seconds a query, on 10 queries only).
[[maybe_unused]] const bool kSearchRegistered = [] {
  for (std::int64_t entries :
       {std::int64_t{kBaseShapes}, std::int64_t{100000}, std::int64_t{1000000}, std::int64_t{10000000}})
    for (std::int64_t kind : {0, 1, 2})
      for (const auto& [method, parallel] : {std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
        auto* b = benchmark::RegisterBenchmark("BM_Search", BM_Search)
                      ->Args({kind, entries, method, parallel})
                      ->ArgNames({"kind", "entries", "method", "parallel"})
                      ->Unit(benchmark::kMicrosecond)
                      ->UseRealTime();
        if (method == 0 && entries >= 10000000) b->Iterations(10);
      }
  return true;
}();

// The paper's ±r buckets: how often its top-1 differs from the exact one, and what it costs.
void BM_SearchBuckets(benchmark::State& state) {
  const auto kind = kindOf(state.range(0));
  const core::Index& index = *indexOf(kind, state.range(1)).index;
  const std::vector<core::Descriptor>& queries = shapes(kind).queries;
  core::SearchOptions exact, buckets;
  buckets.method = core::SearchMethod::kBuckets;
  buckets.bucketRadius = static_cast<int>(state.range(2));
  std::size_t q = 0, misses = 0, searches = 0;
  core::SearchStats stats;
  for (auto _ : state) {
    const core::Descriptor& query = queries[q++ % queries.size()];
    auto found = index.search(query, buckets, &stats);
    state.PauseTiming();
    auto truth = index.search(query, exact);
    if (found->empty() || found->front().entry != truth->front().entry) ++misses;
    ++searches;
    state.ResumeTiming();
  }
  state.counters["miss_rate"] = static_cast<double>(misses) / static_cast<double>(searches);
  state.counters["distances_per_query"] =
      static_cast<double>(stats.distanceEvaluations) / static_cast<double>(searches);
}
BENCHMARK(BM_SearchBuckets)
    ->ArgsProduct({{1, 2}, {kBaseShapes}, {0, 2, 6, 12}})
    ->ArgNames({"kind", "entries", "r"})
    ->Unit(benchmark::kMicrosecond);

// ---- Describe + search: the query's hot path after normalization -----------------------------------

void BM_DescribeAndSearch(benchmark::State& state) {
  const auto kind = kindOf(state.range(0));
  const auto sampling = static_cast<core::Sampling>(state.range(1));
  const core::TriangleMesh mesh = test::makeLopsidedBlob({1.0, 1.6, 0.7}, 4);  // 5,120 triangles
  const core::Normalization n = *core::normalize(mesh, *core::computeMassProperties(mesh));
  const core::Index& index = *indexOf(kind, kBaseShapes, sampling).index;
  volume::Describer describer(test::descriptorOptions(kind, sampling));
  std::vector<double> micros;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    auto candidates = describer.describeCandidates(mesh, n);
    auto matches = index.search(*candidates);
    const auto stop = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(matches);
    micros.push_back(std::chrono::duration<double, std::micro>(stop - start).count());
  }
  state.counters["p50_us"] = percentile(micros, 0.5);
  state.counters["p99_us"] = percentile(micros, 0.99);
  state.counters["triangles"] = static_cast<double>(mesh.triangleCount());
  state.SetLabel(std::string(core::toString(kind)) + "/" + core::toString(sampling) +
                 ", target p50 <= 50 us");
}
BENCHMARK(BM_DescribeAndSearch)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"kind", "vertices"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
