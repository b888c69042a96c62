// Where the plans of a mesh's corrected query go: for each of the mesh's three candidates (the default
// search, k = 3), the parts of its plans timed apart (the best of seven): the morph's (the mesh-motion
// stiffness's layout, the registration's node-block order and CHOLMOD's analysis on it, the interior's
// layout) and the modes' (the node-block order of K − σM on the quadratic tets, CHOLMOD's analysis on it,
// and for scale a whole factorization with that order). A query makes the morph's for every candidate (on
// both cores at once) and the modes' for the one it answers with. A measurement program, not built with
// the project, reaching into volume/src: from build/release,
//   g++ -std=c++20 -O2 -march=native -ffp-contract=off -I../../core/include -I../../io/include \
//     -I../../volume/include -I../../volume/src -I/usr/include/eigen3 -I/usr/include/suitesparse \
//     plan_parts.cpp -o plan_parts (the libraries as for ../block_solves_2026-11-30/warm_queries.cpp)
//   ./plan_parts DB MESH...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include <shapedb/core/physics.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/modal.h>

#include "mesh_motion.h"
#include "sparse_cholesky.h"

using namespace shapedb;
using volume::detail::SparseCholesky;

static double bestOfSeven(const std::function<void()>& run) {
  double best = 1e9;
  for (int i = 0; i < 7; ++i) {
    const auto start = std::chrono::steady_clock::now();
    run();
    best = std::min(
        best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

int main(int argc, char** argv) {
  auto db = io::Database::open(argv[1]);
  if (!db) return 1;
  for (int a = 2; a < argc; ++a) {
    auto loaded = io::loadMesh(argv[a]);
    if (!loaded) return 1;
    io::QueryOptions q;
    q.search.k = 3;
    q.fidelity = false;
    auto r = db->query(loaded->mesh, q);
    if (!r) return 1;
    std::printf("%s (ms)\n", argv[a]);
    for (const auto& match : r->matches) {
      auto data = db->physics(match.match.entry);
      if (!data) return 1;
      const core::TetMesh& mesh = (*data)->tetMesh;
      std::vector<char> isBoundary(mesh.nodeCount(), 0);
      for (const auto& face : core::boundaryFaces(mesh))
        for (const auto node : face.nodes)
          isBoundary[node] = 1;
      const double stiffness = bestOfSeven([&] { volume::detail::MotionStiffness layout(mesh); });
      const auto pattern = volume::detail::MotionStiffness(mesh).matrix();
      const double registrationOrder = bestOfSeven([&] { volume::detail::nodeBlockOrder(pattern); });
      const auto order = volume::detail::nodeBlockOrder(pattern);
      const double registrationAnalysis = bestOfSeven([&] { SparseCholesky::analyze(pattern, order); });
      const double interior =
          bestOfSeven([&] { volume::detail::InteriorMotion::Layout layout(mesh, isBoundary); });
      const auto fem = volume::assembleFem(volume::makeQuadratic(mesh));
      const Eigen::SparseMatrix<double> shifted = fem.stiffness - 1e-3 * fem.mass;
      const double modalOrder = bestOfSeven([&] { volume::detail::nodeBlockOrder(shifted); });
      const auto blocks = volume::detail::nodeBlockOrder(shifted);
      const double modalAnalysis = bestOfSeven([&] { SparseCholesky::analyze(shifted, blocks); });
      const double factorization = bestOfSeven([&] {
        SparseCholesky cholesky;
        cholesky.factorize(shifted, blocks);
      });
      std::printf(
          "  %-16s %5zu nodes, %6ld dofs | morph: stiffness layout %.2f, order %.2f, analysis %.2f, "
          "interior layout %.2f | modes: order %.2f, analysis %.2f (a factorization %.2f)\n",
          match.entry->name.c_str(), mesh.nodeCount(), static_cast<long>(shifted.rows()), stiffness,
          registrationOrder, registrationAnalysis, interior, modalOrder, modalAnalysis, factorization);
    }
  }
}
