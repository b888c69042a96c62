#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Spectra/SymEigsSolver.h>

#include <shapedb/volume/modal.h>

#include "kept_for_tets.h"
#include "node_neighbours.h"
#include "sparse_cholesky.h"
#include "sparse_products.h"

namespace shapedb::volume {

namespace detail {

/// A ModalPlan's analysis, kept for the tets and element order (the variant) it is of.
struct ModalPlanState : KeptForTets<SymbolicFactor> {};

}  // namespace detail

ModalPlan::ModalPlan() : mState(std::make_unique<detail::ModalPlanState>()) {}
ModalPlan::~ModalPlan() = default;
bool ModalPlan::ready() const {
  return mState->ready();
}

namespace {

using core::ModalData;
using core::TetMesh;
using SparseMatrix = Eigen::SparseMatrix<double>;

/// Where a factorization of K − σM takes its symbolic analysis from and leaves it: `plan`'s, for `mesh`'s
/// tets in `order` (no plan: its own, made and dropped).
struct PlanSlot {
  detail::ModalPlanState* plan = nullptr;
  const TetMesh* mesh = nullptr;
  ElementOrder order = ElementOrder::kQuadratic;
};

/// K − σM on K's pattern, which holds M's (the assembler lays M's entries out among K's): one copy of K
/// and a merge per column. Eigen's own sum grows its result from a guess of a few entries per column,
/// copying it a dozen times over for a large K (over 100 ms for a 19,000-dof entry). Falls back to that
/// sum if an entry of M lies outside K's pattern.
SparseMatrix shiftedStiffness(const SparseMatrix& k, const SparseMatrix& m, double sigma) {
  SparseMatrix out = k;
  out.makeCompressed();
  double* values = out.valuePtr();
  const int* rows = out.innerIndexPtr();
  for (Eigen::Index column = 0; column < out.outerSize(); ++column) {
    int at = out.outerIndexPtr()[column];
    const int end = out.outerIndexPtr()[column + 1];
    for (SparseMatrix::InnerIterator it(m, column); it; ++it) {
      while (at < end && rows[at] < it.row())
        ++at;
      if (at == end || rows[at] != it.row()) {
        SparseMatrix sum = k - sigma * m;
        sum.makeCompressed();
        return sum;
      }
      values[at] -= sigma * it.value();
    }
  }
  return out;
}

/// The shift-invert operator in symmetric form. With K − σM factorized (sparse Cholesky; σ < 0, so it is
/// positive definite: K is semi-definite and M definite) as A = H⁻ᵀ H⁻¹ (SparseCholesky's halves), the
/// pencil K φ = λ M φ becomes the standard symmetric problem C y = μ y, C = Hᵀ M H, with φ = H y and
/// μ = 1 / (λ − σ): the smallest λ are the largest μ. Lanczos on C works in the Euclidean inner product;
/// on the pencil itself (Spectra's SymGEigsShiftSolver) every step took four to six products with M for
/// its M inner products and reorthogonalization, which cost more than the solve on quadratic tets. Here
/// a step is one solve (its two halves) and one product with M. Q = I − Y Yᵀ removes the rigid motions,
/// Y an orthonormal basis of their images H⁻¹ R = Hᵀ A R: Lanczos then never meets the six-fold
/// eigenvalue of the rigid modes, which it can resolve short of one (it did, on a 3,500-node beam), and
/// spends no iterations on them.
class SymmetricShiftInvert {
 public:
  using Scalar = double;
  SymmetricShiftInvert(const SparseMatrix& k, const SparseMatrix& m, const Eigen::MatrixXd& rigid,
                       double sigma, const PlanSlot& slot = {})
      : mM(m), mShifted(shiftedStiffness(k, m, sigma)), mScratch(k.rows()), mProduct(k.rows()) {
    mOk = factorizeShifted(slot);
    if (!mOk) return;
    // Orthonormal by Householder QR: the images are orthogonal already (Rᵀ A R = −σ I, as K R = 0), up to
    // round-off.
    const Eigen::MatrixXd images = imageOf(rigid);
    mRigid = Eigen::HouseholderQR<Eigen::MatrixXd>(images).householderQ() *
             Eigen::MatrixXd::Identity(images.rows(), images.cols());
  }
  bool ok() const { return mOk; }
  /// Why the factorization failed, and the size of the factor it foresaw.
  detail::SparseCholesky::Failure failure() const { return mSolver.failure(); }
  double factorNonzeros() const { return mSolver.factorNonzeros(); }
  Eigen::Index rows() const { return mM.rows(); }
  Eigen::Index cols() const { return mM.cols(); }

  void perform_op(const double* in, double* out) const {  // NOLINT: Spectra's interface
    // NaN if a solve failed: Lanczos then fails, and says so.
    mSolver.solveFactorTransposed(in, mScratch.data());
    mProduct.noalias() = mM * mScratch;
    mSolver.solveFactor(mProduct.data(), out);
    Eigen::Map<Eigen::VectorXd> y(out, rows());
    y.noalias() -= mRigid * (mRigid.transpose() * y);
  }

  /// C X for a block of vectors: each pass over the factor serves all of X's columns (four columns cost
  /// 0.4-0.65 times as much per column as one: bench/results/xeon-2core/block_lanczos_2026-11-29.md).
  Eigen::MatrixXd apply(const Eigen::MatrixXd& x) const {
    const Eigen::Index n = rows(), k = x.cols();
    Eigen::MatrixXd s(n, k), ms(n, k), y(n, k);
    mSolver.solveFactorTransposed(x.data(), s.data(), k);
    detail::symmetricProduct(mM, s.data(), ms.data(), k);
    mSolver.solveFactor(ms.data(), y.data(), k);
    y.noalias() -= mRigid * (mRigid.transpose() * y);
    return y;
  }

  /// y = H⁻¹ x = Hᵀ A x for vectors x of the pencil's space, the rigid motions removed.
  Eigen::MatrixXd fromPencil(const Eigen::MatrixXd& x) const {
    Eigen::MatrixXd y = imageOf(x);
    y -= mRigid * (mRigid.transpose() * y);
    return y;
  }
  /// φ = H y: the pencil's vectors of C's.
  Eigen::MatrixXd toPencil(const Eigen::MatrixXd& y) const {
    Eigen::MatrixXd x(y.rows(), y.cols());
    mSolver.solveFactorTransposed(y.data(), x.data(), y.cols());
    return x;
  }

 private:
  /// Factorizes A on the plan's analysis where it has one for these tets, else on a new one (which the
  /// plan keeps, where there is a plan).
  bool factorizeShifted(const PlanSlot& slot) {
    if (!slot.plan) return mSolver.factorize(mShifted, detail::nodeBlockOrder(mShifted));
    std::shared_ptr<const detail::SymbolicFactor> analysis =
        slot.plan->find(*slot.mesh, static_cast<int>(slot.order));
    if (!analysis) {
      const std::vector<int> order = detail::nodeBlockOrder(mShifted);
      analysis = detail::SparseCholesky::analyze(mShifted, order);
      // Where even the analysis fails, factorize says why.
      if (!analysis) return mSolver.factorize(mShifted, order);
      slot.plan->keep(*slot.mesh, analysis, static_cast<int>(slot.order));
    }
    return mSolver.factorize(mShifted, *analysis);
  }

  /// H⁻¹ x = Hᵀ A x.
  Eigen::MatrixXd imageOf(const Eigen::MatrixXd& x) const {
    const Eigen::MatrixXd ax = detail::symmetricProduct(mShifted, x);
    Eigen::MatrixXd y(x.rows(), x.cols());
    mSolver.solveFactor(ax.data(), y.data(), x.cols());
    return y;
  }

  const SparseMatrix& mM;
  const SparseMatrix mShifted;  // A = K − σM
  detail::SparseCholesky mSolver;
  Eigen::MatrixXd mRigid;
  mutable Eigen::VectorXd mScratch, mProduct;
  bool mOk = false;
};

/// Why K − σM of n degrees of freedom could not be factorized, in words.
Error factorizationError(const SymmetricShiftInvert& op, Eigen::Index n) {
  const std::string matrix = "the stiffness matrix (" + std::to_string(n) + " degrees of freedom)";
  switch (op.failure()) {
    case detail::SparseCholesky::Failure::kOutOfMemory: {
      std::string size;
      if (op.factorNonzeros() > 0.0) {
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, " (its factor holds %.3g values, %.2g GB at least)",
                      op.factorNonzeros(), 8e-9 * op.factorNonzeros());
        size = buffer;
      }
      return Error{ErrorCode::kTooLarge, matrix + " could not be factorized: out of memory" + size};
    }
    case detail::SparseCholesky::Failure::kNotPositiveDefinite:
      return Error{ErrorCode::kParse,
                   matrix + " could not be factorized: it is not positive definite (degenerate tets?)"};
    default:
      return Error{ErrorCode::kParse, matrix + " could not be factorized"};
  }
}

/// The six rigid motions (translations along and rotations about x, y, z through the centroid of the
/// nodes), M-orthonormalized by Gram–Schmidt in the M inner product.
Eigen::MatrixXd rigidMotions(const std::vector<core::Vec3>& nodes, const SparseMatrix& mass) {
  const auto n = static_cast<Eigen::Index>(nodes.size());
  core::Vec3 center = core::Vec3::Zero();
  for (const core::Vec3& p : nodes)
    center += p;
  center /= static_cast<double>(n);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(3 * n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    const core::Vec3 p = nodes[static_cast<std::size_t>(i)] - center;
    for (int k = 0; k < 3; ++k)
      r(3 * i + k, k) = 1.0;
    r.block<3, 1>(3 * i, 3) = core::Vec3(0.0, -p.z(), p.y());
    r.block<3, 1>(3 * i, 4) = core::Vec3(p.z(), 0.0, -p.x());
    r.block<3, 1>(3 * i, 5) = core::Vec3(-p.y(), p.x(), 0.0);
  }
  // Modified Gram–Schmidt with each finished column's product with M kept: ⟨r_k, r_j⟩_M = (M r_k) · r_j,
  // M symmetric, so a pass costs six products with M, not one per pair.
  Eigen::MatrixXd mr(3 * n, 6);
  for (int pass = 0; pass < 2; ++pass) {  // twice is enough (Kahan–Parlett)
    for (int j = 0; j < 6; ++j) {
      for (int k = 0; k < j; ++k)
        r.col(j) -= mr.col(k).dot(r.col(j)) * r.col(k);
      mr.col(j).noalias() = mass * r.col(j);
      const double norm = std::sqrt(r.col(j).dot(mr.col(j)));
      r.col(j) /= norm;
      mr.col(j) /= norm;
    }
  }
  return r;
}

Status checkOptions(std::size_t nodeCount, const ModalOptions& options) {
  const core::Material& m = options.material;
  if (options.modes < 1) return Error{ErrorCode::kInvalidArgument, "at least one mode must be asked for"};
  if (!(m.youngsModulus > 0.0 && m.density > 0.0 && std::isfinite(m.youngsModulus) &&
        std::isfinite(m.density)))
    return Error{ErrorCode::kInvalidArgument, "Young's modulus and density must be finite and positive"};
  if (!core::validPoissonRatio(m.poissonRatio))
    return Error{ErrorCode::kInvalidArgument, "Poisson ratio must be in [0, 0.5)"};
  if (!options.pointMasses.empty()) {
    if (options.pointMasses.size() != nodeCount)
      return Error{ErrorCode::kInvalidArgument,
                   "point masses: " + std::to_string(options.pointMasses.size()) + " given for a mesh of " +
                       std::to_string(nodeCount) + " nodes"};
    for (double mass : options.pointMasses)
      if (!(mass >= 0.0 && std::isfinite(mass)))
        return Error{ErrorCode::kInvalidArgument, "point masses must be finite and not negative"};
  }
  if (3 * nodeCount < static_cast<std::size_t>(options.modes) + 6 + 2)
    return Error{ErrorCode::kInvalidArgument,
                 "the tet mesh has too few nodes for " + std::to_string(options.modes) + " modes"};
  return Ok{};
}

/// A rigid mode's eigenvalue is zero up to round-off: ~1e-13 of the stiffness scale. A solid in two
/// pieces has six more zero modes; the slenderest shapes a database holds have their first elastic mode
/// above ~1e-8 of it.
constexpr double kRigidTolerance = 1e-10;

/// The elastic modes: `eigenvalues` ascending with their `vectors`, M-normalized and sign-fixed;
/// `rigid` holds the six rigid eigenvalues (absolute). Fails when the first elastic one is zero too.
Result<ModalData> makeModalData(const Eigen::VectorXd& eigenvalues, const Eigen::MatrixXd& vectors,
                                const std::array<double, 6>& rigid, const FemMatrices& fem,
                                const ModalOptions& options) {
  const double scale = fem.stiffness.diagonal().sum() / fem.mass.diagonal().sum();
  const double firstElastic = eigenvalues[0];
  int zeros = 6;
  for (Eigen::Index i = 0; i < eigenvalues.size(); ++i)
    zeros += std::abs(eigenvalues[i]) <= kRigidTolerance * scale ? 1 : 0;
  for (double r : rigid)
    zeros -= std::abs(r) <= kRigidTolerance * scale ? 0 : 1;
  if (zeros != 6 || !(firstElastic > kRigidTolerance * scale)) {
    // Say what was found: the smallest eigenvalues against the stiffness scale.
    char detail[160];
    std::snprintf(detail, sizeof detail, " (smallest non-rigid: %.3g, %.3g, %.3g of the stiffness scale)",
                  eigenvalues[0] / scale, eigenvalues.size() > 1 ? eigenvalues[1] / scale : 0.0,
                  eigenvalues.size() > 2 ? eigenvalues[2] / scale : 0.0);
    if (zeros == 6)
      return Error{ErrorCode::kParse, std::string("the first non-rigid eigenvalue is not positive") + detail +
                                          ": degenerate or inverted tets?"};
    return Error{
        ErrorCode::kParse,
        "expected six rigid modes, found " + std::to_string(zeros) +
            " zero eigenvalues (a solid in more than one piece, a part its tets hold too loosely to "
            "resist moving, or a body so slender that its first modes are under 1e-10 of its stiffest)" +
            detail};
  }
  ModalData data;
  data.poissonRatio = options.material.poissonRatio;
  for (std::size_t i = 0; i < 6; ++i)
    data.rigidEigenvalues[i] = rigid[i] / firstElastic;
  data.eigenvalues = eigenvalues.head(options.modes);
  data.shapes = vectors.leftCols(options.modes);
  // M-normalize explicitly (the solvers' own normalization is in their inner product, up to round-off),
  // and fix each sign so the largest component is positive: the same mesh gives the same bytes.
  const Eigen::MatrixXd massShapes = detail::symmetricProduct(fem.mass, data.shapes);
  for (int i = 0; i < options.modes; ++i) {
    auto phi = data.shapes.col(i);
    phi /= std::sqrt(phi.dot(massShapes.col(i)));
    Eigen::Index arg = 0;  // a plain loop: Eigen's AVX-512 max reduction trips GCC 12's maybe-uninitialized
    for (Eigen::Index j = 1; j < phi.size(); ++j)
      if (std::abs(phi[j]) > std::abs(phi[arg])) arg = j;
    if (phi[arg] < 0.0) phi = -phi;
  }
  return data;
}

}  // namespace

