#pragma once
// Products of the FEM matrices with blocks of vectors: the modal analysis multiplies K, M and K − σM by
// four to twenty vectors at once (the block Lanczos's steps, the rigid motions, the seeds, the modes).
// Eigen's sparse × dense product passes over the sparse matrix once per column of the block; these pass
// once for all of them. Private to the volume module.

#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace shapedb::volume::detail {

/// Y = A X for a symmetric A stored with both triangles (as the FEM matrices are assembled) and X of
/// `columns` columns, both column-major with A.rows() rows. A = Aᵀ, so each of A's stored columns is
/// also a row: Y's row j is that column's entries times X's rows, every entry of A read once and used for
/// all the columns. Precondition: A is compressed and symmetric (only its stored entries are read; a
/// matrix that is not symmetric gets Aᵀ X). y must not overlap x.
void symmetricProduct(const Eigen::SparseMatrix<double>& a, const double* x, double* y, Eigen::Index columns);
Eigen::MatrixXd symmetricProduct(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& x);

}  // namespace shapedb::volume::detail
