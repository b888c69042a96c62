// detail::nodeNeighbours: the counting version against the pairs-sorting one it replaced, on every 10th
// entry of DB: the same lists, and the time of each (median over the entries of 5 repetitions' best). A
// measurement program, not built with the project: built as coldwarm.cpp, with -I../../volume/src for the
// private header; ./node_neighbours DB.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <shapedb/io/database.h>

#include "mesh_motion.h"
using namespace shapedb;
using volume::detail::NodeNeighbours;
NodeNeighbours byPairs(const core::TetMesh& mesh) {
  std::vector<std::uint64_t> pairs;
  pairs.reserve(16 * mesh.tetCount());
  for (const auto& tet : mesh.tets)
    for (std::uint32_t a : tet)
      for (std::uint32_t b : tet)
        pairs.push_back((static_cast<std::uint64_t>(a) << 32) | b);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  NodeNeighbours out;
  out.start.assign(mesh.nodeCount() + 1, 0);
  out.nodes.reserve(pairs.size());
  for (std::uint64_t p : pairs) {
    ++out.start[(p >> 32) + 1];
    out.nodes.push_back(static_cast<std::uint32_t>(p & 0xffffffffu));
  }
  for (std::size_t i = 0; i < mesh.nodeCount(); ++i)
    out.start[i + 1] += out.start[i];
  return out;
}
template <class F>
double best(F f) {
  double b = 1e9;
  for (int r = 0; r < 5; ++r) {
    auto s = std::chrono::steady_clock::now();
    auto n = f();
    b = std::min(b, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - s).count());
    if (n.nodes.empty()) std::puts("");
  }
  return b;
}
int main(int, char** argv) {
  auto db = io::Database::open(argv[1]);
  std::vector<double> ratio, oldT, newT;
  int same = 0, count = 0;
  for (std::size_t i = 0; i < db->entries().size(); i += 10) {
    auto p = db->physics(db->entries()[i].id);
    if (!p) continue;
    const core::TetMesh& m = (*p)->tetMesh;
    auto a = byPairs(m), b = volume::detail::nodeNeighbours(m);
    same += a.start == b.start && a.nodes == b.nodes;
    ++count;
    double o = best([&] { return byPairs(m); }), n = best([&] { return volume::detail::nodeNeighbours(m); });
    oldT.push_back(o);
    newT.push_back(n);
    ratio.push_back(n / o);
  }
  auto med = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf(
      "%d of %d entries the same lists; median %.0f us by pairs, %.0f us by counting, ratio %.2f "
      "(%.2f-%.2f)\n",
      same, count, med(oldT), med(newT), med(ratio), *std::min_element(ratio.begin(), ratio.end()),
      *std::max_element(ratio.begin(), ratio.end()));
}
