// Each correction candidate of each query, corrected on its own: what the correction's choice among its
// candidates could know before the modes (the morph's report, the stray share, the mass scale, and the
// void share below) beside the first frequency each would give. For every mesh of each directory: the
// default query's three best matches (k = 3, the correction's candidates), then each of them corrected
// alone (a search among that entry only, no fallback). CSV on stdout; `chosen` marks the candidate the
// default corrected query answers with. A measurement program, not built with the project: from
// build/release,
//   g++ -std=c++20 -O2 -march=native -ffp-contract=off -I../../core/include -I../../io/include \
//     -I../../volume/include -I/usr/include/eigen3 candidates.cpp -o candidates (the libraries as for
//     ../block_solves_2026-11-30/warm_queries.cpp)
//   ./candidates DB SET=DIR [SET=DIR ...] > candidates.csv
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <shapedb/core/physics.h>
#include <shapedb/core/spatial.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>

// The void share: of the morphed tets' boundary area, the share whose outward ray meets that boundary again
// across a gap whose midpoint lies inside the query (`void`), and of it the share whose gap is wider than
// 2 % of L (`void_far`): a hole or slit of the morph that the query does not have, the converse of the
// stray share (material where the query has a gap).
static std::pair<double, double> voidShare(const shapedb::core::TetMesh& tets,
                                           const shapedb::core::SurfaceSide& side, double L) {
  using namespace shapedb;
  const core::TriangleMesh bs = core::boundarySurface(tets);
  const core::ClosestPointTree tree(bs);
  double total = 0, inside = 0, far = 0;
  for (std::uint32_t f = 0; f < bs.triangles.size(); ++f) {
    const auto& t = bs.triangles[f];
    const core::Vec3 a0 = bs.vertices[t[0]], a1 = bs.vertices[t[1]], a2 = bs.vertices[t[2]];
    const core::Vec3 nn = (a1 - a0).cross(a2 - a0);
    const double ar = 0.5 * nn.norm();
    if (!(ar > 0)) continue;
    total += ar;
    const core::Vec3 n = nn.normalized(), c = (a0 + a1 + a2) / 3.0;
    auto hit = tree.firstHit(c, n, 1e-9 * L, f);
    if (!hit) continue;
    if (side.signedDistance(c + 0.5 * hit->distance * n) < 0.0) {
      inside += ar;
      if (hit->distance > 0.02 * L) far += ar;
    }
  }
  return {inside / total, far / total};
}
using namespace shapedb;
int main(int argc, char** argv) {
  auto db = io::Database::open(argv[1]);
  if (!db) return 1;
  std::printf(
      "set,shape,rank,entry,family,chosen,f1,descriptor,target_distance,stray,mass_scale,projected,worst_"
      "quality,entry_worst_quality,max_move,mean_move,increments,lumped,void,void_far\n");
  for (int a = 2; a < argc; ++a) {
    const std::string arg = argv[a];
    const std::string set = arg.substr(0, arg.find('='));
    std::vector<std::filesystem::path> files;
    for (auto& e : std::filesystem::directory_iterator(arg.substr(arg.find('=') + 1)))
      files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& file : files) {
      auto m = io::loadMesh(file);
      if (!m) continue;
      io::QueryOptions q0;
      q0.search.k = 3;
      q0.fidelity = false;
      q0.correct = true;
      auto r0 = db->query(m->mesh, q0);
      if (!r0) continue;
      const core::SurfaceSide side(m->mesh);
      const double L = std::cbrt(r0->massProperties.volume);
      for (std::size_t c = 0; c < 3 && c < r0->matches.size(); ++c) {
        const core::EntryId id = r0->matches[c].match.entry;
        io::QueryOptions q = q0;
        q.search.among = std::span<const core::EntryId>(&id, 1);
        q.search.k = 1;
        q.correctionCandidates = 1;
        q.correctionFallback = false;
        auto r = db->query(m->mesh, q);
        if (!r || !r->physics || !r->correction) continue;
        const auto& k = *r->correction;
        const auto v = voidShare(r->physics->tetMesh, side, L);
        std::printf(
            "%s,%s,%zu,%s,%s,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.6g,%.6g,%.6g\n",
            set.c_str(), file.stem().c_str(), c, r0->matches[c].entry->name.c_str(),
            volume::toString(r0->matches[c].entry->family), (int)(c == r0->answered),
            r->physics->frequenciesHz()[0], r0->matches[c].match.distance, k.morph.meanTargetDistance,
            k.strayShare, k.massScale, k.morph.projected, k.morph.worstQuality, k.morph.entryWorstQuality,
            k.morph.maxBoundaryMove, k.morph.meanBoundaryMove, k.morph.increments, k.lumpedModeShare, v.first,
            v.second);
      }
      std::fflush(stdout);
    }
  }
}