const char* toString(ElementOrder order) {
  return order == ElementOrder::kQuadratic ? "quadratic" : "linear";
}

std::optional<ElementOrder> parseElementOrder(std::string_view name) {
  if (name == "linear") return ElementOrder::kLinear;
  if (name == "quadratic") return ElementOrder::kQuadratic;
  return std::nullopt;
}

QuadraticTetMesh makeQuadratic(const TetMesh& mesh) {
  const auto key = [](std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
  };
  std::vector<std::uint64_t> edges;
  edges.reserve(6 * mesh.tetCount());
  for (const TetMesh::Tet& tet : mesh.tets)
    for (const auto& [a, b] : kQuadraticTetEdges)
      edges.push_back(key(tet[static_cast<std::size_t>(a)], tet[static_cast<std::size_t>(b)]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  QuadraticTetMesh out;
  out.cornerCount = mesh.nodeCount();
  out.nodes = mesh.nodes;
  out.nodes.reserve(mesh.nodeCount() + edges.size());
  for (std::uint64_t e : edges)
    out.nodes.push_back(0.5 * (mesh.nodes[e >> 32] + mesh.nodes[e & 0xffffffffu]));
  out.tets.reserve(mesh.tetCount());
  for (const TetMesh::Tet& tet : mesh.tets) {
    QuadraticTetMesh::Tet q{};
    std::copy(tet.begin(), tet.end(), q.begin());
    for (std::size_t e = 0; e < kQuadraticTetEdges.size(); ++e) {
      const std::uint64_t k = key(tet[static_cast<std::size_t>(kQuadraticTetEdges[e][0])],
                                  tet[static_cast<std::size_t>(kQuadraticTetEdges[e][1])]);
      const auto at = std::lower_bound(edges.begin(), edges.end(), k) - edges.begin();
      q[4 + e] = static_cast<std::uint32_t>(mesh.nodeCount() + static_cast<std::size_t>(at));
    }
    out.tets.push_back(q);
  }
  return out;
}

Eigen::Matrix<double, 3, 10> quadraticGradients(const Eigen::Matrix<double, 3, 4>& barycentricGradients,
                                                const Eigen::Vector4d& l) {
  // Corners: N_a = L_a (2 L_a − 1); edges: N_ab = 4 L_a L_b.
  const auto& g = barycentricGradients;
  Eigen::Matrix<double, 3, 10> out;
  for (int a = 0; a < 4; ++a)
    out.col(a) = (4.0 * l[a] - 1.0) * g.col(a);
  for (int e = 0; e < 6; ++e) {
    const int a = kQuadraticTetEdges[static_cast<std::size_t>(e)][0],
              b = kQuadraticTetEdges[static_cast<std::size_t>(e)][1];
    out.col(4 + e) = 4.0 * (l[a] * g.col(b) + l[b] * g.col(a));
  }
  return out;
}

const Eigen::Matrix<double, 10, 10>& quadraticReferenceMass() {
  // Each shape function as a homogeneous quadratic form Lᵀ Q L in the barycentric coordinates (L_a =
  // L_a Σ_b L_b), and ∫ L^α dV / V = 6 α! / (|α| + 3)! for the quartic monomials of their products.
  static const Eigen::Matrix<double, 10, 10> mass = [] {
    std::array<Eigen::Matrix4d, 10> q;
    for (int a = 0; a < 4; ++a) {  // L_a² − Σ_{b≠a} L_a L_b
      q[static_cast<std::size_t>(a)] = Eigen::Matrix4d::Zero();
      q[static_cast<std::size_t>(a)].row(a).setConstant(-0.5);
      q[static_cast<std::size_t>(a)].col(a).setConstant(-0.5);
      q[static_cast<std::size_t>(a)](a, a) = 1.0;
    }
    for (std::size_t e = 0; e < 6; ++e) {  // 4 L_a L_b
      q[4 + e] = Eigen::Matrix4d::Zero();
      q[4 + e](kQuadraticTetEdges[e][0], kQuadraticTetEdges[e][1]) =
          q[4 + e](kQuadraticTetEdges[e][1], kQuadraticTetEdges[e][0]) = 2.0;
    }
    const auto monomial = [](int i, int j, int k, int l) {
      std::array<int, 4> power{};
      for (int v : {i, j, k, l})
        ++power[static_cast<std::size_t>(v)];
      double factorials = 1.0;
      for (int p : power)
        for (int f = 2; f <= p; ++f)
          factorials *= f;
      return 6.0 * factorials / 5040.0;  // 7!
    };
    Eigen::Matrix<double, 10, 10> m = Eigen::Matrix<double, 10, 10>::Zero();
    for (std::size_t p = 0; p < 10; ++p)
      for (std::size_t r = 0; r < 10; ++r)
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k)
              for (int l = 0; l < 4; ++l)
                m(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(r)) +=
                    q[p](i, j) * q[r](k, l) * monomial(i, j, k, l);
    return m;
  }();
  return mass;
}

namespace {

/// The quadrature of degree 2 the quadratic stiffness needs (exact for it): four points, weight V/4
/// each, at these barycentric coordinates.
const std::array<Eigen::Vector4d, 4>& quadraticQuadraturePoints() {
  static const std::array<Eigen::Vector4d, 4> points = [] {
    const double a = 0.5854101966249685, b = 0.1381966011250105;  // (5 ± 3√5) / 20
    return std::array<Eigen::Vector4d, 4>{Eigen::Vector4d(a, b, b, b), Eigen::Vector4d(b, a, b, b),
                                          Eigen::Vector4d(b, b, a, b), Eigen::Vector4d(b, b, b, a)};
  }();
  return points;
}

/// Lamé's parameters of an isotropic material.
struct Lame {
  double lambda = 0.0, mu = 0.0;
};
Lame lame(const core::Material& material) {
  const double e = material.youngsModulus, nu = material.poissonRatio;
  return {e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu))};
}

