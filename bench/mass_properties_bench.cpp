// The first stage of a query: mass properties and normalization of a surface mesh.
// Target: mass properties + normalization <= 50 us for 5k triangles on one core; the paper
// tetrahedralized the query with TetGen instead (milliseconds).
//   build/release/bin/mass_properties_bench --benchmark_repetitions=10 --benchmark_report_aggregates_only

#include <filesystem>

#include <benchmark/benchmark.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

namespace {

using namespace shapedb;

// A latitude-longitude ellipsoid of exactly 2·slices·(stacks−1) triangles: 5,000 or 100,000.
core::TriangleMesh meshOfTriangles(std::int64_t triangles) {
  return triangles <= 5000 ? core::makeUvEllipsoid({1.0, 1.6, 0.7}, 50, 51)
                           : core::makeUvEllipsoid({1.0, 1.6, 0.7}, 250, 201);
}

void setTriangleCounters(benchmark::State& state, const core::TriangleMesh& mesh) {
  state.counters["triangles"] = static_cast<double>(mesh.triangleCount());
  state.counters["ns_per_triangle"] =
      benchmark::Counter(static_cast<double>(mesh.triangleCount()),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_MassPropertiesAndNormalize(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  const core::TopologyReport topology = core::analyzeTopology(mesh);
  for (auto _ : state) {
    auto mp = core::computeMassProperties(mesh, topology);
    auto n = core::normalize(mesh, *mp);
    benchmark::DoNotOptimize(n);
  }
  setTriangleCounters(state, mesh);
  state.SetLabel("target <= 50 us at 5k triangles");
}
BENCHMARK(BM_MassPropertiesAndNormalize)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

void BM_MassProperties(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  const core::TopologyReport topology = core::analyzeTopology(mesh);
  for (auto _ : state)
    benchmark::DoNotOptimize(core::computeMassProperties(mesh, topology));
  setTriangleCounters(state, mesh);
}
BENCHMARK(BM_MassProperties)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

// The topology check that loading does once per mesh (not part of the 50 us target).
void BM_AnalyzeTopology(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(core::analyzeTopology(mesh));
  setTriangleCounters(state, mesh);
}
BENCHMARK(BM_AnalyzeTopology)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

// Its oracle: one global sort of the half-edges.
void BM_AnalyzeTopologyBySorting(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(core::analyzeTopologyBySorting(mesh));
  setTriangleCounters(state, mesh);
}
BENCHMARK(BM_AnalyzeTopologyBySorting)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

// The per-face checks of validateMesh (finite, in range, not degenerate).
void BM_ValidateMesh(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(core::validateMesh(mesh));
  setTriangleCounters(state, mesh);
}
BENCHMARK(BM_ValidateMesh)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

// Loading a binary PLY: parse, validate, topology.
void BM_LoadBinaryPly(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  const auto path =
      std::filesystem::temp_directory_path() / ("shapedb_bench_" + std::to_string(state.range(0)) + ".ply");
  if (!io::saveMesh(mesh, path).ok()) {
    state.SkipWithError("cannot write the mesh");
    return;
  }
  for (auto _ : state)
    benchmark::DoNotOptimize(io::loadMesh(path));
  std::filesystem::remove(path);
  setTriangleCounters(state, mesh);
}
BENCHMARK(BM_LoadBinaryPly)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace

namespace {

void BM_Normalize(benchmark::State& state) {
  const core::TriangleMesh mesh = meshOfTriangles(state.range(0));
  const auto mp = core::computeMassProperties(mesh);
  for (auto _ : state)
    benchmark::DoNotOptimize(core::normalize(mesh, *mp));
  setTriangleCounters(state, mesh);
}
BENCHMARK(BM_Normalize)->Arg(5000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace
