// The sparse Cholesky factorization (CHOLMOD, supernodal or simplicial) of the modal analysis and the
// morph, against Eigen's dense LLᵀ.

#include <array>
#include <cmath>
#include <dlfcn.h>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

// A private header of the volume module (volume/src): this test reaches it on its include path.
#include "cholmod_memory_limit.h"
#include "sparse_cholesky.h"

namespace shapedb::volume::detail {
namespace {

constexpr std::array<CholeskyMethod, 3> kMethods{CholeskyMethod::kAuto, CholeskyMethod::kSimplicial,
                                                 CholeskyMethod::kSupernodal};

const char* name(CholeskyMethod method) {
  switch (method) {
    case CholeskyMethod::kAuto:
      return "auto";
    case CholeskyMethod::kSimplicial:
      return "simplicial";
    case CholeskyMethod::kSupernodal:
      return "supernodal";
  }
  return "?";
}

/// A symmetric positive definite matrix with the structure of an FEM matrix: 3 × 3 blocks coupling the
/// nodes of a grid of `side` × `side` × `length` nodes to their neighbours, random values, made definite by
/// its diagonal.
Eigen::SparseMatrix<double> gridMatrix(int side, std::mt19937_64& rng, int length = 0) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  if (length == 0) length = side;
  const int nx = length;
  const auto node = [side](int x, int y, int z) { return (x * side + y) * side + z; };
  std::vector<Eigen::Triplet<double>> entries;
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < side; ++y)
      for (int z = 0; z < side; ++z)
        for (int dx = 0; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
              if (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0))) continue;  // each pair once
              if (x + dx >= nx || y + dy < 0 || y + dy >= side || z + dz < 0 || z + dz >= side) continue;
              const int a = node(x, y, z), b = node(x + dx, y + dy, z + dz);
              for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                  const double v = value(rng);
                  entries.emplace_back(3 * a + i, 3 * b + j, v);
                  entries.emplace_back(3 * b + j, 3 * a + i, v);
                }
            }
  // Diagonally dominant: definite. (The diagonal goes in with the rest: inserting into a built sparse
  // matrix costs a pass over it per entry.)
  const int n = 3 * nx * side * side;
  std::vector<double> rowSum(static_cast<std::size_t>(n), 0.1);
  for (const Eigen::Triplet<double>& t : entries)
    rowSum[static_cast<std::size_t>(t.row())] += std::abs(t.value());
  for (int i = 0; i < n; ++i)
    entries.emplace_back(i, i, rowSum[static_cast<std::size_t>(i)]);
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(entries.begin(), entries.end());
  m.makeCompressed();
  return m;
}

/// A random elimination order of n rows.
std::vector<int> shuffledOrder(Eigen::Index n, std::mt19937_64& rng) {
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

TEST(SparseCholesky, SolvesAsTheDenseCholeskyForRandomMatricesOrdersAndRightHandSides) {
  std::mt19937_64 rng(5);
  for (const CholeskyMethod method : kMethods)
    for (int side : {2, 3, 5, 7}) {
      const Eigen::SparseMatrix<double> a = gridMatrix(side, rng);
      const Eigen::MatrixXd dense(a);
      const Eigen::LLT<Eigen::MatrixXd> oracle(dense);
      ASSERT_EQ(oracle.info(), Eigen::Success);
      // CHOLMOD's own ordering, and a random one given to it.
      const std::vector<int> order = shuffledOrder(a.rows(), rng);
      for (const std::vector<int>& given : {std::vector<int>{}, order}) {
        SparseCholesky cholesky(method);
        ASSERT_TRUE(cholesky.factorize(a, given)) << "side " << side << ", " << name(method);
        ASSERT_EQ(cholesky.rows(), a.rows());
        for (Eigen::Index columns : {1, 7}) {
          const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), columns);
          const Eigen::MatrixXd x = cholesky.solve(b);
          const Eigen::MatrixXd expected = oracle.solve(b);
          EXPECT_LT((x - expected).norm(), 1e-10 * expected.norm())
              << "side " << side << ", " << columns << " columns, " << (given.empty() ? "own" : "given")
              << " order, " << name(method);
        }
      }
    }
}

