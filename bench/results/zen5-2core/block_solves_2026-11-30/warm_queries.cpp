// Warm corrected queries through io::Database::query, as `shapedb bench` times them: every mesh of DIR
// queried twice (centroid-voxel, three candidates, the fidelity report on), the second timed; prints the
// medians (total without the fidelity report, the correction, its modes) and, with a fourth argument, a
// line per mesh. A measurement program, not built with the project: from build/release,
//   g++ -std=c++20 -O2 -march=native -ffp-contract=off -I../../core/include -I../../io/include \
//     -I../../volume/include -I/usr/include/eigen3 warm_queries.cpp -o warm_queries \
//     io/libshapedb_io.a io/libshapedb_io_mesh.a volume/libshapedb_volume.a io/libshapedb_io_media.a \
//     core/libshapedb_core.a (and the system libraries the shapedb target links) -ltbb
//   ./warm_queries DB DIR [CANDIDATES] [v]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <malloc.h>
#include <string>
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
  if (!db) {
    std::puts(db.error().message.c_str());
    return 1;
  }
  std::vector<std::filesystem::path> files;
  for (auto& e : std::filesystem::directory_iterator(argv[2]))
    files.push_back(e.path());
  std::sort(files.begin(), files.end());
  int candidates = argc > 3 ? std::atoi(argv[3]) : 3;
  std::vector<double> tot, cor, morph, modes, fetch, rest;
  for (int pass = 0; pass < 2; ++pass)
    for (auto& f : files) {
      auto m = io::loadMesh(f);
      if (!m) continue;
      io::QueryOptions q;
      q.descriptor = core::DescriptorKind::kCentroidVoxel;
      q.search.k = 1;
      q.correct = true;
      q.correctionCandidates = candidates;
      q.fidelity = true;
      auto r = db->query(m->mesh, q);
      if (!r) {
        std::printf("%s: %s\n", f.c_str(), r.error().message.c_str());
        continue;
      }
      if (pass == 0) continue;
      const auto& t = r->times;
      tot.push_back(t.total - t.fidelity);
      cor.push_back(t.correct);
      fetch.push_back(t.fetch);
      modes.push_back(r->correction->modesSeconds * 1e6);
      morph.push_back(t.correct - r->correction->modesSeconds * 1e6);
      rest.push_back(t.total - t.fidelity - t.correct);
      if (argc > 4)
        std::printf("%s %s ans %zu spec %d total %.1f correct %.1f modes %.1f morphsum %.1f\n",
                    f.filename().c_str(), r->answeredMatch().entry->name.c_str(), r->answered,
                    (int)r->correction->speculative + 10 * (int)r->correction->fallback, tot.back() / 1e3,
                    cor.back() / 1e3, modes.back() / 1e3, r->correction->morphSeconds * 1e3);
    }
  std::printf("median ms: total-fid %.1f correct %.1f (non-modes %.1f, modes %.1f) rest %.1f fetch %.1f\n",
              med(tot) / 1e3, med(cor) / 1e3, med(morph) / 1e3, med(modes) / 1e3, med(rest) / 1e3,
              med(fetch) / 1e3);
}
