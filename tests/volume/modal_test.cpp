#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/primitives.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume {
namespace {

using core::TetMesh;
using core::Vec3;

TetMesh tetsOrDie(const core::TriangleMesh& surface, const TetrahedralizeOptions& options = {}) {
  Result<TetMesh> tets = tetrahedralize(surface, options);
  EXPECT_TRUE(tets.ok()) << (tets ? "" : tets.error().message);
  return tets ? std::move(tets).value() : TetMesh{};
}

TEST(Fem, StiffnessAnnihilatesRigidMotionsAndMassIntegratesVolume) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(2.0, 1.0, 0.5)));
  const FemMatrices fem = assembleFem(mesh, {.youngsModulus = 3.0, .poissonRatio = 0.25, .density = 2.0});
  const auto n = static_cast<Eigen::Index>(mesh.nodeCount());
  // A translation, and an infinitesimal rotation about z: no strain, no force.
  Eigen::VectorXd translation(3 * n), rotation(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3& p = mesh.nodes[static_cast<std::size_t>(i)];
    translation.segment<3>(3 * i) = Vec3(1.0, -2.0, 0.5);
    rotation.segment<3>(3 * i) = Vec3(-p.y(), p.x(), 0.0);
  }
  EXPECT_LT((fem.stiffness * translation).norm(), 1e-10 * fem.stiffness.norm());
  EXPECT_LT((fem.stiffness * rotation).norm(), 1e-10 * fem.stiffness.norm() * rotation.norm());
  // uᵀMu for a unit translation along x is the mass: ρV = 2 · 1.
  Eigen::VectorXd ux = Eigen::VectorXd::Zero(3 * n);
  for (Eigen::Index i = 0; i < n; ++i)
    ux[3 * i] = 1.0;
  EXPECT_NEAR(ux.dot(fem.mass * ux), 2.0, 1e-12);
}

TEST(Modal, SparseLanczosAgreesWithDenseSolverAndModesAreMOrthonormal) {
  // A small asymmetric solid (no repeated frequencies to blur the comparison of mode shapes).
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.3, 0.9, 0.6)), {.maxVolumeFraction = 1.0 / 150.0});
  ASSERT_LT(mesh.nodeCount(), 500u);
  ModalOptions options;
  options.modes = 12;
  Result<core::ModalData> sparse = computeModes(mesh, options);
  Result<core::ModalData> dense = computeModesDense(mesh, options);
  ASSERT_TRUE(sparse.ok()) << sparse.error().message;
  ASSERT_TRUE(dense.ok()) << dense.error().message;
  ASSERT_EQ(sparse->modeCount(), 12u);
  for (int i = 0; i < 12; ++i)
    EXPECT_NEAR(sparse->eigenvalues[i], dense->eigenvalues[i], 1e-8 * dense->eigenvalues[i]) << "mode " << i;
  for (double rigid : sparse->rigidEigenvalues)
    EXPECT_LT(std::abs(rigid), 1e-8);

  const FemMatrices fem = assembleFem(mesh, options.material);
  const Eigen::MatrixXd gram = sparse->shapes.transpose() * fem.mass * sparse->shapes;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(12, 12)).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::MatrixXd cross = sparse->shapes.transpose() * fem.mass * dense->shapes;
  for (int i = 0; i < 12; ++i) {
    // Same mode: |φᵢᵀ M ψᵢ| = 1, unless two eigenvalues are (nearly) equal and the pair may turn.
    const bool isolated = (i == 0 || sparse->eigenvalues[i] > 1.001 * sparse->eigenvalues[i - 1]) &&
                          (i == 11 || sparse->eigenvalues[i + 1] > 1.001 * sparse->eigenvalues[i]);
    if (isolated) {
      EXPECT_NEAR(std::abs(cross(i, i)), 1.0, 1e-6) << "mode " << i;
    }
  }
  // Each mode satisfies K φ = λ M φ.
  for (int i = 0; i < 12; ++i) {
    const Eigen::VectorXd phi = sparse->shapes.col(i);
    EXPECT_LT((fem.stiffness * phi - sparse->eigenvalues[i] * (fem.mass * phi)).norm(),
              1e-7 * sparse->eigenvalues[i] * (fem.mass * phi).norm());
  }
}

TEST(Modal, FreeFreeBeamMatchesEulerBernoulliBendingFrequencies) {
  // A slender free-free beam, 1 × 0.05 × 0.05 (L/h = 20, where shear and rotary inertia move the first
  // three bending frequencies by under 3 %), unit material (E = ρ = 1, ν = 0.3), about 7,000 nodes:
  // fine enough that constant-strain tets, which are too stiff in bending, come within a few per cent.
  // Euler–Bernoulli: ω_n = (β_n L)² √(EI / ρA) / L², β_n L = 4.7300, 7.8532, 10.9956; I/A = h²/12.
  const double length = 1.0, h = 0.05;
  const TetMesh mesh =
      tetsOrDie(core::makeBox(Vec3(length, h, h)), {.maxRadiusEdgeRatio = 1.4, .maxVolumeFraction = 1e-4});
  Result<core::ModalData> modes =
      computeModes(mesh, ModalOptions{.modes = 8, .material = {.poissonRatio = 0.3}});
  ASSERT_TRUE(modes.ok()) << modes.error().message;
  const Eigen::VectorXd omega = modes->eigenvalues.cwiseSqrt();
  const auto eulerBernoulli = [&](double betaL) {
    return betaL * betaL * h / std::sqrt(12.0) / (length * length);
  };
  // Square section: each bending frequency twice (in y and in z); the torsion mode comes after the third.
  const double expected[6] = {eulerBernoulli(4.730041), eulerBernoulli(4.730041),  eulerBernoulli(7.853205),
                              eulerBernoulli(7.853205), eulerBernoulli(10.995608), eulerBernoulli(10.995608)};
  for (int i = 0; i < 6; ++i) {
    std::printf("beam (%zu nodes) mode %d: ω = %.5f, Euler–Bernoulli %.5f (%+.1f %%)\n", mesh.nodeCount(), i,
                omega[i], expected[i], 100.0 * (omega[i] / expected[i] - 1.0));
    EXPECT_NEAR(omega[i], expected[i], 0.05 * expected[i]) << "mode " << i;
  }
  for (double rigid : modes->rigidEigenvalues)
    EXPECT_LT(std::abs(rigid), 1e-6);
}

