#pragma once
// A sparse Cholesky factorization A = L Lᵀ of a symmetric positive definite matrix by CHOLMOD
// (SuiteSparse): the modal analysis's shift-invert factors K − σM once and solves with it tens of times,
// and the morph's registration factors one system per round. Two methods, chosen per matrix once its
// ordering has been analysed: supernodal, where the factor's dense blocks go through BLAS (with OpenBLAS
// about a third of the time of a column-by-column factorization for the compact, heavy entries: rings,
// shells, stones, unions, limbed bodies), and simplicial, column by column, where the factor is sparse (the
// most slender entries, and small matrices) and the BLAS calls on small blocks would cost more than their
// arithmetic. The first one made in a process keeps a threaded OpenBLAS to one thread
// (sparse_cholesky.cpp). Private to the volume module.

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

/// How SparseCholesky factorizes: kAuto chooses by the factor's density, the others force a method (for
/// tests and the factorization bench).
enum class CholeskyMethod { kAuto, kSimplicial, kSupernodal };

/// kAuto's threshold: supernodal where the factorization's flops per entry of the factor (CHOLMOD's fl /
/// lnz, known after the analysis) reach it. It depends on the BLAS the supernodal method's dense blocks go
/// through and on the processor, measured on the default catalog's entries, for a factorization alone and
/// with the ~50 solves the modal analysis makes: with OpenBLAS (the one scripts/setup.sh installs: its
/// cost per call on small blocks is low), 135 on an AMD EPYC
/// (bench/results/epyc-2core/factorization_2026-11-28.md) and CHOLMOD's own default, 40, on an Intel Xeon,
/// where the supernodal method factorizes the slender entries 1.5-2× faster than on the EPYC and the
/// simplicial one no faster (bench/results/xeon-2core/supernodal_switch_2026-11-29.md), and on an AMD
/// EPYC of the Zen 5 family, where 40 took a geometry correction's median 9 % lower than 135 and left a
/// database build's time as it was (bench/results/zen5-2core/supernodal_switch_2026-11-30.md): Intel
/// processors and AMD ones from Zen 5 on take 40, any other 135. With any other BLAS (BLIS, the reference
/// BLAS: the slender entries and the registration's systems, 74-152, are then 1.5-6× faster column by
/// column), 175.
double supernodalSwitch();

/// How solveFactor and solveFactorTransposed take four right-hand sides, the seeded modal analysis's block.
/// kAuto: the supernodal factor block by block with loops of their own, where it has at most
/// kBlockSolvesMaxNonzeros (CHOLMOD otherwise); kCholmod: always CHOLMOD's solve (the tests' oracle, and
/// the factorization bench's comparison).
///
/// Why: with four columns CHOLMOD's supernodal solve hands each supernode to BLAS (dtrsm, dgemm), and
/// OpenBLAS copies the supernode's block into its own layout on every call (about half the solves' time in
/// a profile of the correction). The loops here read each block once, each row of the four right-hand
/// sides one 4-vector: a solve's two halves took a median 0.57-0.58 of CHOLMOD's time (0.51-0.68) on the
/// default catalog's entries of up to 2 million nonzeros in the factor, and 0.9-1.2 times on factors from
/// 2.5 million on, which no longer fit in the processor's caches and which BLAS's blocking serves better
/// (`factorization_bench`, bench/results/zen5-2core/block_solves_2026-11-30/).
enum class BlockSolves { kAuto, kCholmod };

/// The largest factor (CHOLMOD's lnz) whose four-column solves kAuto takes itself: the loops were still
/// faster at 2.3 million nonzeros and as fast as CHOLMOD at 2.5 million (measured before the forward half
/// took four columns at a time).
inline constexpr double kBlockSolvesMaxNonzeros = 2.0e6;

/// The symbolic half of a factorization, kept to factorize other matrices of the same sparsity pattern on
/// it (SparseCholesky::analyze): the fill-reducing order, the elimination tree, the factor's structure and
/// its method, all of which depend on the pattern alone. The geometry correction factorizes the K − σM of
/// one database entry's tets, moved, at every query that entry answers; the analysis was a third of that
/// factorization's time. Immutable once made: shared among threads.
class SymbolicFactor {
 public:
  ~SymbolicFactor();
  SymbolicFactor(const SymbolicFactor&) = delete;
  SymbolicFactor& operator=(const SymbolicFactor&) = delete;
  /// The rows and stored entries of the matrix analysed: a matrix factorized on it must have as many.
  Eigen::Index rows() const { return mRows; }
  Eigen::Index nonZeros() const { return mNonZeros; }