TEST(SparseCholesky, TheFactorsHalvesComposeTheInverse) {
  // A⁻¹ = H Hᵀ with H = solveFactorTransposed and Hᵀ = solveFactor, taken column by column of the
  // identity: what the modal analysis's symmetric shift-invert rests on. Hᵀ A H = I says the same
  // without the oracle.
  std::mt19937_64 rng(7);
  for (const CholeskyMethod method : kMethods)
    for (int side : {2, 3, 5}) {
      const Eigen::SparseMatrix<double> a = gridMatrix(side, rng);
      const Eigen::MatrixXd dense(a);
      const Eigen::MatrixXd inverse = dense.llt().solve(Eigen::MatrixXd::Identity(a.rows(), a.rows()));
      const std::vector<int> order = shuffledOrder(a.rows(), rng);
      for (const std::vector<int>& given : {std::vector<int>{}, order}) {
        SparseCholesky cholesky(method);
        ASSERT_TRUE(cholesky.factorize(a, given)) << "side " << side << ", " << name(method);
        const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(a.rows(), a.rows());
        Eigen::MatrixXd h(a.rows(), a.rows()), ht(a.rows(), a.rows());
        ASSERT_TRUE(cholesky.solveFactorTransposed(identity.data(), h.data(), a.rows()));
        ASSERT_TRUE(cholesky.solveFactor(identity.data(), ht.data(), a.rows()));
        const std::string what = "side " + std::to_string(side) + ", " + (given.empty() ? "own" : "given") +
                                 " order, " + name(method);
        EXPECT_LT((ht - h.transpose()).norm(), 1e-12 * h.norm()) << what;
        EXPECT_LT((h * h.transpose() - inverse).norm(), 1e-10 * inverse.norm()) << what;
        EXPECT_LT((h.transpose() * dense * h - identity).norm(), 1e-10 * identity.norm()) << what;
        // One column at a time gives the same as all at once.
        const Eigen::VectorXd b = Eigen::VectorXd::Random(a.rows());
        Eigen::VectorXd x(a.rows());
        ASSERT_TRUE(cholesky.solveFactor(b.data(), x.data()));
        EXPECT_LT((x - ht * b).norm(), 1e-12 * x.norm()) << what;
      }
    }
}

TEST(SparseCholesky, FourColumnsSolveAsCholmodSolvesThem) {
  // Four right-hand sides (the modal analysis's block) take a supernodal factor block by block without
  // CHOLMOD's solve (BlockSolves::kAuto); CHOLMOD's own (kCholmod) is the oracle. Grids up to 8 × 8 × 8
  // nodes give supernodes of hundreds of rows; a long bar, a long chain of small ones.
  std::mt19937_64 rng(11);
  for (const CholeskyMethod method : kMethods)
    for (const auto& [side, length] : {std::pair{2, 0}, {5, 0}, {8, 0}, {3, 40}}) {
      const Eigen::SparseMatrix<double> a = gridMatrix(side, rng, length);
      const std::vector<int> order = shuffledOrder(a.rows(), rng);
      for (const std::vector<int>& given : {std::vector<int>{}, order}) {
        SparseCholesky own(method), cholmod(method);
        cholmod.setBlockSolves(BlockSolves::kCholmod);
        ASSERT_TRUE(own.factorize(a, given)) << "side " << side << ", " << name(method);
        ASSERT_TRUE(cholmod.factorize(a, given)) << "side " << side << ", " << name(method);
        ASSERT_LE(own.factorNonzeros(), kBlockSolvesMaxNonzeros);
        const std::string what = "side " + std::to_string(side) + ", length " + std::to_string(length) +
                                 ", " + (given.empty() ? "own" : "given") + " order, " + name(method);
        const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 4);
        Eigen::MatrixXd x(a.rows(), 4), xt(a.rows(), 4), expected(a.rows(), 4), expectedT(a.rows(), 4);
        ASSERT_TRUE(own.solveFactor(b.data(), x.data(), 4));
        ASSERT_TRUE(own.solveFactorTransposed(b.data(), xt.data(), 4));
        ASSERT_TRUE(cholmod.solveFactor(b.data(), expected.data(), 4));
        ASSERT_TRUE(cholmod.solveFactorTransposed(b.data(), expectedT.data(), 4));
        EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm()) << what;
        EXPECT_LT((xt - expectedT).norm(), 1e-12 * expectedT.norm()) << what;
        // The right-hand sides may be overwritten by their solution.
        Eigen::MatrixXd inPlace = b;
        ASSERT_TRUE(own.solveFactor(inPlace.data(), inPlace.data(), 4));
        EXPECT_EQ(inPlace, x) << what;
        inPlace = b;
        ASSERT_TRUE(own.solveFactorTransposed(inPlace.data(), inPlace.data(), 4));
        EXPECT_EQ(inPlace, xt) << what;
      }
    }
}

