// The modal analysis's factorization (volume/src/sparse_cholesky.h) on the quadratic-tet matrices K − σM of
// database entries: Eigen's simplicial LDLᵀ (the first solver, the baseline), and CHOLMOD's LLᵀ by each of
// its methods, simplicial and supernodal, with the one SparseCholesky's automatic choice takes (its
// threshold depends on the processor and the BLAS loaded: Debian's alternatives choose it; LD_LIBRARY_PATH,
// say /usr/lib/x86_64-linux-gnu/blis-serial:/usr/lib/x86_64-linux-gnu/lapack, overrides them). For one entry
// of each family: the degrees of freedom, each solver's factorization, one solve, one solve with 4
// right-hand sides (CHOLMOD's: the seeded modal analysis's block) and one with 20 (milliseconds, best of
// three), and how far the automatic choice's solution is from
// Eigen's. Then the factor's two halves (solveFactorTransposed, solveFactor: what a step of the seeded
// modal analysis takes) for a block of 4 right-hand sides on the supernodal factor, by SparseCholesky's
// own loops (BlockSolves::kAuto, where the factor is small enough for them) and by CHOLMOD's solve. Each
// factorization includes its analysis: Eigen's with its AMD on the scalar graph, CHOLMOD's with the
// node-block order the modal analysis gives it. Run it on one core (taskset -c 0): the build runs one
// factorization per core.
//   build/release/bin/factorization_bench DB [--per-family N]

#include <algorithm>
#include <array>
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
      "| entry | dof | Eigen simplicial: factor | solve | 20 solves | CHOLMOD simplicial: factor | solve "
      "| 4 solves | 20 solves | CHOLMOD supernodal: factor | solve | 4 solves | 20 solves | automatic choice "
      "| "
      "relative difference | factor nonzeros | 4-column halves: own | CHOLMOD |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n");
  std::map<std::string, int> taken;
  std::array<std::vector<double>, 2> blockRatio;  // over simplicial, over supernodal
  std::vector<double> halvesRatio;                // own block solves over CHOLMOD's, where own are taken
  for (const io::EntryRecord& record : db->entries()) {
    if (taken[volume::toString(record.family)]++ >= perFamily) continue;
    auto physics = db->physics(record.id);
    if (!physics) continue;
    const volume::FemMatrices fem = volume::assembleFem(volume::makeQuadratic((*physics)->tetMesh));
    const double scale = fem.stiffness.diagonal().sum() / fem.mass.diagonal().sum();
    Eigen::SparseMatrix<double> a = fem.stiffness + 1e-6 * scale * fem.mass;  // σ as the modal analysis's
    a.makeCompressed();
    const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 20);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> eigen;
    const double f0 = bestOfThree([&] { eigen.compute(a); });
    Eigen::MatrixXd x0, x;
    const double s0 = bestOfThree([&] { x0 = eigen.solve(b.col(0)); });
    const double m0 = bestOfThree([&] { x0 = eigen.solve(b); });
    std::printf("| %s | %ld | %.1f | %.2f | %.1f", record.name.c_str(), static_cast<long>(a.rows()), f0, s0,
                m0);
    const std::vector<int> order = volume::detail::nodeBlockOrder(a);  // as the modal analysis orders
    std::array<double, 2> factor{}, single{};
    // The supernodal factor's two halves for four columns, by the own loops and by CHOLMOD's solve.
    double ownHalves = 0.0, cholmodHalves = 0.0, supernodalNonzeros = 0.0;
    for (const auto method :
         {volume::detail::CholeskyMethod::kSimplicial, volume::detail::CholeskyMethod::kSupernodal}) {
      volume::detail::SparseCholesky cholesky(method);
      const double f = bestOfThree([&] { cholesky.factorize(a, order); });
      const double s1 = bestOfThree([&] { x = cholesky.solve(Eigen::MatrixXd(b.col(0))); });
      const double s4 = bestOfThree([&] { x = cholesky.solve(Eigen::MatrixXd(b.leftCols(4))); });
      const double m = bestOfThree([&] { x = cholesky.solve(b); });
      std::printf(" | %.1f | %.2f | %.2f | %.1f", f, s1, s4, m);
      const std::size_t k = method == volume::detail::CholeskyMethod::kSupernodal ? 1 : 0;
      factor[k] = f;
      single[k] = s1;
      if (method == volume::detail::CholeskyMethod::kSupernodal) {
        const Eigen::MatrixXd b4 = b.leftCols(4);
        Eigen::MatrixXd h4(a.rows(), 4), y4(a.rows(), 4);
        const auto halves = [&] {
          cholesky.solveFactorTransposed(b4.data(), h4.data(), 4);
          cholesky.solveFactor(h4.data(), y4.data(), 4);
        };
        ownHalves = bestOfThree(halves);
        cholesky.setBlockSolves(volume::detail::BlockSolves::kCholmod);
        cholmodHalves = bestOfThree(halves);
        supernodalNonzeros = cholesky.factorNonzeros();
      }
    }
    volume::detail::SparseCholesky automatic;
    automatic.factorize(a, order);
    const Eigen::MatrixXd xa = automatic.solve(b);
    const std::size_t chosen = automatic.supernodal() ? 1 : 0;
    std::printf(" | %s | %.1e", chosen ? "supernodal" : "simplicial", (x0 - xa).norm() / x0.norm());
    const bool ownSolves = supernodalNonzeros <= volume::detail::kBlockSolvesMaxNonzeros;
    std::printf(" | %.0f | %.3f%s | %.3f |\n", supernodalNonzeros, ownHalves, ownSolves ? "" : " (CHOLMOD's)",
                cholmodHalves);
    if (ownSolves) halvesRatio.push_back(ownHalves / cholmodHalves);
    // What the choice gains over either method alone for the modal analysis's use of a factorization: it
    // and ~64 solves.
    for (std::size_t k = 0; k < 2; ++k)
      blockRatio[k].push_back((factor[k] + 64 * single[k]) / (factor[chosen] + 64 * single[chosen]));
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  std::printf(
      "\nmedian speedup of the automatic choice on a factorization and 64 "
      "solves: %.2fx over the simplicial method alone, %.2fx over the supernodal one\n",
      median(blockRatio[0]), median(blockRatio[1]));
  std::printf(
      "median time of a 4-column solve's halves by SparseCholesky's own loops, over CHOLMOD's, where "
      "they are taken: %.2f (%zu entries)\n",
      median(halvesRatio), halvesRatio.size());
  return 0;
}
