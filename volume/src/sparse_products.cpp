#include "sparse_products.h"

#include <algorithm>
#include <array>
#include <vector>

namespace shapedb::volume::detail {
namespace {

/// Y's columns [first, first + W) of A X: X's W columns copied row by row first, so that a row of them
/// is W doubles side by side, which the inner loop multiplies by one entry of A (vector instructions).
template <int W>
void productOfColumns(const Eigen::SparseMatrix<double>& a, const double* x, double* y, Eigen::Index first,
                      std::vector<double>& rows) {
  const Eigen::Index n = a.rows();
  rows.resize(static_cast<std::size_t>(n * W));
  for (Eigen::Index c = 0; c < W; ++c) {
    const double* column = x + (first + c) * n;
    for (Eigen::Index i = 0; i < n; ++i)
      rows[static_cast<std::size_t>(i * W + c)] = column[i];
  }
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  for (Eigen::Index j = 0; j < n; ++j) {
    double sum[W] = {};
    for (int p = outer[j]; p < outer[j + 1]; ++p) {
      const double v = values[p];
      const double* row = rows.data() + static_cast<std::ptrdiff_t>(inner[p]) * W;
      for (int c = 0; c < W; ++c)
        sum[c] += v * row[c];
    }
    for (Eigen::Index c = 0; c < W; ++c)
      y[(first + c) * n + j] = sum[c];
  }
}

}  // namespace

void symmetricProduct(const Eigen::SparseMatrix<double>& a, const double* x, double* y,
                      Eigen::Index columns) {
  // Eight columns at a time at most: their rows (64 bytes each) and the sums stay in registers and cache.
  using Kernel = void (*)(const Eigen::SparseMatrix<double>&, const double*, double*, Eigen::Index,
                          std::vector<double>&);
  static constexpr std::array<Kernel, 8> kKernels{
      &productOfColumns<1>, &productOfColumns<2>, &productOfColumns<3>, &productOfColumns<4>,
      &productOfColumns<5>, &productOfColumns<6>, &productOfColumns<7>, &productOfColumns<8>};
  std::vector<double> rows;
  for (Eigen::Index first = 0; first < columns;) {
    const Eigen::Index width = std::min<Eigen::Index>(8, columns - first);
    kKernels[static_cast<std::size_t>(width - 1)](a, x, y, first, rows);
    first += width;
  }
}

Eigen::MatrixXd symmetricProduct(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& x) {
  Eigen::MatrixXd y(a.rows(), x.cols());
  symmetricProduct(a, x.data(), y.data(), x.cols());
  return y;
}

}  // namespace shapedb::volume::detail