TEST(SparseCholesky, ARefactorizationSolvesAsAFreshOne) {
  // Matrices of one pattern and new values, factorized again on the first one's analysis, solve as the
  // dense Cholesky of each; one that is not positive definite is refused, and leaves nothing to
  // refactorize.
  std::mt19937_64 rng(11);
  for (const CholeskyMethod method : kMethods)
    for (int side : {3, 6}) {
      SparseCholesky cholesky(method);
      ASSERT_FALSE(cholesky.refactorize(gridMatrix(side, rng))) << "nothing analysed yet";
      ASSERT_TRUE(cholesky.factorize(gridMatrix(side, rng), shuffledOrder(3 * side * side * side, rng)));
      for (int values = 0; values < 3; ++values) {
        const Eigen::SparseMatrix<double> a = gridMatrix(side, rng);
        ASSERT_TRUE(cholesky.refactorize(a)) << "side " << side << ", " << name(method);
        const Eigen::MatrixXd b = Eigen::MatrixXd::Random(a.rows(), 3);
        const Eigen::MatrixXd expected = Eigen::MatrixXd(a).llt().solve(b);
        EXPECT_LT((cholesky.solve(b) - expected).norm(), 1e-10 * expected.norm())
            << "side " << side << ", values " << values << ", " << name(method);
      }
      Eigen::SparseMatrix<double> indefinite = gridMatrix(side, rng);
      indefinite.coeffRef(4, 4) = -1e3;
      EXPECT_FALSE(cholesky.refactorize(indefinite)) << name(method);
      EXPECT_FALSE(cholesky.refactorize(gridMatrix(side, rng))) << "the failed factor is gone";
    }
}