/// Isotropic elasticity in Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains.
Eigen::Matrix<double, 6, 6> elasticity(const core::Material& material) {
  const auto [lambda, mu] = lame(material);
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  d.topLeftCorner<3, 3>().setConstant(lambda);
  d.topLeftCorner<3, 3>().diagonal().array() += 2.0 * mu;
  d.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return d;
}

/// The strain–displacement matrix of N nodes from their shape-function gradients (columns).
template <int N>
Eigen::Matrix<double, 6, 3 * N> strainDisplacement(const Eigen::Matrix<double, 3, N>& grad) {
  Eigen::Matrix<double, 6, 3 * N> b = Eigen::Matrix<double, 6, 3 * N>::Zero();
  for (int a = 0; a < N; ++a) {
    const double gx = grad(0, a), gy = grad(1, a), gz = grad(2, a);
    b(0, 3 * a) = gx;
    b(1, 3 * a + 1) = gy;
    b(2, 3 * a + 2) = gz;
    b(3, 3 * a + 1) = gz;
    b(3, 3 * a + 2) = gy;
    b(4, 3 * a) = gz;
    b(4, 3 * a + 2) = gx;
    b(5, 3 * a) = gy;
    b(5, 3 * a + 1) = gx;
  }
  return b;
}

/// Assembles element matrices straight into the compressed storage of K and M: the patterns first (a 3 × 3
/// block of K per pair of nodes that share an element, and its diagonal in M), then each element's values
/// added where they belong.
/// 2–3× faster than Eigen's triplets for quadratic tets, which bring 900 + 300 of them each.
template <std::size_t N>
class Assembler {
 public:
  using Element = std::array<std::uint32_t, N>;

  Assembler(std::size_t nodeCount, const std::vector<Element>& elements) {
    // Node adjacency (each node with itself too), CSR with sorted neighbours.
    mAdjacency = detail::nodeNeighbours(nodeCount, elements);
    const std::size_t pairCount = mAdjacency.nodes.size();
    // K's column 3b + c: rows 3a, 3a + 1, 3a + 2 for every neighbour a of b. M's 3 × 3 blocks are
    // diagonal (the same scalar mass on each axis): its column 3b + c has row 3a + c only.
    const auto n = static_cast<Eigen::Index>(3 * nodeCount);
    Eigen::SparseMatrix<double>& k = mMatrices.stiffness;
    Eigen::SparseMatrix<double>& m = mMatrices.mass;
    k.resize(n, n);
    k.resizeNonZeros(static_cast<Eigen::Index>(9 * pairCount));
    m.resize(n, n);
    m.resizeNonZeros(static_cast<Eigen::Index>(3 * pairCount));
    for (std::size_t b = 0; b < nodeCount; ++b) {
      const std::size_t degree = start(b + 1) - start(b);
      for (std::size_t c = 0; c < 3; ++c) {
        const std::size_t column = 3 * b + c, first = 9 * start(b) + 3 * degree * c,
                          firstMass = 3 * start(b) + degree * c;
        k.outerIndexPtr()[column] = static_cast<int>(first);
        m.outerIndexPtr()[column] = static_cast<int>(firstMass);
        for (std::size_t j = 0; j < degree; ++j) {
          const std::uint32_t a = mAdjacency.nodes[start(b) + j];
          for (std::size_t r = 0; r < 3; ++r)
            k.innerIndexPtr()[first + 3 * j + r] = static_cast<int>(3 * a + r);
          m.innerIndexPtr()[firstMass + j] = static_cast<int>(3 * a + c);
        }
      }
    }
    k.outerIndexPtr()[n] = static_cast<int>(9 * pairCount);
    m.outerIndexPtr()[n] = static_cast<int>(3 * pairCount);
    std::fill_n(k.valuePtr(), 9 * pairCount, 0.0);
    std::fill_n(m.valuePtr(), 3 * pairCount, 0.0);
  }

