// A fracture's burst: a mesh broken into fragments that all need physical data at one instant.
//
//   build/release/bin/burst_bench DB MESH [--pieces N] [--runs R] [--fidelity] [--cache E] [--neighbours K]
//                                 [--units mm|cm|m|in|ft]
//
// MESH is broken with shapedb's fracture (N Voronoi pieces, default 200; the default resolution), then the
// fragments are answered R times (default 5) each way, and the medians over the runs are reported:
//   - burst, cold: a fresh Database (its open included: the index of the descriptor searched, as `shapedb
//     query` opens it; its entry cache empty), then Database::queryMany
//     over every fragment: the wall time to all of them matched, fetched, adapted and linked;
//   - burst, warm: queryMany again on that Database (its cache as the cold burst left it);
//   - one at a time, warm: the same fragments through Database::query, one after another, as before
//     queryMany (the figure a burst replaces);
//   - per stage, the median over the fragments of the warm one-at-a-time queries (microseconds).
// Queries skip the fidelity report unless --fidelity is given (an interactive burst does not need it).
// --cache sets the Database's entry cache (Database::OpenOptions::cacheEntries; its default otherwise);
// --neighbours, how many matches' spectra each answer's eigenvalues are blended from (QueryOptions).
// The machine's cores are all used by the bursts (TBB); `taskset -c 0` measures one core.

#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <shapedb/core/statistics.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/fracture.h>

namespace {

namespace core = shapedb::core;
namespace io = shapedb::io;
namespace volume = shapedb::volume;
using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// Fails the run: a burst with an unanswered fragment is not a measurement.
bool allAnswered(const std::vector<shapedb::Result<io::QueryResult>>& results) {
  for (const auto& r : results)
    if (!r) {
      std::fprintf(stderr, "burst_bench: a fragment's query failed: %s\n", r.error().message.c_str());
      return false;
    }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  int pieces = 200, runs = 5;
  std::optional<std::size_t> cacheEntries;
  bool fidelity = false;
  int neighbours = io::QueryOptions{}.neighbours;
  double scale = 1.0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--pieces") && i + 1 < argc) {
      pieces = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) {
      runs = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--cache") && i + 1 < argc) {
      const int entries = std::atoi(argv[++i]);
      if (entries < 1) {
        std::fprintf(stderr, "burst_bench: --cache takes a number of entries ≥ 1\n");
        return 2;
      }
      cacheEntries = static_cast<std::size_t>(entries);
    } else if (!std::strcmp(argv[i], "--neighbours") && i + 1 < argc) {
      neighbours = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--fidelity")) {
      fidelity = true;
    } else if (!std::strcmp(argv[i], "--units") && i + 1 < argc) {
      const std::optional<double> unit = io::unitScale(argv[++i]);
      if (!unit) {
        std::fprintf(stderr, "burst_bench: unknown unit %s (mm, cm, m, in or ft)\n", argv[i]);
        return 2;
      }
      scale = *unit;
    } else if (argv[i][0] == '-') {
      std::fprintf(stderr, "burst_bench: unknown option %s\n", argv[i]);
      return 2;
    } else {
      positional.push_back(argv[i]);
    }
  }
  if (positional.size() != 2 || pieces < 1 || runs < 1 || neighbours < 1) {
    std::fprintf(stderr,
                 "usage: burst_bench DB MESH [--pieces N] [--runs R] [--fidelity] [--cache E]\n"
                 "                   [--neighbours K]\n"
                 "                   [--units mm|cm|m|in|ft]\n");
    return 2;
  }
  const std::string dbPath = positional[0], meshPath = positional[1];

  io::LoadOptions load;
  load.scale = scale;
  auto mesh = io::loadMesh(meshPath, load);
  if (!mesh) {
    std::fprintf(stderr, "burst_bench: %s\n", mesh.error().message.c_str());
    return 1;
  }
  volume::FractureOptions breaking;
  breaking.pieces = pieces;
  const Clock::time_point broke = Clock::now();
  auto fractured = volume::fracture(mesh->mesh, breaking);
  if (!fractured) {
    std::fprintf(stderr, "burst_bench: %s: %s\n", meshPath.c_str(), fractured.error().message.c_str());
    return 1;
  }
  const std::vector<core::TriangleMesh>& fragments = fractured->fragments;
  std::size_t triangles = 0;
  for (const core::TriangleMesh& f : fragments)
    triangles += f.triangleCount();
  std::printf("%s: %zu fragments of %d pieces (%.0f triangles each on average; fracture %.1f s), %d runs\n",
              meshPath.c_str(), fragments.size(), pieces,
              static_cast<double>(triangles) / static_cast<double>(fragments.size()),
              millisecondsSince(broke) / 1e3, runs);

  io::QueryOptions options;
  options.fidelity = fidelity;
  options.neighbours = neighbours;
  std::vector<double> cold, coldOpen, warm, serial;
  std::vector<double> validate, mass, describe, search, fetch, adapt, link, total;
  io::Database::OpenOptions open;
  open.descriptors = {options.descriptor};  // the one index the burst searches, as shapedb query opens
  if (cacheEntries) open.cacheEntries = *cacheEntries;
  for (int run = 0; run < runs; ++run) {
    Clock::time_point start = Clock::now();
    auto db = io::Database::open(dbPath, open);
    if (!db) {
      std::fprintf(stderr, "burst_bench: %s\n", db.error().message.c_str());
      return 1;
    }
    coldOpen.push_back(millisecondsSince(start));
    if (!allAnswered(db->queryMany(fragments, options))) return 1;
    cold.push_back(millisecondsSince(start));

    start = Clock::now();
    if (!allAnswered(db->queryMany(fragments, options))) return 1;
    warm.push_back(millisecondsSince(start));

    start = Clock::now();
    std::vector<io::QueryResult> alone;
    for (const core::TriangleMesh& f : fragments) {
      auto r = db->query(f, options);
      if (!r) {
        std::fprintf(stderr, "burst_bench: a fragment's query failed: %s\n", r.error().message.c_str());
        return 1;
      }
      alone.push_back(std::move(r).value());
    }
    serial.push_back(millisecondsSince(start));
    for (const io::QueryResult& r : alone) {
      validate.push_back(r.times.validate);
      mass.push_back(r.times.massProperties);
      describe.push_back(r.times.describe);
      search.push_back(r.times.search);
      fetch.push_back(r.times.fetch);
      adapt.push_back(r.times.adapt);
      link.push_back(r.times.link);
      total.push_back(r.times.total);
    }
  }

  std::printf("\n| | wall time to all answered (median of %d) |\n|---|---:|\n", runs);
  std::printf("| burst, cold (open %.1f ms included) | %.1f ms |\n", core::median(coldOpen),
              core::median(cold));
  std::printf("| burst, warm | %.1f ms |\n", core::median(warm));
  std::printf("| one at a time, warm | %.1f ms |\n", core::median(serial));
  std::printf("\nwarm burst %.2fx faster than one at a time\n", core::median(serial) / core::median(warm));
  std::printf("\nper query, one at a time (µs): median (p99)\n");
  const auto row = [](const char* stage, const std::vector<double>& v) {
    std::printf("  %-16s %9.1f (%.1f)\n", stage, core::median(v), core::percentile(v, 0.99));
  };
  row("validate", validate);
  row("mass properties", mass);
  row("describe", describe);
  row("search", search);
  row("fetch", fetch);
  row("adapt", adapt);
  row("link", link);
  row("total", total);
  return 0;
}