TEST(SparseCholesky, AFactorizationOnAKeptAnalysisIsAFreshOneToTheBit) {
  // Matrices of one pattern and new values, factorized on one analysis made beforehand (analyze), solve
  // exactly as each factorized with its own analysis does, by either method, in a given order or CHOLMOD's;
  // threads factorizing on one shared analysis at once too. A matrix of another size is refused.
  std::mt19937_64 rng(13);
  for (const CholeskyMethod method : kMethods)
    for (int side : {3, 7}) {
      const Eigen::Index n = 3 * side * side * side;
      for (const bool given : {true, false}) {
        const std::vector<int> order = given ? shuffledOrder(n, rng) : std::vector<int>();
        const std::shared_ptr<const SymbolicFactor> analysis =
            SparseCholesky::analyze(gridMatrix(side, rng), order, method);
        ASSERT_NE(analysis, nullptr);
        EXPECT_EQ(analysis->rows(), n);
        std::vector<Eigen::SparseMatrix<double>> matrices;
        std::vector<Eigen::MatrixXd> rhs, fresh;
        for (int values = 0; values < 4; ++values) {
          matrices.push_back(gridMatrix(side, rng));
          rhs.push_back(Eigen::MatrixXd::Random(n, 4));
          SparseCholesky own(method);
          ASSERT_TRUE(own.factorize(matrices.back(), order));
          Eigen::MatrixXd x(n, 12);
          x.leftCols(4) = own.solve(rhs.back());
          ASSERT_TRUE(own.solveFactor(rhs.back().data(), x.middleCols(4, 4).data(), 4));
          ASSERT_TRUE(own.solveFactorTransposed(rhs.back().data(), x.rightCols(4).data(), 4));
          fresh.push_back(x);
        }
        const auto onAnalysis = [&](std::size_t i) {
          SparseCholesky kept(method);
          Eigen::MatrixXd x(n, 12);
          if (!kept.factorize(matrices[i], *analysis)) return Eigen::MatrixXd();
          x.leftCols(4) = kept.solve(rhs[i]);
          kept.solveFactor(rhs[i].data(), x.middleCols(4, 4).data(), 4);
          kept.solveFactorTransposed(rhs[i].data(), x.rightCols(4).data(), 4);
          return x;
        };
        std::vector<Eigen::MatrixXd> concurrent(matrices.size());
        std::vector<std::thread> threads;
        for (std::size_t i = 0; i < matrices.size(); ++i)
          threads.emplace_back([&, i] { concurrent[i] = onAnalysis(i); });
        for (std::thread& t : threads)
          t.join();
        for (std::size_t i = 0; i < matrices.size(); ++i) {
          EXPECT_EQ(onAnalysis(i), fresh[i]) << "side " << side << ", matrix " << i << ", " << name(method);
          EXPECT_EQ(concurrent[i], fresh[i]) << "side " << side << ", matrix " << i << ", concurrently";
        }
        SparseCholesky wrong(method);
        EXPECT_FALSE(wrong.factorize(gridMatrix(side + 1, rng), *analysis)) << name(method);
      }
    }
  EXPECT_EQ(SparseCholesky::analyze(gridMatrix(3, rng), std::vector<int>(5, 0)), nullptr)
      << "an order of the wrong size";
}

TEST(SparseCholesky, AnIndefiniteOrMalformedMatrixIsRefused) {
  for (const CholeskyMethod method : kMethods) {
    SCOPED_TRACE(name(method));
    std::mt19937_64 rng(6);
    Eigen::SparseMatrix<double> a = gridMatrix(3, rng);
    a.coeffRef(10, 10) = -1e3;  // a negative pivot
    SparseCholesky cholesky(method);
    EXPECT_FALSE(cholesky.factorize(a));
    EXPECT_EQ(cholesky.rows(), 0);
    Eigen::SparseMatrix<double> rectangular(6, 3);
    rectangular.makeCompressed();
    EXPECT_FALSE(cholesky.factorize(rectangular));
    const Eigen::SparseMatrix<double> b = gridMatrix(2, rng);
    EXPECT_FALSE(cholesky.factorize(b, {0, 1, 2})) << "an order of the wrong size";
    EXPECT_TRUE(cholesky.factorize(b)) << "the same object factorizes again";
  }
}

// Why a factorization failed: out of memory (its factor's size foreseen), not positive definite, or
// neither; and after a success, nothing.
TEST(SparseCholesky, AFailureSaysWhetherMemoryOrThePivotsRanOut) {
  for (const CholeskyMethod method : kMethods) {
    SCOPED_TRACE(name(method));
    std::mt19937_64 rng(16);
    const Eigen::SparseMatrix<double> large = gridMatrix(9, rng);  // 2,187 rows: a factor of megabytes
    SparseCholesky cholesky(method);
    {
      const test::CholmodMemoryLimit limit(std::size_t{1} << 20);  // refuses the numeric factor's blocks
      EXPECT_FALSE(cholesky.factorize(large));
    }
    EXPECT_EQ(cholesky.failure(), SparseCholesky::Failure::kOutOfMemory);
    EXPECT_GT(8.0 * cholesky.factorNonzeros(), 1048576.0);  // the numeric factor ran out
    ASSERT_TRUE(cholesky.factorize(large)) << "with the memory back";
    EXPECT_EQ(cholesky.failure(), SparseCholesky::Failure::kNone);

    Eigen::SparseMatrix<double> indefinite = gridMatrix(3, rng);
    indefinite.coeffRef(10, 10) = -1e3;
    EXPECT_FALSE(cholesky.factorize(indefinite));
    EXPECT_EQ(cholesky.failure(), SparseCholesky::Failure::kNotPositiveDefinite);
    Eigen::SparseMatrix<double> rectangular(6, 3);
    rectangular.makeCompressed();
    EXPECT_FALSE(cholesky.factorize(rectangular));
    EXPECT_EQ(cholesky.failure(), SparseCholesky::Failure::kOther);
  }
}

