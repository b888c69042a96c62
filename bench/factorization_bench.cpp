// The modal analysis's factorization, CHOLMOD's supernodal Cholesky (volume/src/sparse_cholesky.h)
// against Eigen's simplicial LDLᵀ that it replaced, on the quadratic-tet matrices K − σM of database
// entries: for one entry of each family, the degrees of freedom, each solver's factorization, one solve,
// and one solve with 20 right-hand sides (milliseconds, best of three), and how far the two solutions
// differ. Each factorization includes its analysis: Eigen's with its AMD on the scalar graph, CHOLMOD's
// with the node-block order the modal analysis gives it (the simplicial solver it replaced had that order
// too, which halved its analysis). Run it on one core (taskset -c 0): the build runs one factorization per
// core.
//   build/release/bin/factorization_bench DB [--per-family N]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include <shapedb/io/database.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/modal.h>

#include "sparse_cholesky.h"

namespace {

using namespace shapedb;
using Clock = std::chrono::steady_clock;

/// The best of three runs of f, milliseconds.
template <typename F>
double bestOfThree(F&& f) {
  double best = 1e300;
  for (int run = 0; run < 3; ++run) {
    const Clock::time_point start = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s DB [--per-family N]\n", argv[0]);
    return 2;
  }
  int perFamily = 1;
  for (int i = 2; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--per-family") perFamily = std::max(1, std::atoi(argv[++i]));
  auto db = io::Database::open(argv[1]);
  if (!db) {
    std::fprintf(stderr, "%s\n", db.error().message.c_str());
    return 1;
  }
  std::printf(
      "| entry | dof | simplicial: factor | solve | 20 solves | supernodal: factor | solve | 20 solves "
      "| relative difference |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::map<std::string, int> taken;
  std::vector<double> factorRatio, solveRatio, blockRatio;
  for (const io::EntryRecord& record : db->entries()) {
    if (taken[volume::toString(record.family)]++ >= perFamily) continue;
    auto physics = db->physics(record.id);
    if (!physics) continue;
    const volume::FemMatrices fem = volume::assembleFem(volume::makeQuadratic((*physics)->tetMesh));
    const double scale = fem.stiffness.diagonal().sum() / fem.mass.diagonal().sum();
    Eigen::SparseMatrix<double> a = fem.stiffness + 1e-6 * scale * fem.mass;  // σ as the modal analysis's
    a.makeCompressed();
    const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 20);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> simplicial;
    volume::detail::SparseCholesky supernodal;
    const double f1 = bestOfThree([&] { simplicial.compute(a); });
    const std::vector<int> order = volume::detail::nodeBlockOrder(a);  // as the modal analysis orders
    const double f2 = bestOfThree([&] { supernodal.factorize(a, order); });
    Eigen::MatrixXd x1, x2;
    const double s1 = bestOfThree([&] { x1 = simplicial.solve(b.col(0)); });
    const double s2 = bestOfThree([&] { x2 = supernodal.solve(Eigen::MatrixXd(b.col(0))); });
    const double m1 = bestOfThree([&] { x1 = simplicial.solve(b); });
    const double m2 = bestOfThree([&] { x2 = supernodal.solve(b); });
    std::printf("| %s | %ld | %.1f | %.2f | %.1f | %.1f | %.2f | %.1f | %.1e |\n", record.name.c_str(),
                static_cast<long>(a.rows()), f1, s1, m1, f2, s2, m2, (x1 - x2).norm() / x1.norm());
    factorRatio.push_back(f1 / f2);
    solveRatio.push_back(s1 / s2);
    blockRatio.push_back(m1 / m2);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  std::printf(
      "\nmedian speedup of the supernodal factorization: factor %.2fx, one solve %.2fx, 20 solves %.2fx\n",
      median(factorRatio), median(solveRatio), median(blockRatio));
  return 0;
}
