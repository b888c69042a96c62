// Each mesh of DIR queried through io::Database::query (centroid-voxel, the fidelity report off), one
// Database for all: once without the correction (untimed: it fetches the matches' entries into the cache,
// as shapedb bench's earlier methods do), then twice with it (three candidates). The first corrected query
// of a mesh finds its candidates' plans (since 56d1f12) not yet made unless an earlier mesh's correction
// made them; the second finds them. Prints the medians of the first and the second queries' times, the
// process's peak resident memory, the heap in use at the end (the entry cache and what it keeps) and how
// many entries were morphed; with a third argument, each query's time. A measurement program, not built
// with the project: from build/release,
//   g++ -std=c++20 -O2 -march=native -ffp-contract=off -I../../core/include -I../../io/include \
//     -I../../volume/include -I/usr/include/eigen3 coldwarm.cpp -o coldwarm (the libraries as for
//     ../block_solves_2026-11-30/warm_queries.cpp)
//   ./coldwarm DB DIR [v]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <malloc.h>
#include <set>
#include <string>
#include <sys/resource.h>
#include <vector>

#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
using namespace shapedb;
static double med(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}
int main(int argc, char** argv) {
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  auto db = io::Database::open(argv[1]);
  if (!db) return 1;
  std::vector<std::filesystem::path> files;
  for (auto& e : std::filesystem::directory_iterator(argv[2]))
    files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<double> first, second;
  std::set<std::string> morphed;  // the entries morphed: the candidates, and the fallbacks where they were
  for (auto& f : files) {
    auto m = io::loadMesh(f);
    if (!m) continue;
    for (int pass = -1; pass < 2; ++pass) {
      io::QueryOptions q;
      q.descriptor = core::DescriptorKind::kCentroidVoxel;
      q.search.k = 1;
      q.correct =
          pass >= 0;  // the first, uncorrected, fetches the entries (as shapedb bench's earlier methods do)
      q.correctionCandidates = 3;
      const auto start = std::chrono::steady_clock::now();
      auto r = db->query(m->mesh, q);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      if (!r || pass < 0) continue;
      if (r->correction)
        for (std::size_t i = 0; i < r->matches.size() && i < static_cast<std::size_t>(r->correction->morphs);
             ++i)
          morphed.insert(r->matches[i].entry->name);
      (pass == 0 ? first : second).push_back(ms);
      if (argc > 3)
        std::printf("%s pass %d %.1f ms (total %.1f)\n", f.filename().c_str(), pass, ms,
                    r->times.total / 1e3);
    }
  }
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  std::printf(
      "first query median %.1f ms, second %.1f ms, %zu meshes, peak RSS %.0f MB, heap in use %.1f MB, %zu "
      "entries morphed\n",
      med(first), med(second), first.size(), u.ru_maxrss / 1024.0, mallinfo2().uordblks / 1e6,
      morphed.size());
}
