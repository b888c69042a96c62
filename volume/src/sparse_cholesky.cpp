#include "sparse_cholesky.h"

#include <algorithm>
#include <cholmod.h>
#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif
#include <cstring>
#include <dlfcn.h>
#include <limits>
#include <mutex>

#include <Eigen/OrderingMethods>

namespace shapedb::volume::detail {
namespace {

/// OpenBLAS's build, if OpenBLAS is the BLAS loaded (openblas_get_parallel: 0 sequential, 1 its own
/// threads, 2 OpenMP's); null for any other BLAS.
using Query = int (*)();
Query openBlasParallel() {
  static const auto query = reinterpret_cast<Query>(::dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
  return query;
}

/// CHOLMOD's dense blocks go through whichever BLAS and LAPACK the system provides. Most are safe to call
/// from several threads at once (the reference ones, BLIS, OpenBLAS built for threads); a sequential
/// OpenBLAS built without locking (Debian's libopenblas0-serial) is not: concurrent factorizations then
/// fail at random, or worse. Where that library is the one loaded, the factorizations and solves of all
/// threads take turns; elsewhere this lock is never taken.
std::mutex* blasLock() {
  static std::mutex* const lock = []() -> std::mutex* {
    const Query parallel = openBlasParallel();
    return parallel && parallel() == 0 ? new std::mutex : nullptr;
  }();
  return lock;
}

/// An OpenBLAS built with threads of its own (Debian's libopenblas0-pthread, the one scripts/setup.sh
/// installs) runs a large dense block on as many threads as there are cores. shapedb's callers already run
/// one factorization per core (a build's workers, a query's candidates), which those threads would only
/// contend with, and the haptic loop's core would lose its own. OpenBLAS has no setting per calling
/// thread, so the first SparseCholesky sets it to one thread for the whole process: other code of the
/// process that calls the same OpenBLAS (NumPy, where it shares the system's BLAS) then runs on one thread
/// too (docs/architecture.md). An OpenMP OpenBLAS is kept to the calling thread by SerialOpenMp.
void oneOpenBlasThread() {
  static const bool done = [] {
    const auto set = reinterpret_cast<void (*)(int)>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    const Query parallel = openBlasParallel();
    if (set && parallel && parallel() == 1) set(1);
    return true;
  }();
  static_cast<void>(done);
}

/// Debian's CHOLMOD runs parts of a large factorization in OpenMP parallel regions of up to four threads.
/// Its callers already run one factorization per core (a build's workers), so those threads only fight
/// them: a 2-thread build of 112 entries took 29.0 s with them and 26.1 s without. OpenMP's
/// max-active-levels is a per-thread setting; 0 runs this thread's parallel regions on this thread
/// alone, and the previous value comes back when the call is over. Found at run time, as the OpenMP
/// runtime CHOLMOD was built with (none: nothing to do).
class SerialOpenMp {
 public:
  SerialOpenMp() {
    if (functions().set) {
      mPrevious = functions().get();
      functions().set(0);
    }
  }
  ~SerialOpenMp() {
    if (functions().set) functions().set(mPrevious);
  }
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;

 private:
  struct Functions {
    int (*get)() = nullptr;
    void (*set)(int) = nullptr;
  };
  static const Functions& functions() {
    static const Functions f = [] {
      Functions found;
      found.get = reinterpret_cast<int (*)()>(::dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
      found.set = reinterpret_cast<void (*)(int)>(::dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
      if (!found.get || !found.set) found = {};
      return found;
    }();
    return f;
  }
  int mPrevious = 1;
};

/// What every call into CHOLMOD holds: the BLAS lock where one is needed, and OpenMP kept to this thread.
struct CallGuard {
  std::unique_lock<std::mutex> blas = [] {
    std::mutex* lock = blasLock();
    return lock ? std::unique_lock<std::mutex>(*lock) : std::unique_lock<std::mutex>();
  }();
  SerialOpenMp openMp;
};

#if defined(__x86_64__) || defined(__i386__)
/// The processor's family as CPUID reports it (the base family, plus the extended one where the base is
/// 15); 0 where it cannot be read.
unsigned cpuFamily() {
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (__get_cpuid(1, &a, &b, &c, &d) == 0) return 0;
  const unsigned base = (a >> 8) & 0xFu;
  return base == 0xFu ? base + ((a >> 20) & 0xFFu) : base;
}
#endif

}  // namespace

double supernodalSwitch() {
  // The header says where these were measured.
  constexpr double kOpenBlasSmallBlocks = 40.0, kOpenBlas = 135.0, kOtherBlas = 175.0;
  if (!openBlasParallel()) return kOtherBlas;
#if defined(__x86_64__) || defined(__i386__)
  constexpr unsigned kZen5 = 0x1A;
  if (__builtin_cpu_is("intel") || (__builtin_cpu_is("amd") && cpuFamily() >= kZen5))
    return kOpenBlasSmallBlocks;
#endif
  return kOpenBlas;
}

std::vector<int> nodeBlockOrder(const Eigen::SparseMatrix<double>& matrix) {
  const Eigen::Index nodes = matrix.rows() / 3;
  std::vector<Eigen::Triplet<double, int>> pattern;
  pattern.reserve(static_cast<std::size_t>(matrix.nonZeros() / 9 + nodes));
  for (Eigen::Index column = 0; column < matrix.outerSize(); column += 3)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix, column); it; ++it)
      if (it.row() % 3 == 0)
        pattern.emplace_back(static_cast<int>(it.row() / 3), static_cast<int>(column / 3), 1.0);
  Eigen::SparseMatrix<double> graph(nodes, nodes);
  graph.setFromTriplets(pattern.begin(), pattern.end());
  // Eigen's orderings return the inverse permutation: its k-th index is the node eliminated k-th.
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> nodeOrder;
  Eigen::AMDOrdering<int>()(graph, nodeOrder);
  std::vector<int> order(static_cast<std::size_t>(3 * nodes));
  for (Eigen::Index i = 0; i < nodes; ++i)
    for (int c = 0; c < 3; ++c)
      order[static_cast<std::size_t>(3 * i + c)] = 3 * nodeOrder.indices()[i] + c;
  return order;
}

namespace {

/// Starts CHOLMOD's `common` for factorizations by `method`.
void startCommon(cholmod_common& common, CholeskyMethod method) {
  oneOpenBlasThread();
  cholmod_start(&common);
  common.print = 0;  // errors are returned to the caller, not printed
  // LLᵀ by either method, so that a matrix that is not positive definite is refused by both (a
  // simplicial LDLᵀ would go on through an indefinite one).
  common.final_ll = 1;
  switch (method) {
    case CholeskyMethod::kAuto:
      common.supernodal = CHOLMOD_AUTO;
      common.supernodal_switch = supernodalSwitch();
      break;
    case CholeskyMethod::kSimplicial:
      common.supernodal = CHOLMOD_SIMPLICIAL;
      break;
    case CholeskyMethod::kSupernodal:
      common.supernodal = CHOLMOD_SUPERNODAL;
      break;
  }
  common.quick_return_if_not_posdef = 1;
}

}  // namespace

/// CHOLMOD's state: its workspace (`common`), the factor, and the dense buffers cholmod_solve2 reuses from
/// one solve to the next (mutable: a solve changes no result, only scratch space).
struct SparseCholesky::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  mutable cholmod_dense* x = nullptr;
  mutable cholmod_dense* y = nullptr;
  mutable cholmod_dense* e = nullptr;
  /// The four-column solves' workspace (blockSolves): the right-hand sides row by row, one supernode's rows.
  mutable std::vector<Eigen::Vector4d> rows, gathered;

