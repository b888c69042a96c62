// The whole query: p50 and p99 of each stage for 5k- and 50k-triangle query meshes.
//   build/release/bin/query_bench [DB] [--queries N] [--csv FILE] [--no-fidelity] [--descriptor KIND]
//                                 [--meshes FILE...]
//   (DB default: build/demo.db; --no-fidelity: skip the fidelity report, to profile the rest;
//   --descriptor: moment, voxel or centroid-voxel, the default)
// --meshes: instead of the blobs, each file given (any format shapedb reads, in metres) queried N times
// (default 15) after one query that warms the cache: per file its orientation candidates and the
// medians of describe, search and the whole query without its fidelity report, and its best match. What
// shows the cost of a shape whose frame the moments leave free to turn (a torus, a ball).
// Targets on the 2-core reference machine, 5k triangles, against the default database:
// mass properties + describe + search <= 100 us p50 (the paper: 4 ms); the whole query with physical
// data fetched, adapted and linked <= 2 ms p50 (fidelity report not included: it is reported apart).
// Validation (per-face checks, closed surface) is its own stage: it is not part of the first target,
// and is part of the second.
// Queries are random smooth blobs (a latitude-longitude ellipsoid with random radii and low-order bumps)
// under a random similarity. Each set is run twice: "cold" (first touch of each matched entry: read from
// the file, its locator built) and "warm" (from the cache). A plain program rather than Google Benchmark:
// it reports percentiles per stage, which Google Benchmark does not.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/statistics.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>

namespace {

using shapedb::core::Mat4;
using shapedb::core::percentile;
using shapedb::core::TriangleMesh;
using shapedb::core::Vec3;

/// A closed star-shaped blob of 2·n·(n+1−1) triangles: n slices, n+1 stacks.
TriangleMesh makeBlob(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  TriangleMesh mesh =
      shapedb::core::makeUvEllipsoid({1.0, 0.4 + 0.6 * u(rng), 0.15 + 0.85 * u(rng)}, n, n + 1);
  std::array<Vec3, 4> bumps;
  for (Vec3& b : bumps)
    b = Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized();
  for (Vec3& v : mesh.vertices) {
    double scale = 1.0;
    for (const Vec3& b : bumps)
      scale += 0.08 * std::exp(4.0 * (v.normalized().dot(b) - 1.0));
    v *= scale;
  }
  const Eigen::Quaterniond q(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
  Mat4 pose = Mat4::Identity();
  pose.topLeftCorner<3, 3>() = (0.01 + 2.0 * u(rng)) * q.normalized().toRotationMatrix();
  pose.topRightCorner<3, 1>() = Vec3(u(rng), u(rng), u(rng)) * 10.0;
  return shapedb::core::transformed(mesh, pose);
}

/// --meshes: per file, the medians of `repeats` warm queries.
int queryFiles(const shapedb::io::Database& db, const std::vector<std::string>& files, int repeats,
               const shapedb::io::QueryOptions& options) {
  std::printf("%-36s %9s %10s %12s %10s %12s  %s\n", "mesh", "triangles", "candidates", "describe µs",
              "search µs", "query µs", "best match");
  for (const std::string& file : files) {
    auto loaded = shapedb::io::loadMesh(file);
    if (!loaded) {
      std::fprintf(stderr, "query_bench: %s\n", loaded.error().message.c_str());
      return 1;
    }
    std::vector<double> describe, search, query;
    std::optional<shapedb::io::QueryResult> last;
    for (int k = 0; k <= repeats; ++k) {
      auto r = db.query(loaded->mesh, options);
      if (!r) {
        std::fprintf(stderr, "query_bench: %s: %s\n", file.c_str(), r.error().message.c_str());
        return 1;
      }
      if (k == 0) continue;  // the cache's first touch of the match
      describe.push_back(r->times.describe);
      search.push_back(r->times.search);
      query.push_back(r->times.total - r->times.fidelity);
      last = std::move(r).value();
    }
    const shapedb::core::Match& best = last->matches.front().match;
    std::printf("%-36s %9zu %10zu %12.1f %10.1f %12.1f  %s at %.4f\n",
                std::filesystem::path(file).filename().string().c_str(), loaded->mesh.triangleCount(),
                last->orientationCandidates, percentile(describe, 0.5), percentile(search, 0.5),
                percentile(query, 0.5), last->matches.front().entry->name.c_str(), best.distance);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dbPath = "build/demo.db", csvPath;
  int queries = 100;
  bool queriesGiven = false;
  std::vector<std::string> meshFiles;
  shapedb::io::QueryOptions options;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--meshes")) {
      while (i + 1 < argc && argv[i + 1][0] != '-')
        meshFiles.emplace_back(argv[++i]);
    } else if (!std::strcmp(argv[i], "--queries") && i + 1 < argc) {
      queries = std::max(1, std::atoi(argv[++i]));
      queriesGiven = true;
    } else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc)
      csvPath = argv[++i];
    else if (!std::strcmp(argv[i], "--no-fidelity"))
      options.fidelity = false;
    else if (!std::strcmp(argv[i], "--descriptor") && i + 1 < argc) {
      const auto kind = shapedb::core::parseDescriptorKind(argv[++i]);
      if (!kind) {
        std::fprintf(stderr, "query_bench: unknown descriptor '%s' (moment, voxel, centroid-voxel)\n",
                     argv[i]);
        return 2;
      }
      options.descriptor = *kind;
    } else if (argv[i][0] != '-')
      dbPath = argv[i];
    else {
      std::fprintf(stderr,
                   "usage: query_bench [DB] [--queries N] [--csv FILE] [--no-fidelity] [--descriptor KIND] "
                   "[--meshes FILE...]\n");
      return 2;
    }
  }
  shapedb::io::Database::OpenOptions open;
  open.cacheEntries = 4096;
  auto db = shapedb::io::Database::open(dbPath, open);
  if (!db) {
    std::fprintf(stderr, "query_bench: %s\n", db.error().message.c_str());
    return 1;
  }
  if (!meshFiles.empty()) return queryFiles(*db, meshFiles, queriesGiven ? queries : 15, options);
  std::printf("database %s: %zu entries; %d queries per size; 2 passes (cold, warm); descriptor %s\n",
              dbPath.c_str(), db->entries().size(), queries, shapedb::core::toString(options.descriptor));
  std::FILE* csv = csvPath.empty() ? nullptr : std::fopen(csvPath.c_str(), "w");
  if (csv) std::fprintf(csv, "triangles,pass,stage,p50_us,p99_us,target_p50_us\n");