  /// Adds an element's stiffness (3N × 3N) and its scalar mass (N × N, on each axis).
  void add(const Element& e, const Eigen::Matrix<double, 3 * N, 3 * N>& ke,
           const Eigen::Matrix<double, static_cast<int>(N), static_cast<int>(N)>& scalarMass) {
    double* k = mMatrices.stiffness.valuePtr();
    double* m = mMatrices.mass.valuePtr();
    for (std::size_t j = 0; j < N; ++j) {
      const std::uint32_t b = e[j];
      const auto begin = mAdjacency.nodes.begin() + static_cast<std::ptrdiff_t>(start(b));
      const auto end = mAdjacency.nodes.begin() + static_cast<std::ptrdiff_t>(start(b + 1));
      const std::size_t degree = start(b + 1) - start(b);
      for (std::size_t i = 0; i < N; ++i) {
        const auto slot = static_cast<std::size_t>(std::lower_bound(begin, end, e[i]) - begin);
        const double mass = scalarMass(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
        for (std::size_t c = 0; c < 3; ++c) {
          const std::size_t at = 9 * start(b) + 3 * degree * c + 3 * slot;
          for (std::size_t r = 0; r < 3; ++r)
            k[at + r] += ke(static_cast<Eigen::Index>(3 * i + r), static_cast<Eigen::Index>(3 * j + c));
          m[3 * start(b) + degree * c + slot] += mass;
        }
      }
    }
  }

  /// K and M, swapped out: Eigen 3.4's SparseMatrix has no move constructor, so moving the FemMatrices
  /// would copy both (tens of milliseconds for the heaviest entries).
  FemMatrices finish() && {
    FemMatrices out;
    out.stiffness.swap(mMatrices.stiffness);
    out.mass.swap(mMatrices.mass);
    return out;
  }

 private:
  /// Where node b's neighbours start among mAdjacency.nodes (and its K and M columns among the values).
  std::size_t start(std::size_t b) const { return mAdjacency.start[b]; }
  detail::NodeNeighbours mAdjacency;
  FemMatrices mMatrices;
};

}  // namespace

Eigen::Matrix<double, 30, 30> quadraticElementStiffness(
    const Eigen::Matrix<double, 3, 4>& barycentricGradients, double volume, const core::Material& material) {
  // T(3a + i, 3b + j) = Σ_q w ∂_i N_a ∂_j N_b over the quadrature points, all of weight w = V/4: w W Wᵀ,
  // W's columns the points' gradients stacked node by node (a 3 × 10 matrix's column-major storage).
  Eigen::Matrix<double, 30, 4> w;
  const auto& points = quadraticQuadraturePoints();
  for (std::size_t q = 0; q < points.size(); ++q) {
    const Eigen::Matrix<double, 3, 10> g = quadraticGradients(barycentricGradients, points[q]);
    w.col(static_cast<Eigen::Index>(q)) = Eigen::Map<const Eigen::Matrix<double, 30, 1>>(g.data());
  }
  Eigen::Matrix<double, 30, 30> t;
  t.noalias() = (volume / 4.0) * w * w.transpose();
  const auto [lambda, mu] = lame(material);
  Eigen::Matrix<double, 30, 30> ke;
  for (int b = 0; b < 10; ++b)
    for (int a = 0; a < 10; ++a) {
      const Eigen::Matrix3d s = t.block<3, 3>(3 * a, 3 * b);
      ke.block<3, 3>(3 * a, 3 * b) =
          lambda * s + mu * s.transpose() + (mu * s.trace()) * Eigen::Matrix3d::Identity();
    }
  return ke;
}

FemMatrices assembleFem(const TetMesh& mesh, const core::Material& material) {
  const Eigen::Matrix<double, 6, 6> d = elasticity(material);
  // Consistent mass of a linear tet: ρV/20 · (1 + δ_ab) per axis.
  const Eigen::Matrix4d referenceMass = (Eigen::Matrix4d::Ones() + Eigen::Matrix4d::Identity()) / 20.0;
  Assembler<4> assembler(mesh.nodeCount(), mesh.tets);
  for (std::size_t t = 0; t < mesh.tetCount(); ++t) {
    const auto [grad, volume] = core::tetGradients(mesh, t);
    const Eigen::Matrix<double, 6, 12> b = strainDisplacement<4>(grad);
    const Eigen::Matrix<double, 12, 12> ke = volume * b.transpose() * d * b;
    const Eigen::Matrix4d me = material.density * volume * referenceMass;
    assembler.add(mesh.tets[t], ke, me);
  }
  return std::move(assembler).finish();
}

FemMatrices assembleFem(const QuadraticTetMesh& mesh, const core::Material& material) {
  Assembler<10> assembler(mesh.nodeCount(), mesh.tets);
  for (const QuadraticTetMesh::Tet& tet : mesh.tets) {
    const auto [grad, volume] =
        core::tetGradients({mesh.nodes[tet[0]], mesh.nodes[tet[1]], mesh.nodes[tet[2]], mesh.nodes[tet[3]]});
    const Eigen::Matrix<double, 30, 30> ke = quadraticElementStiffness(grad, volume, material);
    const Eigen::Matrix<double, 10, 10> me = material.density * volume * quadraticReferenceMass();
    assembler.add(tet, ke, me);
  }
  return std::move(assembler).finish();
}

