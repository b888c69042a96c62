// The one-pass products of the FEM matrices with blocks of vectors, against Eigen's own product.

#include <random>
#include <vector>

#include <gtest/gtest.h>

// A private header of the volume module (volume/src): this test reaches it on its include path.
#include "sparse_products.h"

namespace shapedb::volume::detail {
namespace {

/// A random symmetric matrix of n rows with both triangles stored, about `perColumn` entries a column
/// besides its diagonal, some columns empty but for it.
Eigen::SparseMatrix<double> randomSymmetric(Eigen::Index n, int perColumn, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::uniform_int_distribution<Eigen::Index> row(0, n - 1);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j = 0; j < n; ++j) {
    entries.emplace_back(j, j, value(rng));
    for (int k = 0; k < perColumn / 2; ++k) {
      const Eigen::Index i = row(rng);
      const double v = value(rng);
      entries.emplace_back(i, j, v);
      if (i != j) entries.emplace_back(j, i, v);
    }
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  a.makeCompressed();
  return a;
}

TEST(SparseProducts, SymmetricProductAgreesWithEigensForAnyNumberOfColumns) {
  std::mt19937_64 rng(20261129);
  for (const Eigen::Index n : {1, 7, 300}) {
    const Eigen::SparseMatrix<double> a = randomSymmetric(n, 12, rng);
    ASSERT_TRUE(a.isApprox(Eigen::SparseMatrix<double>(a.transpose()))) << "the test's matrix is symmetric";
    for (const Eigen::Index columns : {1, 2, 3, 4, 5, 6, 7, 8, 9, 13, 20}) {
      const Eigen::MatrixXd x = Eigen::MatrixXd::Random(n, columns);
      const Eigen::MatrixXd expected = a * x;
      const Eigen::MatrixXd y = symmetricProduct(a, x);
      ASSERT_EQ(y.rows(), n);
      ASSERT_EQ(y.cols(), columns);
      EXPECT_LE((y - expected).cwiseAbs().maxCoeff(), 1e-13 * std::max(1.0, expected.cwiseAbs().maxCoeff()))
          << n << " rows, " << columns << " columns";
    }
  }
}

TEST(SparseProducts, SymmetricProductOfNoColumnsIsEmpty) {
  std::mt19937_64 rng(7);
  const Eigen::SparseMatrix<double> a = randomSymmetric(10, 4, rng);
  EXPECT_EQ(symmetricProduct(a, Eigen::MatrixXd(10, 0)).cols(), 0);
}

}  // namespace
}  // namespace shapedb::volume::detail
