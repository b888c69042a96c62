#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include <shapedb/core/stretch.h>

namespace shapedb::core {

namespace {

/// Index of the component pair (j, l), j ≤ l, in StretchBasis::coupling.
constexpr std::size_t pairIndex(int j, int l) {
  if (j == l) return static_cast<std::size_t>(j);
  return static_cast<std::size_t>(j + l + 2);  // (0,1) → 3, (0,2) → 4, (1,2) → 5
}

}  // namespace

StretchBasis computeStretchBasis(const TetMesh& mesh, const ModalData& modes) {
  const Eigen::Index m = modes.shapes.cols();
  const auto tets = static_cast<Eigen::Index>(mesh.tetCount());
  const auto nodes = static_cast<Eigen::Index>(mesh.nodeCount());
  const double nu = modes.poissonRatio;
  const double lambda = nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = 1.0 / (2.0 * (1.0 + nu));

  // h[3i + j](t, r) = √V_t ∂_i φ_r,j on tet t: products of columns integrate over the mesh.
  std::array<Eigen::MatrixXd, 9> h;
  for (Eigen::MatrixXd& x : h)
    x.resize(tets, m);
  StretchBasis basis;
  basis.firstMoments.setZero(9, m);
  const MassProperties tetMass = computeTetMassProperties(mesh);
  basis.centroid = tetMass.centerOfMass;
  basis.secondMoments = covarianceFromInertia(tetMass.inertia);
  std::vector<Eigen::Triplet<double>> massTriplets;
  massTriplets.reserve(static_cast<std::size_t>(16 * tets));
  for (Eigen::Index t = 0; t < tets; ++t) {
    const auto& tet = mesh.tets[static_cast<std::size_t>(t)];
    const auto [grad, volume] = tetGradients(mesh, static_cast<std::size_t>(t));
    const double w = std::sqrt(volume);

    Eigen::Matrix<double, 3, 4> x;  // node positions, columns
    for (int a = 0; a < 4; ++a)
      x.col(a) = mesh.nodes[tet[static_cast<std::size_t>(a)]];
    const Vec3 xSum = x.rowwise().sum();
    // ∫ f g over a linear tet = V/20 (Σ f_i g_i + Σ f_i Σ g_i): the consistent mass.
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        massTriplets.emplace_back(tet[static_cast<std::size_t>(a)], tet[static_cast<std::size_t>(b)],
                                  volume / 20.0 * (a == b ? 2.0 : 1.0));

    for (Eigen::Index r = 0; r < m; ++r) {
      Eigen::Matrix<double, 3, 4> u;
      for (int a = 0; a < 4; ++a)
        u.col(a) =
            modes.shapes.col(r).segment<3>(3 * static_cast<Eigen::Index>(tet[static_cast<std::size_t>(a)]));
      const Mat3 g = grad * u.transpose();  // (i, j) = ∂_i u_j
      const Mat3 moments = volume / 20.0 * (x * u.transpose() + xSum * u.rowwise().sum().transpose());
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          h[static_cast<std::size_t>(3 * i + j)](t, r) = w * g(i, j);
          basis.firstMoments(3 * i + j, r) += moments(i, j);
        }
    }
  }

  // The bilinear form λ div u div v + μ Σ_ij (∂_i u_j ∂_i v_j + ∂_i u_j ∂_j v_i), ∂_i → g_i ∂_i, for
  // u and v each one displacement component of a mode.
  const auto hij = [&](int i, int j) -> const Eigen::MatrixXd& {
    return h[static_cast<std::size_t>(3 * i + j)];
  };
  for (int j = 0; j < 3; ++j)
    for (int l = j; l < 3; ++l)
      basis.coupling[pairIndex(j, l)] =
          lambda * (hij(j, j).transpose() * hij(l, l)) + mu * (hij(l, j).transpose() * hij(j, l));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      basis.shear[static_cast<std::size_t>(3 * i + j)] = mu * (hij(i, j).transpose() * hij(i, j));

  Eigen::SparseMatrix<double> scalarMass(nodes, nodes);
  scalarMass.setFromTriplets(massTriplets.begin(), massTriplets.end());
  for (int j = 0; j < 3; ++j) {
    Eigen::MatrixXd component(nodes, m);
    for (Eigen::Index i = 0; i < nodes; ++i)
      component.row(i) = modes.shapes.row(3 * i + j);
    basis.mass[static_cast<std::size_t>(j)] = component.transpose() * (scalarMass * component);
  }
  return basis;
}