 private:
  friend class SparseCholesky;
  struct Impl;
  explicit SymbolicFactor(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> mImpl;
  Eigen::Index mRows = 0, mNonZeros = 0;
};

class SparseCholesky {
 public:
  explicit SparseCholesky(CholeskyMethod method = CholeskyMethod::kAuto);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Factorizes `matrix` (square, symmetric, both triangles stored, as FEM matrices are assembled: the
  /// simplicial method reads the lower, the supernodal one the upper) with its rows and columns taken
  /// in the order `order` (order[k] is the row eliminated k-th: a fill-reducing ordering; CHOLMOD's own
  /// approximate minimum degree when empty). False when it is not positive definite or the factorization
  /// fails (then solve must not be called).
  bool factorize(const Eigen::SparseMatrix<double>& matrix, const std::vector<int>& order = {});
  /// Factorizes `matrix` again on the last factorize's symbolic analysis (its order, its method): for
  /// matrices of one sparsity pattern and changing values, such as the morph's registration rounds.
  /// Precondition: `matrix` has the sparsity pattern of the matrix last factorized. False, as factorize,
  /// when it is not positive definite, and when there is no factor to start from.
  bool refactorize(const Eigen::SparseMatrix<double>& matrix);

  /// The symbolic analysis factorize(matrix, order) makes, by itself, for factorize(matrix, analysis) on
  /// this matrix and others of its pattern; null where it fails (out of memory, a malformed matrix, an order
  /// of the wrong size).
  static std::shared_ptr<const SymbolicFactor> analyze(const Eigen::SparseMatrix<double>& matrix,
                                                       const std::vector<int>& order = {},
                                                       CholeskyMethod method = CholeskyMethod::kAuto);
  /// Factorizes `matrix` on `analysis` (made by analyze of a matrix of the same sparsity pattern, which is
  /// the caller's to ensure): the same factor as factorize(matrix, order) with analyze's order and method,
  /// to the bit, without the analysis. False as factorize, and when `matrix` has other dimensions or another
  /// number of entries than the matrix analysed.
  bool factorize(const Eigen::SparseMatrix<double>& matrix, const SymbolicFactor& analysis);

  /// X = A⁻¹ B, for any number of columns of B (several at once share each pass over the factor), both
  /// column-major with rows() rows. Not thread-safe, not even two solves at once: they share CHOLMOD's
  /// scratch space. False (and X all NaN) if CHOLMOD could not allocate that space.
  bool solve(const double* b, double* x, Eigen::Index columns = 1) const;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;

  /// The factor's halves. CHOLMOD factorizes P A Pᵀ = L Lᵀ (P the fill-reducing permutation), so A⁻¹ = H Hᵀ
  /// with H = Pᵀ L⁻ᵀ: solveFactor gives X = Hᵀ B = L⁻¹ P B, solveFactorTransposed X = H B = Pᵀ L⁻ᵀ B, each
  /// half the work of a solve. What turns A⁻¹ M x = μ x into the symmetric Hᵀ M H y = μ y (x = H y).
  /// Same contract as solve; four columns may be solved without CHOLMOD (BlockSolves), to the same
  /// values up to round-off.
  bool solveFactor(const double* b, double* x, Eigen::Index columns = 1) const;
  bool solveFactorTransposed(const double* b, double* x, Eigen::Index columns = 1) const;

  void setBlockSolves(BlockSolves blockSolves) { mBlockSolves = blockSolves; }

  Eigen::Index rows() const { return mRows; }
  /// Why the last factorize or refactorize returned false (kNone after one that succeeded).
  enum class Failure { kNone, kNotPositiveDefinite, kOutOfMemory, kOther };
  Failure failure() const { return mFailure; }
  /// The nonzeros of the factor the last analysis foresaw (CHOLMOD's lnz): 8 bytes each at least, what a
  /// factorization that ran out of memory needed.
  double factorNonzeros() const { return mFactorNonzeros; }
  /// Whether the last successful factorize was supernodal (else simplicial).
  bool supernodal() const;

 private:
  /// The numeric factorization on the analysis in place (refactorize's work); its caller holds CHOLMOD's
  /// call guard.
  bool factorizeNumerically(const Eigen::SparseMatrix<double>& matrix);
  /// One CHOLMOD solve of `system` (CHOLMOD_A, _P, _L, _Lt, _Pt) with b's columns into x: false (and x all
  /// NaN) if there is no factor or CHOLMOD could not allocate its scratch space, which it reuses from one
  /// call to the next. x may be b.
  bool solveSystem(int system, const double* b, double* x, Eigen::Index columns) const;
  /// Whether solveFactor and solveFactorTransposed of `columns` right-hand sides take the supernodal
  /// factor block by block themselves instead of CHOLMOD.
  bool blockSolves(Eigen::Index columns) const;
  /// solveFactor (or, `transposed`, solveFactorTransposed) of four columns, where blockSolves.
  void solveFourColumns(bool transposed, const double* b, double* x) const;
  struct Impl;
  std::unique_ptr<Impl> mImpl;
  Eigen::Index mRows = 0;
  Failure mFailure = Failure::kNone;
  double mFactorNonzeros = 0.0;
  BlockSolves mBlockSolves = BlockSolves::kAuto;
};

}  // namespace shapedb::volume::detail