  struct Stage {
    const char* name;
    double shapedb::io::QueryTimes::*field;
  };
  const Stage stages[] = {{"validate", &shapedb::io::QueryTimes::validate},
                          {"mass_properties", &shapedb::io::QueryTimes::massProperties},
                          {"describe", &shapedb::io::QueryTimes::describe},
                          {"search", &shapedb::io::QueryTimes::search},
                          {"fetch", &shapedb::io::QueryTimes::fetch},
                          {"adapt", &shapedb::io::QueryTimes::adapt},
                          {"link", &shapedb::io::QueryTimes::link},
                          {"fidelity", &shapedb::io::QueryTimes::fidelity}};
  for (int n : {50, 158}) {  // 5,000 and 49,928 triangles
    std::mt19937_64 rng(2026);
    std::vector<TriangleMesh> meshes;
    for (int i = 0; i < queries; ++i)
      meshes.push_back(makeBlob(rng, n));
    const std::size_t triangles = meshes.front().triangleCount();
    for (const char* pass : {"cold", "warm"}) {
      std::vector<std::vector<double>> t(std::size(stages) + 2);
      std::vector<double> candidates, outside;
      for (const TriangleMesh& mesh : meshes) {
        auto r = db->query(mesh, options);
        if (!r) {
          std::fprintf(stderr, "query_bench: %s\n", r.error().message.c_str());
          return 1;
        }
        for (std::size_t s = 0; s < std::size(stages); ++s)
          t[s].push_back(r->times.*stages[s].field);
        candidates.push_back(static_cast<double>(r->orientationCandidates));
        outside.push_back(static_cast<double>(r->link.outsideCount) /
                          static_cast<double>(mesh.vertices.size()));
        const auto& x = r->times;
        t[std::size(stages)].push_back(x.massProperties + x.describe + x.search);
        t[std::size(stages) + 1].push_back(x.total - x.fidelity);
      }
      std::printf("\n%zu triangles, %s pass (µs)       p50        p99    target p50\n", triangles, pass);
      const auto row = [&](const char* name, const std::vector<double>& v, double target) {
        const double p50 = percentile(v, 0.5), p99 = percentile(v, 0.99);
        std::printf("  %-26s %10.1f %10.1f", name, p50, p99);
        if (target > 0) std::printf("   %8.0f", target);
        std::printf("\n");
        if (csv) std::fprintf(csv, "%zu,%s,%s,%.2f,%.2f,%.0f\n", triangles, pass, name, p50, p99, target);
      };
      for (std::size_t s = 0; s < std::size(stages); ++s)
        row(stages[s].name, t[s], 0);
      const bool small = triangles <= 5000;
      row("normalize+describe+search", t[std::size(stages)], small ? 100.0 : 0.0);
      row("query without fidelity", t[std::size(stages) + 1], small ? 2000.0 : 0.0);
      std::printf("  vertices outside the matched tets: p50 %.0f%%\n", 100.0 * percentile(outside, 0.5));
      std::printf("  orientation candidates: p50 %.0f, p99 %.0f\n", percentile(candidates, 0.5),
                  percentile(candidates, 0.99));
    }
  }
  if (csv) std::fclose(csv);
  return 0;
}