TEST(Modal, DisconnectedSolidIsAnError) {
  // Two separate cubes: twelve rigid modes, not six.
  TetMesh a = tetsOrDie(core::makeBox(Vec3(1, 1, 1)));
  const TetMesh b = tetsOrDie(core::makeBox(Vec3(1, 1, 1)));
  const auto offset = static_cast<std::uint32_t>(a.nodes.size());
  for (const Vec3& p : b.nodes)
    a.nodes.push_back(p + Vec3(3, 0, 0));
  for (auto tet : b.tets) {
    for (auto& v : tet)
      v += offset;
    a.tets.push_back(tet);
  }
  Result<core::ModalData> modes = computeModes(a, ModalOptions{.modes = 4, .material = {}});
  ASSERT_FALSE(modes.ok());
  EXPECT_NE(modes.error().message.find("rigid"), std::string::npos) << modes.error().message;
}

TEST(Tetrahedralize, TetVolumeIntegralsEqualSurfaceIntegrals) {
  for (const core::TriangleMesh& surface :
       {core::makeBox(Vec3(2, 1, 0.5)), core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.3), 24, 12),
        core::makeCone(0.5, 1.5, 20), core::makeCapsule(0.3, 1.0, 16, 4),
        core::makeTriangularPrism(1.0, 0.7, 2.0)}) {
    const TetMesh tets = tetsOrDie(surface);
    ASSERT_TRUE(core::validateTetMesh(tets).ok());
    const core::MassProperties fromTets = core::computeTetMassProperties(tets);
    Result<core::MassProperties> fromSurface = core::computeMassProperties(surface);
    ASSERT_TRUE(fromSurface.ok());
    EXPECT_NEAR(fromTets.volume, fromSurface->volume, 1e-9 * fromSurface->volume);
    EXPECT_LT((fromTets.centerOfMass - fromSurface->centerOfMass).norm(),
              1e-9 * std::cbrt(fromSurface->volume));
    EXPECT_LT((fromTets.inertia - fromSurface->inertia).norm(), 1e-9 * fromSurface->inertia.norm());
    // The tets' boundary is the input surface, refined: same area.
    EXPECT_NEAR(core::computeSurfaceArea(core::boundarySurface(tets)), fromSurface->area,
                1e-9 * fromSurface->area);
  }
}

TEST(Tetrahedralize, GuardedAndInProcessGiveTheSameMesh) {
  const core::TriangleMesh surface = core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.3), 16, 8);
  const TetMesh guarded = tetsOrDie(surface, {.guarded = true});
  const TetMesh local = tetsOrDie(surface, {.guarded = false});
  ASSERT_EQ(guarded.nodes.size(), local.nodes.size());
  ASSERT_EQ(guarded.tets, local.tets);
  for (std::size_t i = 0; i < local.nodes.size(); ++i)
    ASSERT_EQ(guarded.nodes[i], local.nodes[i]);
}

TEST(Tetrahedralize, BadInputIsAnErrorNotACrash) {
  core::TriangleMesh open = core::makeBox(Vec3(1, 1, 1));
  open.triangles.pop_back();
  Result<TetMesh> r = tetrahedralize(open);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotClosed);

  // Closed and oriented but self-intersecting: two overlapping cubes in one mesh. TetGen's own check.
  core::TriangleMesh overlap = core::makeBox(Vec3(1, 1, 1));
  const core::TriangleMesh other = core::transformed(core::makeBox(Vec3(1, 1, 1)), [] {
    core::Mat4 t = core::Mat4::Identity();
    t.topRightCorner<3, 1>() = Vec3(0.5, 0.3, 0.2);
    return t;
  }());
  const auto offset = static_cast<std::uint32_t>(overlap.vertices.size());
  overlap.vertices.insert(overlap.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (auto tri : other.triangles)
    overlap.triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
  r = tetrahedralize(overlap);
  ASSERT_FALSE(r.ok());
  std::printf("self-intersecting: %s\n", r.error().message.c_str());

  // The worker that crashed is replaced: the next mesh tetrahedralizes as before.
  const TetMesh after = tetsOrDie(core::makeBox(Vec3(1, 2, 3)));
  EXPECT_NEAR(core::computeTetMassProperties(after).volume, 6.0, 1e-12);
}

}  // namespace
}  // namespace shapedb::volume