namespace {

/// Lanczos stops once every wanted Ritz pair's residual is within this fraction of its value. An entry's
/// modes are computed once and kept: converged far past their discretization error.
constexpr double kEntryTolerance = 1e-10;
/// computeModesFrom's (the geometry correction's, which a query waits for): the eigenvalues' error goes
/// as the residual squared over the gap, the shapes' as the residual over the relative gap, and Lanczos
/// converges most pairs far past the residual it checks. On 70 corrections of the default catalog's
/// entries the twenty frequencies matched those at 1e-10 to 1.2e-8 and the shapes to 2.8e-7 (1 − MAC,
/// where the next frequency is over 1 % away), with 50.3 solves on average against 54.4 at 1e-6
/// (bench/results/xeon-2core/seeded_tolerance_2026-11-29.md).
constexpr double kSeededTolerance = 1e-4;

/// What the solvers share: the rigid motions (known in closed form; detected, K r ≈ 0 with Rayleigh
/// quotients near zero, and deflated, so that the solvers look for the elastic modes only), their Rayleigh
/// quotients, and the shift, a small negative multiple of the stiffness scale (the ratio of the
/// diagonals, near the largest eigenvalue). Every eigenvalue is ≥ 0 > σ, so the smallest ones are the
/// nearest to it; the smaller |σ|, the better they separate, down to where K − σM becomes ill-conditioned.
struct Pencil {
  Eigen::MatrixXd rigid;
  std::array<double, 6> rigidEigenvalues{};
  double sigma = 0.0;
};

Pencil pencilOf(const std::vector<core::Vec3>& nodes, const FemMatrices& fem) {
  Pencil p;
  p.rigid = rigidMotions(nodes, fem.mass);
  const Eigen::MatrixXd stiffRigid = detail::symmetricProduct(fem.stiffness, p.rigid);
  for (int j = 0; j < 6; ++j)
    p.rigidEigenvalues[static_cast<std::size_t>(j)] = p.rigid.col(j).dot(stiffRigid.col(j));
  const double scale = fem.stiffness.diagonal().sum() / fem.mass.diagonal().sum();
  p.sigma = -1e-6 * scale;
  return p;
}

/// The modes from C's largest eigenvalues μ (descending, so λ = σ + 1/μ ascending) and their vectors y in
/// C's space (φ = H y).
Result<ModalData> modesOf(const SymmetricShiftInvert& op, const Pencil& pencil, const Eigen::VectorXd& mu,
                          const Eigen::MatrixXd& y, const FemMatrices& fem, const ModalOptions& options) {
  const Eigen::VectorXd eigenvalues = pencil.sigma + mu.array().inverse();
  return makeModalData(eigenvalues, op.toPencil(y), pencil.rigidEigenvalues, fem, options);
}

/// Shift-invert Lanczos (Spectra's, restarted) on `op` to `tolerance` (a relative Ritz residual), from
/// `start` (a vector of the pencil's space) when given, else Spectra's own random vector; the solves with
/// the factorized K − σM are added to `solves`.
Result<ModalData> restartedLanczos(SymmetricShiftInvert& op, const Pencil& pencil, const FemMatrices& fem,
                                   const ModalOptions& options, double tolerance,
                                   const Eigen::VectorXd* start, int* solves) {
  const Eigen::Index n = op.rows();
  const Eigen::Index nev = options.modes;
  const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
  Spectra::SymEigsSolver<SymmetricShiftInvert> eigs(op, nev, ncv);
  if (start) {
    // Lanczos keeps to the deflated space only if it starts there.
    const Eigen::VectorXd deflated = op.fromPencil(*start);
    eigs.init(deflated.data());
  } else {
    eigs.init();
  }
  eigs.compute(Spectra::SortRule::LargestAlge, 1000, tolerance, Spectra::SortRule::LargestAlge);
  if (solves) *solves += static_cast<int>(eigs.num_operations());
  if (eigs.info() != Spectra::CompInfo::Successful)
    return Error{ErrorCode::kParse, "Lanczos did not converge on " + std::to_string(nev) + " modes"};
  return modesOf(op, pencil, eigs.eigenvalues(), eigs.eigenvectors(), fem, options);
}

/// Shift-invert Lanczos on assembled matrices (computeModes of either order) to `tolerance`.
Result<ModalData> solveSparse(const std::vector<core::Vec3>& nodes, const FemMatrices& fem,
                              const ModalOptions& options, double tolerance) {
  const Pencil pencil = pencilOf(nodes, fem);
  SymmetricShiftInvert op(fem.stiffness, fem.mass, pencil.rigid, pencil.sigma);
  if (!op.ok()) return factorizationError(op, fem.stiffness.rows());
  return restartedLanczos(op, pencil, fem, options, tolerance, nullptr, nullptr);
}

/// The columns of a block Lanczos step: each pass over the factor serves four vectors
/// (SymmetricShiftInvert::apply).
constexpr Eigen::Index kBlockSize = 4;

/// ModalOptions::cancel has been set.
bool cancelled(const std::atomic<bool>* cancel) {
  return cancel && cancel->load(std::memory_order_relaxed);
}

/// What a cancelled solve ends with.
Error cancelledError() {
  return Error{ErrorCode::kCancelled, "the modes' solve was cancelled: its answer is no longer wanted"};
}

/// C's `nev` largest eigenvalues (descending) and their eigenvectors, by block Lanczos.
struct RitzPairs {
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
};

/// Block Lanczos on `op` from the orthonormal block `start` (in C's space, the rigid motions removed),
/// every new block orthogonalized against the whole basis, never restarted: C's restriction to
/// the basis is the block tridiagonal T, and a Ritz pair (θ, V s) of it has the residual ‖B s_last‖, B the
/// triangular factor of the next block, s_last the last block's rows of s. Stops once each of the `nev`
/// largest Ritz values has a residual within `tolerance` of itself (Spectra's criterion). Empty when the
/// basis would exceed `maxColumns` first, or a block loses rank before (C's invariant subspace reached
/// with too few pairs in it), or once `cancel` is true. `solves` counts one solve per column.
std::optional<RitzPairs> blockLanczos(const SymmetricShiftInvert& op, const Eigen::MatrixXd& start,
                                      Eigen::Index nev, double tolerance, Eigen::Index maxColumns,
                                      int& solves, const std::atomic<bool>* cancel) {
  const Eigen::Index n = op.rows(), b = start.cols();
  Eigen::MatrixXd basis(n, maxColumns + b);
  basis.leftCols(b) = start;
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(maxColumns + b, maxColumns + b);
  for (Eigen::Index m = b;; m += b) {
    if (cancelled(cancel)) return std::nullopt;
    Eigen::MatrixXd w = op.apply(basis.middleCols(m - b, b));
    solves += static_cast<int>(b);
    // Against the whole basis (classical Gram–Schmidt in blocks), a second time where a column lost
    // most of its norm to the first (Daniel–Gragg–Kaufman–Stewart: its round-off then matters): the
    // coefficients are T's last block column.
    const auto v = basis.leftCols(m);
    const Eigen::VectorXd before = w.colwise().norm();
    Eigen::MatrixXd h = v.transpose() * w;
    w.noalias() -= v * h;
    if ((w.colwise().norm().transpose().array() < 0.7 * before.array()).any()) {
      const Eigen::MatrixXd again = v.transpose() * w;
      w.noalias() -= v * again;
      h += again;
    }
    t.block(0, m - b, m, b) = h;
    t.block(m - b, 0, b, m) = h.transpose();
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(w);
    const Eigen::MatrixXd next = Eigen::MatrixXd(qr.matrixQR().topRows(b).triangularView<Eigen::Upper>());
    if (m >= nev + b) {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(t.topLeftCorner(m, m));
      const Eigen::MatrixXd s = ritz.eigenvectors().rightCols(nev);
      const Eigen::VectorXd theta = ritz.eigenvalues().tail(nev);
      bool converged = true;
      for (Eigen::Index i = 0; i < nev && converged; ++i)
        converged = (next * s.col(i).tail(b)).norm() <= tolerance * std::abs(theta[i]);
      if (converged) return RitzPairs{theta.reverse(), v * s.rowwise().reverse()};
    }
    // A block that lost rank (its norm a round-off of T's) or a full basis: the restarted solver takes over.
    const double scale = t.topLeftCorner(m, m).cwiseAbs().maxCoeff();
    if (m + b > maxColumns || !(next.diagonal().cwiseAbs().minCoeff() > 1e-10 * scale)) return std::nullopt;
    basis.middleCols(m, b) = qr.householderQ() * Eigen::MatrixXd::Identity(n, b);
    t.block(m, m - b, b, b) = next;
    t.block(m - b, m, b, b) = next.transpose();
  }
}

/// The seeded solve (computeModesFrom): block Lanczos from kBlockSize mixtures of the `seeds` (the
/// pencil's space, each M-normalized), every seed in every start vector, the weights fixed so that the same
/// seeds give the same modes; where it does not converge within a basis of six times the modes wanted, the
/// restarted Lanczos from the seeds' sum. Against the restarted Lanczos alone, on 140 corrections of the
/// default catalog's entries (every one converged in the block): 64 solves on average against 50, each
/// pass over the factor serving four, the basis never restarted and its residuals read off T; the
/// correction 3-5 % faster at the median, 8-11 % at p90, the largest entries' 10-25 %
/// (bench/results/xeon-2core/block_lanczos_2026-11-29.md).
Result<ModalData> solveSeeded(const std::vector<core::Vec3>& nodes, const FemMatrices& fem,
                              const ModalOptions& options, const Eigen::MatrixXd& seeds, int* solves,
                              const PlanSlot& plan) {
  const Pencil pencil = pencilOf(nodes, fem);
  SymmetricShiftInvert op(fem.stiffness, fem.mass, pencil.rigid, pencil.sigma, plan);
  if (!op.ok()) return factorizationError(op, fem.stiffness.rows());
  if (cancelled(options.cancel)) return cancelledError();
  int count = 0;
  const Eigen::Index nev = options.modes;
  // The deflated space has n − 6 dimensions; the basis stays well inside it.
  const Eigen::Index maxColumns = std::min<Eigen::Index>(6 * nev, op.rows() - 6 - kBlockSize);
  if (maxColumns >= nev + kBlockSize) {
    // Values in [−1, 1] from a fixed sequence (SplitMix64), the same on every platform.
    std::uint64_t state = 0x5eed;
    const auto uniform = [&state] {
      std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      z ^= z >> 31;
      return 2.0 * static_cast<double>(z >> 11) * 0x1.0p-53 - 1.0;
    };
    // Fewer seeds than the block's columns: the rest of the start is made up.
    Eigen::MatrixXd mixed(seeds.rows(), std::max(seeds.cols(), kBlockSize));
    mixed.leftCols(seeds.cols()) = seeds;
    for (Eigen::Index i = seeds.size(); i < mixed.size(); ++i)
      mixed.data()[i] = uniform();
    Eigen::MatrixXd weights(mixed.cols(), kBlockSize);
    for (Eigen::Index i = 0; i < weights.size(); ++i)
      weights.data()[i] = uniform();
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(op.fromPencil(mixed * weights));
    const Eigen::VectorXd diagonal = qr.matrixQR().diagonal().cwiseAbs();
    // Seeds that span fewer dimensions than the block (the same seed twice): the restarted solver.
    if (diagonal.minCoeff() > 1e-10 * diagonal.maxCoeff()) {
      const Eigen::MatrixXd start = qr.householderQ() * Eigen::MatrixXd::Identity(op.rows(), kBlockSize);
      if (auto pairs = blockLanczos(op, start, nev, kSeededTolerance, maxColumns, count, options.cancel)) {
        if (solves) *solves = count;
        return modesOf(op, pencil, pairs->values, pairs->vectors, fem, options);
      }
    }
  }
  if (cancelled(options.cancel)) return cancelledError();
  const Eigen::VectorXd sum = seeds.rowwise().sum();
  auto modes = restartedLanczos(op, pencil, fem, options, kSeededTolerance, &sum, &count);
  if (solves) *solves = count;
  return modes;
}

/// The seeds at every node of `mesh`: the corners' values as given, a mid-edge node's the mean of its
/// edge's two corners (the quadratic interpolant of a field that is linear along the edge).
Eigen::MatrixXd seedsAtAllNodes(const QuadraticTetMesh& mesh, const Eigen::MatrixXd& corners) {
  Eigen::MatrixXd all(3 * static_cast<Eigen::Index>(mesh.nodeCount()), corners.cols());
  all.topRows(corners.rows()) = corners;
  for (const QuadraticTetMesh::Tet& tet : mesh.tets)
    for (std::size_t e = 0; e < kQuadraticTetEdges.size(); ++e) {
      const Eigen::Index at = 3 * static_cast<Eigen::Index>(tet[4 + e]);
      const Eigen::Index a =
          3 * static_cast<Eigen::Index>(tet[static_cast<std::size_t>(kQuadraticTetEdges[e][0])]);
      const Eigen::Index b =
          3 * static_cast<Eigen::Index>(tet[static_cast<std::size_t>(kQuadraticTetEdges[e][1])]);
      all.middleRows(at, 3) = 0.5 * (corners.middleRows(a, 3) + corners.middleRows(b, 3));
    }
  return all;
}

/// All 3n eigenpairs by the dense solver: the six smallest must be the rigid ones.
Result<ModalData> solveDense(const FemMatrices& fem, const ModalOptions& options) {
  const Eigen::MatrixXd k(fem.stiffness), m(fem.mass);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(k, m);
  if (solver.info() != Eigen::Success) return Error{ErrorCode::kParse, "dense eigensolver failed"};
  const Eigen::VectorXd& all = solver.eigenvalues();
  std::array<double, 6> rigid{};
  for (std::size_t i = 0; i < 6; ++i)
    rigid[i] = all[static_cast<Eigen::Index>(i)];
  return makeModalData(all.segment(6, all.size() - 6), solver.eigenvectors().rightCols(all.size() - 6), rigid,
                       fem, options);
}

/// K and M of `mesh` with options.pointMasses added to M's diagonal, three degrees of freedom per node (the
/// first nodes: a quadratic mesh numbers its corners first).
template <class Mesh>
FemMatrices assemble(const Mesh& mesh, const ModalOptions& options) {
  FemMatrices fem = assembleFem(mesh, options.material);
  for (std::size_t i = 0; i < options.pointMasses.size(); ++i)
    for (Eigen::Index k = 0; k < 3; ++k) {
      const Eigen::Index dof = 3 * static_cast<Eigen::Index>(i) + k;
      fem.mass.coeffRef(dof, dof) += options.pointMasses[i];
    }
  return fem;
}

/// The quadratic modes at the corners only.
Result<ModalData> cornersOnly(Result<ModalData> modes, std::size_t cornerCount) {
  if (!modes) return modes;
  ModalData corners = std::move(modes).value();
  corners.shapes.conservativeResize(3 * static_cast<Eigen::Index>(cornerCount), Eigen::NoChange);
  return corners;
}

}  // namespace

