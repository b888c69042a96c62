#pragma once
// A sparse Cholesky factorization A = L Lᵀ of a symmetric positive definite matrix by CHOLMOD's
// supernodal method (SuiteSparse): the modal analysis's shift-invert factors K − σM once and solves with
// it tens of times. Dense blocks of the factor go through BLAS, so the factorization of a quadratic-tet
// stiffness matrix takes a half to a third of the time of a column-by-column (simplicial) one, and a solve
// with many right-hand sides costs a few solves with one. Private to the volume module.

#include <memory>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace shapedb::volume::detail {

/// A fill-reducing order for matrices of 3 × 3 blocks (a node's x, y, z, as FEM matrices are):
/// approximate minimum degree on the graph of the nodes, each node's three rows kept together; order[k] is
/// the row eliminated k-th. The same fill as AMD on the scalar graph, in a fraction of the analysis time
/// (the node graph has a ninth of the entries). Precondition: rows() divisible by 3.
std::vector<int> nodeBlockOrder(const Eigen::SparseMatrix<double>& matrix);

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Factorizes `matrix` (square, symmetric: its lower triangle is read) with its rows and columns taken
  /// in the order `order` (order[k] is the row eliminated k-th: a fill-reducing ordering; CHOLMOD's own
  /// approximate minimum degree when empty). False when it is not positive definite or the factorization
  /// fails (then solve must not be called).
  bool factorize(const Eigen::SparseMatrix<double>& matrix, const std::vector<int>& order = {});

  /// X = A⁻¹ B, for any number of columns of B (several at once share each pass over the factor), both
  /// column-major with rows() rows. Not thread-safe, not even two solves at once: they share CHOLMOD's
  /// scratch space. False (and X all NaN) if CHOLMOD could not allocate that space.
  bool solve(const double* b, double* x, Eigen::Index columns = 1) const;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;

  Eigen::Index rows() const { return mRows; }

 private:
  struct Impl;
  std::unique_ptr<Impl> mImpl;
  Eigen::Index mRows = 0;
};

}  // namespace shapedb::volume::detail