  explicit Impl(CholeskyMethod method) { startCommon(common, method); }
  ~Impl() {
    freeFactor();
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  void freeFactor() {
    if (factor) cholmod_free_factor(&factor, &common);
    for (cholmod_dense** d : {&x, &y, &e})
      if (*d) cholmod_free_dense(d, &common);
  }
};

namespace {

/// The supernodes of CHOLMOD's supernodal LLᵀ factor: supernode s is columns super[s] to super[s + 1] − 1,
/// its rows s[pi[s]] to s[pi[s + 1] − 1] (its own columns first, the diagonal block's), its values the
/// column-major block of those rows and columns at x + px[s].
struct Supernodes {
  explicit Supernodes(const cholmod_factor& f)
      : count(f.nsuper),
        super(static_cast<const int*>(f.super)),
        pi(static_cast<const int*>(f.pi)),
        px(static_cast<const int*>(f.px)),
        rows(static_cast<const int*>(f.s)),
        values(static_cast<const double*>(f.x)) {}
  std::size_t count;
  const int *super, *pi, *px, *rows;
  const double* values;
};

/// L X = X for four right-hand sides, each row of X one Vector4d: supernode by supernode, the diagonal
/// block's triangle solved, then its columns' part of the rows below subtracted (gathered in `below`).
/// Four columns at a time, each row below updated once from all four: a row's 4-vector read and written
/// once per four columns instead of once per column.
void forwardSolve(const Supernodes& l, std::vector<Eigen::Vector4d>& x, std::vector<Eigen::Vector4d>& below) {
  for (std::size_t s = 0; s < l.count; ++s) {
    const int k1 = l.super[s], columns = l.super[s + 1] - k1, first = l.pi[s];
    const int height = l.pi[s + 1] - first, offDiagonal = height - columns;
    const double* block = l.values + l.px[s];
    below.assign(static_cast<std::size_t>(offDiagonal), Eigen::Vector4d::Zero());
    int j = 0;
    for (; j + 4 <= columns; j += 4) {
      const double* c0 = block + static_cast<std::ptrdiff_t>(j) * height;
      const double* c1 = c0 + height;
      const double* c2 = c1 + height;
      const double* c3 = c2 + height;
      Eigen::Vector4d& x0 = x[static_cast<std::size_t>(k1 + j)];
      Eigen::Vector4d& x1 = x[static_cast<std::size_t>(k1 + j + 1)];
      Eigen::Vector4d& x2 = x[static_cast<std::size_t>(k1 + j + 2)];
      Eigen::Vector4d& x3 = x[static_cast<std::size_t>(k1 + j + 3)];
      x0 /= c0[j];
      x1 = (x1 - c0[j + 1] * x0) / c1[j + 1];
      x2 = (x2 - c0[j + 2] * x0 - c1[j + 2] * x1) / c2[j + 2];
      x3 = (x3 - c0[j + 3] * x0 - c1[j + 3] * x1 - c2[j + 3] * x2) / c3[j + 3];
      for (int i = j + 4; i < columns; ++i)
        x[static_cast<std::size_t>(k1 + i)] -= (c0[i] * x0 + c1[i] * x1) + (c2[i] * x2 + c3[i] * x3);
      for (int i = columns; i < height; ++i)
        below[static_cast<std::size_t>(i - columns)] += (c0[i] * x0 + c1[i] * x1) + (c2[i] * x2 + c3[i] * x3);
    }
    for (; j < columns; ++j) {  // the last one to three columns
      const double* column = block + static_cast<std::ptrdiff_t>(j) * height;
      Eigen::Vector4d& xj = x[static_cast<std::size_t>(k1 + j)];
      xj /= column[j];
      for (int i = j + 1; i < columns; ++i)
        x[static_cast<std::size_t>(k1 + i)] -= column[i] * xj;
      for (int i = columns; i < height; ++i)
        below[static_cast<std::size_t>(i - columns)] += column[i] * xj;
    }
    for (int i = 0; i < offDiagonal; ++i)
      x[static_cast<std::size_t>(l.rows[first + columns + i])] -= below[static_cast<std::size_t>(i)];
  }
}

/// Σ a[i] v[i] over `count` rows, in four interleaved partial sums: one sum's chain of additions would
/// take an addition's latency per row.
Eigen::Vector4d weightedSum(const double* a, const Eigen::Vector4d* v, int count) {
  std::array<Eigen::Vector4d, 4> partial;
  partial.fill(Eigen::Vector4d::Zero());
  int i = 0;
  for (; i + 4 <= count; i += 4)
    for (int k = 0; k < 4; ++k)
      partial[static_cast<std::size_t>(k)] += a[i + k] * v[i + k];
  for (; i < count; ++i)
    partial[0] += a[i] * v[i];
  return (partial[0] + partial[1]) + (partial[2] + partial[3]);
}

/// Lᵀ X = X, the same way backwards: each supernode's rows below gathered once, then its columns solved
/// last to first.
void backwardSolve(const Supernodes& l, std::vector<Eigen::Vector4d>& x,
                   std::vector<Eigen::Vector4d>& below) {
  for (std::size_t s = l.count; s-- > 0;) {
    const int k1 = l.super[s], columns = l.super[s + 1] - k1, first = l.pi[s];
    const int height = l.pi[s + 1] - first, offDiagonal = height - columns;
    const double* block = l.values + l.px[s];
    below.resize(static_cast<std::size_t>(offDiagonal));
    for (int i = 0; i < offDiagonal; ++i)
      below[static_cast<std::size_t>(i)] = x[static_cast<std::size_t>(l.rows[first + columns + i])];
    for (int j = columns - 1; j >= 0; --j) {
      const double* column = block + static_cast<std::ptrdiff_t>(j) * height;
      const Eigen::Vector4d sum =
          weightedSum(column + columns, below.data(), offDiagonal) +
          weightedSum(column + j + 1, &x[static_cast<std::size_t>(k1 + j + 1)], columns - j - 1);
      Eigen::Vector4d& xj = x[static_cast<std::size_t>(k1 + j)];
      xj = (xj - sum) / column[j];
    }
  }
}

}  // namespace

SparseCholesky::SparseCholesky(CholeskyMethod method) : mImpl(std::make_unique<Impl>(method)) {}
SparseCholesky::~SparseCholesky() = default;

namespace {

/// A view of `matrix` for CHOLMOD, which reads it, and only the triangle `stype` names: −1 the lower, 1 the
/// upper.
cholmod_sparse viewOf(const Eigen::SparseMatrix<double>& matrix, int stype) {
  cholmod_sparse a{};
  a.nrow = a.ncol = static_cast<std::size_t>(matrix.rows());
  a.nzmax = static_cast<std::size_t>(matrix.nonZeros());
  a.p = const_cast<int*>(matrix.outerIndexPtr());
  a.i = const_cast<int*>(matrix.innerIndexPtr());
  a.x = const_cast<double*>(matrix.valuePtr());
  a.stype = stype;
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_REAL;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

/// CHOLMOD's symbolic analysis of `matrix` in `order` (CHOLMOD's AMD when empty) with `common`'s method;
/// null where the matrix or the order is malformed or the analysis fails. Its caller holds the call guard.
cholmod_factor* analyzeWith(const Eigen::SparseMatrix<double>& matrix, const std::vector<int>& order,
                            cholmod_common& common) {
  if (matrix.rows() != matrix.cols() || !matrix.isCompressed()) return nullptr;
  if (!order.empty() && static_cast<Eigen::Index>(order.size()) != matrix.rows()) return nullptr;
  cholmod_sparse a = viewOf(matrix, -1);
  common.nmethods = 1;
  common.method[0].ordering = order.empty() ? CHOLMOD_AMD : CHOLMOD_GIVEN;
  common.postorder = 1;
  return cholmod_analyze_p(&a, order.empty() ? nullptr : const_cast<int*>(order.data()), nullptr, 0, &common);
}

bool outOfMemory(const cholmod_common& common) {
  return common.status == CHOLMOD_OUT_OF_MEMORY || common.status == CHOLMOD_TOO_LARGE;
}

}  // namespace

/// A symbolic factor and the CHOLMOD workspace it was allocated in (and is freed in).
struct SymbolicFactor::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  double factorNonzeros = 0.0;
  explicit Impl(CholeskyMethod method) { startCommon(common, method); }
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

SymbolicFactor::SymbolicFactor(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
SymbolicFactor::~SymbolicFactor() = default;

std::shared_ptr<const SymbolicFactor> SparseCholesky::analyze(const Eigen::SparseMatrix<double>& matrix,
                                                              const std::vector<int>& order,
                                                              CholeskyMethod method) {
  auto impl = std::make_unique<SymbolicFactor::Impl>(method);
  {
    const CallGuard guard;
    impl->factor = analyzeWith(matrix, order, impl->common);
    // The analysis's workspace (a few integers per row) is not needed to keep it.
    cholmod_free_work(&impl->common);
  }
  if (!impl->factor) return nullptr;
  impl->factorNonzeros = impl->common.lnz;
  std::shared_ptr<SymbolicFactor> out(new SymbolicFactor(std::move(impl)));
  out->mRows = matrix.rows();
  out->mNonZeros = matrix.nonZeros();
  return out;
}

bool SparseCholesky::factorize(const Eigen::SparseMatrix<double>& matrix, const std::vector<int>& order) {
  Impl& s = *mImpl;
  s.freeFactor();
  mRows = 0;
  mFailure = Failure::kOther;
  mFactorNonzeros = 0.0;
  const CallGuard guard;
  s.factor = analyzeWith(matrix, order, s.common);
  if (!s.factor) {
    if (outOfMemory(s.common)) mFailure = Failure::kOutOfMemory;
    return false;
  }
  mFactorNonzeros = s.common.lnz;
  mRows = matrix.rows();
  return factorizeNumerically(matrix);
}

bool SparseCholesky::factorize(const Eigen::SparseMatrix<double>& matrix, const SymbolicFactor& analysis) {
  Impl& s = *mImpl;
  s.freeFactor();
  mRows = 0;
  mFailure = Failure::kOther;
  mFactorNonzeros = 0.0;
  if (matrix.rows() != analysis.rows() || matrix.cols() != analysis.rows() ||
      matrix.nonZeros() != analysis.nonZeros())
    return false;
  const CallGuard guard;
  // A copy of the analysis (its structure only: a symbolic factor has no values) becomes this factor.
  s.factor = cholmod_copy_factor(analysis.mImpl->factor, &s.common);
  if (!s.factor) {
    if (outOfMemory(s.common)) mFailure = Failure::kOutOfMemory;
    return false;
  }
  mFactorNonzeros = analysis.mImpl->factorNonzeros;
  mRows = matrix.rows();
  return factorizeNumerically(matrix);
}

bool SparseCholesky::refactorize(const Eigen::SparseMatrix<double>& matrix) {
  const CallGuard guard;
  return factorizeNumerically(matrix);
}

bool SparseCholesky::factorizeNumerically(const Eigen::SparseMatrix<double>& matrix) {
  Impl& s = *mImpl;
  mFailure = Failure::kOther;
  if (!s.factor || matrix.rows() != mRows || matrix.cols() != mRows || !matrix.isCompressed()) return false;
  // Each method permutes the triangle it reads in one pass where it is the one it is given: the lower for
  // the simplicial method, the upper for the supernodal one (given the lower, it makes two passes; the
  // second took 2-9 % of a supernodal factorization).
  cholmod_sparse a = viewOf(matrix, s.factor->is_super ? 1 : -1);
  if (!cholmod_factorize(&a, s.factor, &s.common) || s.common.status != CHOLMOD_OK ||
      s.factor->minor < s.factor->n) {
    if (s.common.status == CHOLMOD_OUT_OF_MEMORY || s.common.status == CHOLMOD_TOO_LARGE)
      mFailure = Failure::kOutOfMemory;
    else if (s.common.status == CHOLMOD_NOT_POSDEF || s.factor->minor < s.factor->n)
      mFailure = Failure::kNotPositiveDefinite;
    s.freeFactor();
    mRows = 0;
    return false;
  }
  mFailure = Failure::kNone;
  return true;
}

bool SparseCholesky::solveSystem(int system, const double* b, double* x, Eigen::Index columns) const {
  Impl& s = *mImpl;
  cholmod_dense rhs{};
  rhs.nrow = rhs.d = static_cast<std::size_t>(mRows);
  rhs.ncol = static_cast<std::size_t>(columns);
  rhs.nzmax = rhs.nrow * rhs.ncol;
  rhs.x = const_cast<double*>(b);
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  const CallGuard guard;
  if (!s.factor || !cholmod_solve2(system, s.factor, &rhs, nullptr, &s.x, nullptr, &s.y, &s.e, &s.common)) {
    std::fill(x, x + rhs.nzmax, std::numeric_limits<double>::quiet_NaN());
    return false;
  }
  std::memcpy(x, s.x->x, sizeof(double) * rhs.nzmax);
  return true;
}

bool SparseCholesky::solve(const double* b, double* x, Eigen::Index columns) const {
  return solveSystem(CHOLMOD_A, b, x, columns);
}

bool SparseCholesky::solveFactor(const double* b, double* x, Eigen::Index columns) const {
  if (blockSolves(columns)) {
    solveFourColumns(/*transposed=*/false, b, x);
    return true;
  }
  // x = P b, then L⁻¹ x in place of it (CHOLMOD's P and L systems are separate calls).
  return solveSystem(CHOLMOD_P, b, x, columns) && solveSystem(CHOLMOD_L, x, x, columns);
}

bool SparseCholesky::solveFactorTransposed(const double* b, double* x, Eigen::Index columns) const {
  if (blockSolves(columns)) {
    solveFourColumns(/*transposed=*/true, b, x);
    return true;
  }
  return solveSystem(CHOLMOD_Lt, b, x, columns) && solveSystem(CHOLMOD_Pt, x, x, columns);
}

void SparseCholesky::solveFourColumns(bool transposed, const double* b, double* x) const {
  // L⁻¹ P b: row k of P b is row Perm[k] of b. Pᵀ L⁻ᵀ b: row Perm[k] of the result is row k of L⁻ᵀ b.
  const Impl& s = *mImpl;
  const int* perm = static_cast<const int*>(s.factor->Perm);
  const std::size_t n = static_cast<std::size_t>(mRows);
  const auto permuted = [perm](std::size_t k) { return static_cast<std::size_t>(perm[k]); };
  s.rows.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t c = 0; c < 4; ++c)
      s.rows[k][static_cast<Eigen::Index>(c)] = b[c * n + (transposed ? k : permuted(k))];
  if (transposed)
    backwardSolve(Supernodes(*s.factor), s.rows, s.gathered);
  else
    forwardSolve(Supernodes(*s.factor), s.rows, s.gathered);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t c = 0; c < 4; ++c)
      x[c * n + (transposed ? permuted(k) : k)] = s.rows[k][static_cast<Eigen::Index>(c)];
}

bool SparseCholesky::blockSolves(Eigen::Index columns) const {
  const cholmod_factor* f = mImpl->factor;
  return mBlockSolves == BlockSolves::kAuto && columns == 4 && f && f->is_super && f->itype == CHOLMOD_INT &&
         f->xtype == CHOLMOD_REAL && f->Perm && mFactorNonzeros <= kBlockSolvesMaxNonzeros;
}

bool SparseCholesky::supernodal() const {
  return mImpl->factor && mImpl->factor->is_super;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  Eigen::MatrixXd x(b.rows(), b.cols());
  solve(b.data(), x.data(), b.cols());
  return x;
}

}  // namespace shapedb::volume::detail