Result<StretchedModes> stretchModes(const StretchBasis& basis, const ModalData& modes, const TetMesh& mesh,
                                    const Vec3& stretch) {
  const Eigen::Index m = modes.shapes.cols();
  if (!(stretch.array().isFinite().all() && (stretch.array() > 0.0).all()))
    return Error{ErrorCode::kInvalidArgument, "a stretch must be finite and > 0 along every axis"};
  const auto fits = [m](const Eigen::MatrixXd& q) { return q.rows() == m && q.cols() == m; };
  if (static_cast<Eigen::Index>(basis.modeCount()) != m || modes.eigenvalues.size() != m ||
      modes.shapes.rows() != static_cast<Eigen::Index>(3 * mesh.nodeCount()) ||
      !std::all_of(basis.coupling.begin(), basis.coupling.end(), fits) ||
      !std::all_of(basis.shear.begin(), basis.shear.end(), fits) ||
      !std::all_of(basis.mass.begin(), basis.mass.end(), fits))
    return Error{ErrorCode::kInvalidArgument,
                 "the stretch basis does not fit the entry's modes and tet mesh"};

  // The split modes: vector j·m + r is component j of mode r.
  const Vec3& a = stretch;
  const Vec3 g = a.cwiseInverse();
  const Eigen::Index n = 3 * m;
  Eigen::MatrixXd stiffness(n, n), mass = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < 3; ++j) {
    for (int l = j; l < 3; ++l) {
      Eigen::MatrixXd block = g[j] * g[l] * basis.coupling[pairIndex(j, l)];
      if (j == l)
        for (int i = 0; i < 3; ++i)
          block += g[i] * g[i] * basis.shear[static_cast<std::size_t>(3 * i + j)];
      stiffness.block(j * m, l * m, m, m) = block;
      stiffness.block(l * m, j * m, m, m) = block.transpose();
    }
    mass.block(j * m, j * m, m, m) = basis.mass[static_cast<std::size_t>(j)];
  }

  // The stretched body's rotations r_k(x) = e_k × a ∘ (x − centroid): their mass products with the split
  // modes, (e_k × p) · (φ_j e_j) = Σ_b ε_kbj a_b (x_b − c_b) φ_j (the modes carry no linear momentum, so
  // the first moments may be taken about the origin), and with each other (gram).
  const auto& fm = basis.firstMoments;  // row 3b + j: ∫ x_b φ_j
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(3, n);
  for (int k = 0; k < 3; ++k)
    for (int b = 0; b < 3; ++b)
      for (int j = 0; j < 3; ++j) {
        const int epsilon = (k - b) * (b - j) * (j - k) / 2;  // Levi-Civita ε_kbj
        if (epsilon != 0) c.block(k, j * m, 1, m) += epsilon * a[b] * fm.row(3 * b + j);
      }
  const Mat3 s = a.asDiagonal() * basis.secondMoments * a.asDiagonal();
  const Mat3 gram = s.trace() * Mat3::Identity() - s;
  const Eigen::MatrixXd rotationPart = gram.ldlt().solve(c);  // G⁻¹ C, 3 × n
  mass -= c.transpose() * rotationPart;

  // Drop the directions the projection leaves (nearly) without mass, then solve the standard problem
  // in the mass-orthonormal coordinates that remain.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> massEigen(mass);
  if (massEigen.info() != Eigen::Success)
    return Error{ErrorCode::kInvalidArgument, "the stretched modes' mass matrix has no eigen-decomposition"};
  const double floor = 1e-10 * massEigen.eigenvalues().maxCoeff();
  Eigen::Index first = 0;
  while (first < n && !(massEigen.eigenvalues()[first] > floor))
    ++first;
  if (n - first < m)
    return Error{ErrorCode::kInvalidArgument,
                 "the stretch leaves fewer independent directions than modes once the rotations are removed"};
  const Eigen::MatrixXd whiten =
      massEigen.eigenvectors().rightCols(n - first) *
      massEigen.eigenvalues().tail(n - first).cwiseSqrt().cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(whiten.transpose() * stiffness * whiten);
  if (ritz.info() != Eigen::Success)
    return Error{ErrorCode::kInvalidArgument, "the stretched modes' eigenproblem did not converge"};

  StretchedModes out;
  out.stretch = stretch;
  out.eigenvalues = ritz.eigenvalues().head(m);
  const Eigen::MatrixXd y = whiten * ritz.eigenvectors().leftCols(m);  // n × m, yᵀ mass y = I
  out.shapes.resize(modes.shapes.rows(), m);
  // Component j of every node (every third row): that component of the modes times its block of y.
  using Rows = Eigen::Stride<Eigen::Dynamic, 3>;
  const auto nodes = static_cast<Eigen::Index>(mesh.nodeCount());
  for (int j = 0; j < 3; ++j) {
    const Eigen::Map<const Eigen::MatrixXd, 0, Rows> from(modes.shapes.data() + j, nodes, m,
                                                          Rows(modes.shapes.outerStride(), 3));
    Eigen::Map<Eigen::MatrixXd, 0, Rows> to(out.shapes.data() + j, nodes, m,
                                            Rows(out.shapes.outerStride(), 3));
    to.noalias() = from * y.middleRows(j * m, m);
  }
  const Eigen::MatrixXd rotations = rotationPart * y;  // 3 × m
  for (std::size_t i = 0; i < mesh.nodeCount(); ++i) {
    const Vec3 p = a.cwiseProduct(mesh.nodes[i] - basis.centroid);
    const auto row = 3 * static_cast<Eigen::Index>(i);
    for (Eigen::Index r = 0; r < m; ++r)
      out.shapes.col(r).segment<3>(row) -= Vec3(rotations.col(r)).cross(p);  // Σ_k w_k e_k × p
  }
  // The sign convention of computeModes: the largest component positive.
  for (Eigen::Index r = 0; r < m; ++r) {
    Eigen::Index arg = 0;
    out.shapes.col(r).cwiseAbs().maxCoeff(&arg);
    if (out.shapes(arg, r) < 0.0) out.shapes.col(r) *= -1.0;
  }
  return out;
}

Vec3 momentMatchingStretch(const Mat3& body, const Mat3& target) {
  return (target.diagonal().array() / body.diagonal().array()).sqrt().matrix();
}

}  // namespace shapedb::core
