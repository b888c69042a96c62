#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <shapedb/volume/modal.h>

namespace shapedb::volume {
namespace {

using core::ModalData;
using core::TetMesh;
using SparseMatrix = Eigen::SparseMatrix<double>;

/// y = P (K − σM)⁻¹ x for Spectra's shift-invert mode, by a sparse LDLᵀ of K − σM (symmetric positive
/// definite for σ < 0: K is semi-definite and M definite; Spectra's own SymShiftInvert uses sparse LU,
/// about twice the work). P = I − R Rᵀ M removes the rigid motions R (M-orthonormal): Lanczos then never
/// meets the six-fold eigenvalue of the rigid modes, which it can resolve short of one (it did, on a
/// 3,500-node beam), and spends no iterations on them.
class ShiftInvertLdlt {
 public:
  using Scalar = double;
  ShiftInvertLdlt(const SparseMatrix& k, const SparseMatrix& m, const Eigen::MatrixXd& rigid)
      : mK(k), mM(m), mRigid(rigid), mMRigid(m * rigid) {}
  Eigen::Index rows() const { return mK.rows(); }
  Eigen::Index cols() const { return mK.cols(); }
  void set_shift(double sigma) {  // NOLINT: Spectra's interface
    mSolver.compute(mK - sigma * mM);
    mOk = mSolver.info() == Eigen::Success;
  }
  void perform_op(const double* in, double* out) const {  // NOLINT: Spectra's interface
    Eigen::Map<const Eigen::VectorXd> x(in, mK.rows());
    Eigen::Map<Eigen::VectorXd> y(out, mK.rows());
    y.noalias() = mSolver.solve(x);
    y.noalias() -= mRigid * (mMRigid.transpose() * y);
  }
  bool ok() const { return mOk; }

 private:
  const SparseMatrix& mK;
  const SparseMatrix& mM;
  const Eigen::MatrixXd& mRigid;
  const Eigen::MatrixXd mMRigid;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> mSolver;
  bool mOk = false;
};

/// The six rigid motions (translations along and rotations about x, y, z through the centroid of the
/// nodes), M-orthonormalized by Gram–Schmidt in the M inner product.
Eigen::MatrixXd rigidMotions(const TetMesh& mesh, const SparseMatrix& mass) {
  const auto n = static_cast<Eigen::Index>(mesh.nodeCount());
  core::Vec3 center = core::Vec3::Zero();
  for (const core::Vec3& p : mesh.nodes)
    center += p;
  center /= static_cast<double>(n);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(3 * n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    const core::Vec3 p = mesh.nodes[static_cast<std::size_t>(i)] - center;
    for (int k = 0; k < 3; ++k)
      r(3 * i + k, k) = 1.0;
    r.block<3, 1>(3 * i, 3) = core::Vec3(0.0, -p.z(), p.y());
    r.block<3, 1>(3 * i, 4) = core::Vec3(p.z(), 0.0, -p.x());
    r.block<3, 1>(3 * i, 5) = core::Vec3(-p.y(), p.x(), 0.0);
  }
  for (int pass = 0; pass < 2; ++pass) {  // twice is enough (Kahan–Parlett)
    for (int j = 0; j < 6; ++j) {
      for (int k = 0; k < j; ++k)
        r.col(j) -= r.col(k).dot(mass * r.col(j)) * r.col(k);
      r.col(j) /= std::sqrt(r.col(j).dot(mass * r.col(j)));
    }
  }
  return r;
}

Status checkOptions(const TetMesh& mesh, const ModalOptions& options) {
  const FemMaterial& m = options.material;
  if (options.modes < 1) return Error{ErrorCode::kInvalidArgument, "at least one mode must be asked for"};
  if (!(m.youngsModulus > 0.0 && m.density > 0.0 && std::isfinite(m.youngsModulus) &&
        std::isfinite(m.density)))
    return Error{ErrorCode::kInvalidArgument, "Young's modulus and density must be finite and positive"};
  if (!(m.poissonRatio >= 0.0 && m.poissonRatio < 0.5))
    return Error{ErrorCode::kInvalidArgument, "Poisson ratio must be in [0, 0.5)"};
  if (3 * mesh.nodeCount() < static_cast<std::size_t>(options.modes) + 6 + 2)
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
    return Error{ErrorCode::kParse, "expected six rigid modes, found " + std::to_string(zeros) +
                                        " zero eigenvalues (is the solid in one piece?)" + detail};
  }
  ModalData data;
  data.poissonRatio = options.material.poissonRatio;
  for (std::size_t i = 0; i < 6; ++i)
    data.rigidEigenvalues[i] = rigid[i] / firstElastic;
  data.eigenvalues = eigenvalues.head(options.modes);
  data.shapes = vectors.leftCols(options.modes);
  const SparseMatrix& mass = fem.mass;
  // M-normalize explicitly (the solvers' own normalization is in their inner product, up to round-off),
  // and fix each sign so the largest component is positive: the same mesh gives the same bytes.
  for (int i = 0; i < options.modes; ++i) {
    auto phi = data.shapes.col(i);
    phi /= std::sqrt(phi.dot(mass * phi));
    Eigen::Index arg = 0;  // a plain loop: Eigen's AVX-512 max reduction trips GCC 12's maybe-uninitialized
    for (Eigen::Index j = 1; j < phi.size(); ++j)
      if (std::abs(phi[j]) > std::abs(phi[arg])) arg = j;
    if (phi[arg] < 0.0) phi = -phi;
  }
  return data;
}

}  // namespace