Result<ModalData> computeModes(const QuadraticTetMesh& mesh, const ModalOptions& options) {
  if (Status ok = checkOptions(mesh.nodeCount(), options); !ok) return ok.error();
  return solveSparse(mesh.nodes, assemble(mesh, options), options, kEntryTolerance);
}

Result<ModalData> computeModes(const TetMesh& mesh, const ModalOptions& options) {
  if (Status ok = checkOptions(mesh.nodeCount(), options); !ok) return ok.error();
  if (options.order == ElementOrder::kQuadratic) {
    const QuadraticTetMesh quadratic = makeQuadratic(mesh);
    return cornersOnly(solveSparse(quadratic.nodes, assemble(quadratic, options), options, kEntryTolerance),
                       mesh.nodeCount());
  }
  return solveSparse(mesh.nodes, assemble(mesh, options), options, kEntryTolerance);
}

Result<ModalData> computeModesFrom(const TetMesh& mesh, const Eigen::MatrixXd& seeds,
                                   const ModalOptions& options, int* solves) {
  if (Status ok = checkOptions(mesh.nodeCount(), options); !ok) return ok.error();
  if (seeds.rows() != 3 * static_cast<Eigen::Index>(mesh.nodeCount()) || seeds.cols() < 1 ||
      !seeds.allFinite())
    return Error{ErrorCode::kInvalidArgument, "the seeds must be finite, 3 values per node of the tet mesh"};
  if (cancelled(options.cancel)) return cancelledError();
  // Each seed M-normalized, so that every seed mode is well represented in the start (a zero seed stays
  // zero).
  const auto normalized = [](const FemMatrices& fem, Eigen::MatrixXd all) {
    const Eigen::MatrixXd massAll = detail::symmetricProduct(fem.mass, all);
    for (Eigen::Index j = 0; j < all.cols(); ++j) {
      const double norm = std::sqrt(all.col(j).dot(massAll.col(j)));
      if (norm > 0.0) all.col(j) /= norm;
    }
    return all;
  };
  const PlanSlot plan{options.plan ? options.plan->mState.get() : nullptr, &mesh, options.order};
  if (options.order == ElementOrder::kQuadratic) {
    const QuadraticTetMesh quadratic = makeQuadratic(mesh);
    const FemMatrices fem = assemble(quadratic, options);
    return cornersOnly(solveSeeded(quadratic.nodes, fem, options,
                                   normalized(fem, seedsAtAllNodes(quadratic, seeds)), solves, plan),
                       mesh.nodeCount());
  }
  const FemMatrices fem = assemble(mesh, options);
  return solveSeeded(mesh.nodes, fem, options, normalized(fem, seeds), solves, plan);
}

Result<ModalData> computeModesDense(const TetMesh& mesh, const ModalOptions& options) {
  if (Status ok = checkOptions(mesh.nodeCount(), options); !ok) return ok.error();
  if (options.order == ElementOrder::kQuadratic) {
    const QuadraticTetMesh quadratic = makeQuadratic(mesh);
    return cornersOnly(solveDense(assemble(quadratic, options), options), mesh.nodeCount());
  }
  return solveDense(assemble(mesh, options), options);
}

}  // namespace shapedb::volume