// kAuto: column by column where the factor stays sparse (a slender bar of nodes), by dense blocks where it
// fills in (a cube of them); a forced method is the method used.
TEST(SparseCholesky, TheAutomaticMethodFollowsTheFactorsDensity) {
  std::mt19937_64 rng(8);
  const Eigen::SparseMatrix<double> bar = gridMatrix(2, rng, 200), cube = gridMatrix(12, rng);
  SparseCholesky automatic;
  ASSERT_TRUE(automatic.factorize(bar));
  EXPECT_FALSE(automatic.supernodal());
  ASSERT_TRUE(automatic.factorize(cube, nodeBlockOrder(cube)));
  EXPECT_TRUE(automatic.supernodal());
  for (const CholeskyMethod method : {CholeskyMethod::kSimplicial, CholeskyMethod::kSupernodal}) {
    SparseCholesky forced(method);
    ASSERT_TRUE(forced.factorize(bar));
    EXPECT_EQ(forced.supernodal(), method == CholeskyMethod::kSupernodal) << name(method);
  }
}

// A threaded OpenBLAS, where it is the BLAS loaded, runs on the calling thread alone once a factorization
// has been set up: its own threads would contend with the build's workers (sparse_cholesky.cpp).
TEST(SparseCholesky, AThreadedOpenBlasIsKeptToOneThread) {
  using Query = int (*)();
  const auto parallel = reinterpret_cast<Query>(::dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
  const auto threads = reinterpret_cast<Query>(::dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!parallel || !threads || parallel() != 1)
    GTEST_SKIP() << "the BLAS loaded is not an OpenBLAS with threads of its own";
  std::mt19937_64 rng(9);
  const Eigen::SparseMatrix<double> cube = gridMatrix(8, rng);
  SparseCholesky cholesky(CholeskyMethod::kSupernodal);
  ASSERT_TRUE(cholesky.factorize(cube));
  EXPECT_EQ(threads(), 1);
}

// The database build factorizes on every worker thread at once, through whichever BLAS the system has:
// each thread's results must be those of the same work done alone.
TEST(SparseCholesky, ConcurrentFactorizationsAndSolvesEqualSerialOnes) {
  constexpr int kThreads = 4, kMatrices = 3;
  std::vector<Eigen::SparseMatrix<double>> matrices;
  std::vector<Eigen::MatrixXd> rhs;
  std::mt19937_64 rng(7);
  for (int i = 0; i < kThreads * kMatrices; ++i) {
    matrices.push_back(gridMatrix(7 + i % 2, rng));  // 1,029 or 1,536 rows: supernodes go through BLAS
    rhs.push_back(Eigen::MatrixXd::Random(matrices.back().rows(), 3));
  }
  const auto solveAll = [&](int first, int step, std::vector<Eigen::MatrixXd>& out) {
    for (std::size_t i = static_cast<std::size_t>(first); i < matrices.size();
         i += static_cast<std::size_t>(step)) {
      SparseCholesky cholesky(CholeskyMethod::kSupernodal);
      out[i] = cholesky.factorize(matrices[i]) ? cholesky.solve(rhs[i]) : Eigen::MatrixXd();
    }
  };
  std::vector<Eigen::MatrixXd> serial(matrices.size()), concurrent(matrices.size());
  solveAll(0, 1, serial);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] { solveAll(t, kThreads, concurrent); });
  for (std::thread& t : threads)
    t.join();
  for (std::size_t i = 0; i < matrices.size(); ++i) {
    ASSERT_GT(serial[i].size(), 0) << "matrix " << i;
    EXPECT_EQ(concurrent[i], serial[i]) << "matrix " << i;
  }
}

}  // namespace
}  // namespace shapedb::volume::detail