FemMatrices assembleFem(const TetMesh& mesh, const FemMaterial& material) {
  const double e = material.youngsModulus, nu = material.poissonRatio;
  // Isotropic elasticity in Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains.
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  const double lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = e / (2.0 * (1.0 + nu));
  d.topLeftCorner<3, 3>().setConstant(lambda);
  d.topLeftCorner<3, 3>().diagonal().array() += 2.0 * mu;
  d.bottomRightCorner<3, 3>().diagonal().setConstant(mu);

  std::vector<Eigen::Triplet<double>> kTriplets, mTriplets;
  kTriplets.reserve(mesh.tetCount() * 144);
  mTriplets.reserve(mesh.tetCount() * 48);
  for (std::size_t t = 0; t < mesh.tetCount(); ++t) {
    const auto& tet = mesh.tets[t];
    const auto [grad, volume] = core::tetGradients(mesh, t);
    Eigen::Matrix<double, 6, 12> b = Eigen::Matrix<double, 6, 12>::Zero();
    for (int a = 0; a < 4; ++a) {
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
    const Eigen::Matrix<double, 12, 12> ke = volume * b.transpose() * d * b;
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j)
        kTriplets.emplace_back(3 * static_cast<int>(tet[static_cast<std::size_t>(i / 3)]) + i % 3,
                               3 * static_cast<int>(tet[static_cast<std::size_t>(j / 3)]) + j % 3, ke(i, j));
    // Consistent mass of a linear tet: ρV/20 · (1 + δ_ab) per axis.
    for (int a = 0; a < 4; ++a)
      for (int bb = 0; bb < 4; ++bb)
        for (int k = 0; k < 3; ++k)
          mTriplets.emplace_back(3 * static_cast<int>(tet[static_cast<std::size_t>(a)]) + k,
                                 3 * static_cast<int>(tet[static_cast<std::size_t>(bb)]) + k,
                                 material.density * volume / 20.0 * (a == bb ? 2.0 : 1.0));
  }
  const auto n = static_cast<Eigen::Index>(3 * mesh.nodeCount());
  FemMatrices matrices;
  matrices.stiffness.resize(n, n);
  matrices.mass.resize(n, n);
  matrices.stiffness.setFromTriplets(kTriplets.begin(), kTriplets.end());
  matrices.mass.setFromTriplets(mTriplets.begin(), mTriplets.end());
  return matrices;
}

Result<ModalData> computeModes(const TetMesh& mesh, const ModalOptions& options) {
  if (Status ok = checkOptions(mesh, options); !ok) return ok.error();
  const FemMatrices fem = assembleFem(mesh, options.material);
  const auto n = fem.stiffness.rows();

  // The rigid modes are known in closed form: detect them (K r ≈ 0, Rayleigh quotients near zero) and
  // deflate them, so that Lanczos looks for the elastic modes only.
  const Eigen::MatrixXd rigid = rigidMotions(mesh, fem.mass);
  std::array<double, 6> rigidEigenvalues{};
  for (int j = 0; j < 6; ++j)
    rigidEigenvalues[static_cast<std::size_t>(j)] = rigid.col(j).dot(fem.stiffness * rigid.col(j));

  // The shift: a small negative multiple of the stiffness scale (the ratio of the diagonals, near the
  // largest eigenvalue). Every eigenvalue is ≥ 0 > σ, so the smallest ones are the nearest to it; the
  // smaller |σ|, the better they separate, down to where K − σM becomes ill-conditioned.
  const double scale = fem.stiffness.diagonal().sum() / fem.mass.diagonal().sum();
  const double sigma = -1e-6 * scale;
  ShiftInvertLdlt op(fem.stiffness, fem.mass, rigid);
  Spectra::SparseSymMatProd<double> bop(fem.mass);
  const Eigen::Index nev = options.modes;
  const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
  Spectra::SymGEigsShiftSolver<ShiftInvertLdlt, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, nev, ncv, sigma);
  if (!op.ok())
    return Error{ErrorCode::kParse, "the stiffness matrix could not be factorized (degenerate tets?)"};
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  if (eigs.info() != Spectra::CompInfo::Successful)
    return Error{ErrorCode::kParse, "Lanczos did not converge on " + std::to_string(nev) + " modes"};
  return makeModalData(eigs.eigenvalues(), eigs.eigenvectors(), rigidEigenvalues, fem, options);
}

Result<ModalData> computeModesDense(const TetMesh& mesh, const ModalOptions& options) {
  if (Status ok = checkOptions(mesh, options); !ok) return ok.error();
  const FemMatrices fem = assembleFem(mesh, options.material);
  const Eigen::MatrixXd k(fem.stiffness), m(fem.mass);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(k, m);
  if (solver.info() != Eigen::Success) return Error{ErrorCode::kParse, "dense eigensolver failed"};
  // All 3n eigenvalues: the six smallest must be the rigid ones.
  const Eigen::VectorXd& all = solver.eigenvalues();
  std::array<double, 6> rigid{};
  for (std::size_t i = 0; i < 6; ++i)
    rigid[i] = all[static_cast<Eigen::Index>(i)];
  return makeModalData(all.segment(6, all.size() - 6), solver.eigenvectors().rightCols(all.size() - 6), rigid,
                       fem, options);
}

}  // namespace shapedb::volume
