#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/primitives.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/tetrahedralize.h>

#include "cholmod_memory_limit.h"
#include "test_support.h"

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
  const FemMatrices fem =
      assembleFem(mesh, {.name = "test", .density = 2.0, .youngsModulus = 3.0, .poissonRatio = 0.25});
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

TEST(Fem, QuadraticReferenceMassIsTheClosedForm) {
  // ∫ N_a N_b dV / V of the 10-node tet, times 420: corners 6 (same) and 1 (two corners), corner and
  // edge −4 (the edge ends at the corner) or −6, edges 32 (same), 16 (sharing a corner), 8 (opposite).
  // (The classic table; its entries sum to 420: ∫ (Σ N)² = V.)
  const auto& edges = kQuadraticTetEdges;
  const auto touches = [&](int e, int corner) { return edges[e][0] == corner || edges[e][1] == corner; };
  const Eigen::Matrix<double, 10, 10>& m = quadraticReferenceMass();
  for (int a = 0; a < 10; ++a)
    for (int b = 0; b < 10; ++b) {
      double expected = 0.0;
      if (a < 4 && b < 4) {
        expected = a == b ? 6.0 : 1.0;
      } else if (a < 4 || b < 4) {
        const int corner = std::min(a, b), edge = std::max(a, b) - 4;
        expected = touches(edge, corner) ? -4.0 : -6.0;
      } else {
        const int e = a - 4, f = b - 4;
        const bool shared = touches(f, edges[e][0]) || touches(f, edges[e][1]);
        expected = e == f ? 32.0 : shared ? 16.0 : 8.0;
      }
      EXPECT_NEAR(420.0 * m(a, b), expected, 1e-12) << a << ", " << b;
    }
  EXPECT_NEAR(m.sum(), 1.0, 1e-14);
}

// The closed form against the product it replaces: Bᵀ D B (B the strain–displacement matrix in Voigt
// order with engineering shears, D the isotropic elasticity) summed over the four-point rule, on random
// tets and materials.
TEST(Fem, QuadraticElementStiffnessIsTheVoigtProduct) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), poisson(0.0, 0.49), modulus(0.1, 10.0);
  const double a = 0.5854101966249685, b = 0.1381966011250105;
  const std::array<Eigen::Vector4d, 4> points{Eigen::Vector4d(a, b, b, b), Eigen::Vector4d(b, a, b, b),
                                              Eigen::Vector4d(b, b, a, b), Eigen::Vector4d(b, b, b, a)};
  for (int trial = 0; trial < 50; ++trial) {
    std::array<Vec3, 4> corners;
    for (Vec3& p : corners)
      p = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
    const auto [grad, volume] = core::tetGradients(corners);
    if (std::abs(volume) < 1e-3) continue;
    const core::Material material{
        .name = "test", .density = 1.0, .youngsModulus = modulus(rng), .poissonRatio = poisson(rng)};
    const double e = material.youngsModulus, nu = material.poissonRatio;
    const double lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = e / (2.0 * (1.0 + nu));
    Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
    d.topLeftCorner<3, 3>().setConstant(lambda);
    d.topLeftCorner<3, 3>().diagonal().array() += 2.0 * mu;
    d.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
    Eigen::Matrix<double, 30, 30> expected = Eigen::Matrix<double, 30, 30>::Zero();
    for (const Eigen::Vector4d& l : points) {
      const Eigen::Matrix<double, 3, 10> g = quadraticGradients(grad, l);
      Eigen::Matrix<double, 6, 30> strain = Eigen::Matrix<double, 6, 30>::Zero();
      for (int n = 0; n < 10; ++n) {
        strain(0, 3 * n) = strain(4, 3 * n + 2) = strain(5, 3 * n + 1) = g(0, n);
        strain(1, 3 * n + 1) = strain(3, 3 * n + 2) = strain(5, 3 * n) = g(1, n);
        strain(2, 3 * n + 2) = strain(3, 3 * n + 1) = strain(4, 3 * n) = g(2, n);
      }
      expected += (std::abs(volume) / 4.0) * strain.transpose() * d * strain;
    }
    const Eigen::Matrix<double, 30, 30> ke = quadraticElementStiffness(grad, std::abs(volume), material);
    EXPECT_LT((ke - expected).norm(), 1e-12 * expected.norm()) << "trial " << trial;
  }
}

/// Displacements of every node of either mesh from a function of position.
template <typename Field>
Eigen::VectorXd interpolate(const std::vector<Vec3>& nodes, Field field) {
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i)
    u.segment<3>(3 * static_cast<Eigen::Index>(i)) = field(nodes[i]);
  return u;
}

TEST(Fem, BothOrdersIntegrateUniformStrainAndSecondMomentsExactly) {
  const TetMesh mesh = tetsOrDie(core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.3), 16, 8));
  const QuadraticTetMesh quadratic = makeQuadratic(mesh);
  ASSERT_EQ(quadratic.cornerCount, mesh.nodeCount());
  for (std::size_t i = 0; i < mesh.nodeCount(); ++i)
    ASSERT_EQ(quadratic.nodes[i], mesh.nodes[i]);
  const core::MassProperties tets = core::computeTetMassProperties(mesh);
  const core::Mat3 covariance = core::covarianceFromInertia(tets.inertia);
  const core::Material material{.name = "test", .density = 2.0, .youngsModulus = 3.0, .poissonRatio = 0.25};
  const double lambda = 3.0 * 0.25 / (1.25 * 0.5), mu = 3.0 / 2.5;
  // u = E x with E symmetric: uniform strain E, energy density λ (tr E)² / 2 + μ E:E.
  core::Mat3 strain;
  strain << 0.3, 0.1, -0.2, 0.1, -0.5, 0.05, -0.2, 0.05, 0.7;
  const double energy =
      tets.volume * (0.5 * lambda * strain.trace() * strain.trace() + mu * strain.cwiseProduct(strain).sum());
  const auto check = [&](const std::vector<Vec3>& nodes, const FemMatrices& fem, const char* order) {
    const Eigen::VectorXd u = interpolate(nodes, [&](const Vec3& p) -> Vec3 { return strain * p; });
    EXPECT_NEAR(0.5 * u.dot(fem.stiffness * u), energy, 1e-10 * energy) << order;
    const Eigen::VectorXd rotation =
        interpolate(nodes, [](const Vec3& p) { return Vec3(-p.y(), p.x(), 0.0); });
    EXPECT_LT((fem.stiffness * rotation).norm(), 1e-10 * fem.stiffness.norm() * rotation.norm()) << order;
    // uᵀMu for u = x e_x: ρ ∫ x² dV (x is in both spaces; so is x², which the mass integrates exactly).
    const Eigen::VectorXd ux =
        interpolate(nodes, [&](const Vec3& p) { return Vec3(p.x() - tets.centerOfMass.x(), 0.0, 0.0); });
    EXPECT_NEAR(ux.dot(fem.mass * ux), 2.0 * covariance(0, 0), 1e-12 * covariance(0, 0)) << order;
  };
  check(mesh.nodes, assembleFem(mesh, material), "linear");
  check(quadratic.nodes, assembleFem(quadratic, material), "quadratic");
}

TEST(Modal, QuadraticSparseAgreesWithDenseAndModesAreMOrthonormal) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.3, 0.9, 0.6)), {.maxVolumeFraction = 1.0 / 12.0});
  const QuadraticTetMesh quadratic = makeQuadratic(mesh);
  ASSERT_LT(quadratic.nodeCount(), 400u);
  const ModalOptions options{
      .modes = 10, .material = core::unitMaterial(), .order = ElementOrder::kQuadratic};
  Result<core::ModalData> full = computeModes(quadratic, options);
  Result<core::ModalData> corners = computeModes(mesh, options);
  Result<core::ModalData> dense = computeModesDense(mesh, options);
  ASSERT_TRUE(full.ok()) << full.error().message;
  ASSERT_TRUE(corners.ok()) << corners.error().message;
  ASSERT_TRUE(dense.ok()) << dense.error().message;
  ASSERT_EQ(full->shapes.rows(), 3 * static_cast<Eigen::Index>(quadratic.nodeCount()));
  ASSERT_EQ(corners->shapes.rows(), 3 * static_cast<Eigen::Index>(mesh.nodeCount()));
  for (int i = 0; i < 10; ++i) {
    EXPECT_NEAR(full->eigenvalues[i], dense->eigenvalues[i], 1e-8 * dense->eigenvalues[i]) << "mode " << i;
    EXPECT_EQ(corners->eigenvalues[i], full->eigenvalues[i]);
  }
  EXPECT_EQ(corners->shapes, full->shapes.topRows(corners->shapes.rows()));
  const FemMatrices fem = assembleFem(quadratic, options.material);
  const Eigen::MatrixXd gram = full->shapes.transpose() * fem.mass * full->shapes;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(10, 10)).cwiseAbs().maxCoeff(), 1e-9);
  for (int i = 0; i < 10; ++i) {
    const Eigen::VectorXd phi = full->shapes.col(i);
    EXPECT_LT((fem.stiffness * phi - full->eigenvalues[i] * (fem.mass * phi)).norm(),
              1e-7 * full->eigenvalues[i] * (fem.mass * phi).norm());
  }
}

TEST(Modal, QuadraticTetsDoNotLockInBending) {
  // A plate 5 : 4 : 1 of a few hundred tets, one or two through its thickness. Constant-strain tets
  // cannot bend without shearing and come out far too stiff (+84 %); quadratic ones on the same mesh are
  // within 2 % of quadratic ones on a mesh six times finer (+1.1 %).
  const core::TriangleMesh plate = core::makeBox(Vec3(1.0, 0.8, 0.2));
  const TetMesh coarse = tetsOrDie(plate, {.maxVolumeFraction = 1.0 / 150.0});
  const TetMesh fine = tetsOrDie(plate, {.maxVolumeFraction = 1.0 / 1200.0});
  const auto first = [](const TetMesh& mesh, ElementOrder order) {
    Result<core::ModalData> m =
        computeModes(mesh, {.modes = 4, .material = core::unitMaterial(), .order = order});
    EXPECT_TRUE(m.ok()) << (m ? "" : m.error().message);
    return m ? std::sqrt(m->eigenvalues[0]) : 0.0;
  };
  const double linear = first(coarse, ElementOrder::kLinear),
               quadratic = first(coarse, ElementOrder::kQuadratic),
               reference = first(fine, ElementOrder::kQuadratic);
  std::printf("plate: %zu tets, ω1 linear %.4f, quadratic %.4f; %zu tets, quadratic %.4f\n",
              coarse.tetCount(), linear, quadratic, fine.tetCount(), reference);
  EXPECT_NEAR(quadratic, reference, 0.02 * reference);
  EXPECT_GE(quadratic, reference * (1.0 - 1e-9));  // a coarser conforming mesh is stiffer, never softer
  EXPECT_GT(linear, 1.2 * reference);
}

TEST(Modal, SparseLanczosAgreesWithDenseSolverAndModesAreMOrthonormal) {
  // A small asymmetric solid (no repeated frequencies to blur the comparison of mode shapes).
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.3, 0.9, 0.6)), {.maxVolumeFraction = 1.0 / 150.0});
  ASSERT_LT(mesh.nodeCount(), 500u);
  ModalOptions options;
  options.modes = 12;
  options.order = ElementOrder::kLinear;
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

// Lanczos started from given vectors (the geometry correction's seeds: an entry's modes on moved nodes)
// finds the same modes as the dense oracle, whatever the seeds: random ones here, for both orders. On
// these few nodes, random seeds fill the block Lanczos's basis before it converges, and the restarted
// Lanczos from the seeds' sum finishes: this checks the way out (the next test, the block's answers).
TEST(Modal, SeededLanczosAgreesWithTheDenseSolverForRandomSeeds) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.3, 0.9, 0.6)), {.maxVolumeFraction = 1.0 / 15.0});
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (ElementOrder order : {ElementOrder::kLinear, ElementOrder::kQuadratic}) {
    const ModalOptions options{.modes = 6, .material = core::unitMaterial(0.3), .order = order};
    Result<core::ModalData> dense = computeModesDense(mesh, options);
    ASSERT_TRUE(dense.ok()) << dense.error().message;
    for (int trial = 0; trial < 2; ++trial) {
      Eigen::MatrixXd seeds(3 * static_cast<Eigen::Index>(mesh.nodeCount()), 1 + trial * 5);
      for (Eigen::Index i = 0; i < seeds.size(); ++i)
        seeds.data()[i] = normal(rng);
      int solves = 0;
      Result<core::ModalData> seeded = computeModesFrom(mesh, seeds, options, &solves);
      ASSERT_TRUE(seeded.ok()) << seeded.error().message;
      EXPECT_GT(solves, 0);
      // Converged to a relative residual of 1e-4: eigenvalues to its square, ~1e-8, and the shapes of
      // modes isolated by over 1 % to the residual over that gap, an angle of 1e-2 (1 − cos ≈ 5e-5) at most.
      for (int m = 0; m < 6; ++m) {
        EXPECT_NEAR(seeded->eigenvalues[m] / dense->eigenvalues[m], 1.0, 1e-8)
            << toString(order) << " trial " << trial << " mode " << m;
        const bool isolated = (m == 0 || dense->eigenvalues[m] > 1.01 * dense->eigenvalues[m - 1]) &&
                              (m == 5 || dense->eigenvalues[m + 1] > 1.01 * dense->eigenvalues[m]);
        if (!isolated) continue;
        const Eigen::VectorXd a = seeded->shapes.col(m), b = dense->shapes.col(m);
        EXPECT_NEAR(std::abs(a.dot(b)) / (a.norm() * b.norm()), 1.0, 1e-4)
            << toString(order) << " trial " << trial << " mode " << m;
      }
    }
  }
  // Seeds of the wrong size are an error.
  EXPECT_EQ(computeModesFrom(mesh, Eigen::MatrixXd::Ones(5, 2), ModalOptions{}).error().code,
            ErrorCode::kInvalidArgument);
}

// A seeded solve whose answer is no longer wanted gives up when told (ModalOptions::cancel): a flag that
// is set ends it with kCancelled; one that stays clear changes nothing, to the bit.
TEST(Modal, ASeededSolveGivesUpWhenCancelledAndIsUnchangedWhenNot) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.2, 1.0, 0.7)), {.maxVolumeFraction = 1.0 / 30.0});
  const ModalOptions options{.modes = 8, .material = core::unitMaterial(0.3)};
  const Result<core::ModalData> reference = computeModes(mesh, options);
  ASSERT_TRUE(reference.ok()) << reference.error().message;
  const Result<core::ModalData> plain = computeModesFrom(mesh, reference->shapes, options);
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  std::atomic<bool> cancel{false};
  ModalOptions cancellable = options;
  cancellable.cancel = &cancel;
  const Result<core::ModalData> uncancelled = computeModesFrom(mesh, reference->shapes, cancellable);
  ASSERT_TRUE(uncancelled.ok()) << uncancelled.error().message;
  EXPECT_EQ(uncancelled->eigenvalues, plain->eigenvalues);
  EXPECT_EQ(uncancelled->shapes, plain->shapes);
  cancel = true;
  const Result<core::ModalData> cancelled = computeModesFrom(mesh, reference->shapes, cancellable);
  ASSERT_FALSE(cancelled.ok());
  EXPECT_EQ(cancelled.error().code, ErrorCode::kCancelled);
}

// A plan (ModalOptions::plan) keeps the first seeded solve's symbolic analysis for the next solves of the
// same tets, wherever their nodes have moved: every solve with it gives what the same solve without one
// gives, to the bit, for the plan's tets and for any others, which leave it as it was.
TEST(Modal, APlanServesItsTetsWhereverTheirNodesAreAndChangesNoBit) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.2, 1.0, 0.7)), {.maxVolumeFraction = 1.0 / 30.0});
  const TetMesh other = tetsOrDie(core::makeCylinder(0.5, 1.5, 16), {.maxVolumeFraction = 1.0 / 30.0});
  TetMesh moved = mesh;  // the same tets over other nodes: an affine stretch and a bend
  for (Vec3& p : moved.nodes)
    p = Vec3(1.3 * p.x(), 0.8 * p.y() + 0.2 * p.x() * p.x(), p.z());
  const ModalOptions options{.modes = 8, .material = core::unitMaterial(0.3)};
  const Result<core::ModalData> seeds = computeModes(mesh, options);
  const Result<core::ModalData> otherSeeds = computeModes(other, options);
  ASSERT_TRUE(seeds.ok() && otherSeeds.ok());
  const auto expectSame = [](const Result<core::ModalData>& a, const Result<core::ModalData>& b,
                             const char* what) {
    ASSERT_TRUE(a.ok() && b.ok()) << what;
    EXPECT_EQ(a->eigenvalues, b->eigenvalues) << what;
    EXPECT_EQ(a->shapes, b->shapes) << what;
  };
  for (const ElementOrder order : {ElementOrder::kQuadratic, ElementOrder::kLinear}) {
    ModalOptions bare = options;
    bare.order = order;
    ModalPlan plan;
    ModalOptions planned = bare;
    planned.plan = &plan;
    EXPECT_FALSE(plan.ready());
    expectSame(computeModesFrom(mesh, seeds->shapes, planned), computeModesFrom(mesh, seeds->shapes, bare),
               "the solve that makes the analysis");
    EXPECT_TRUE(plan.ready());
    expectSame(computeModesFrom(moved, seeds->shapes, planned), computeModesFrom(moved, seeds->shapes, bare),
               "the same tets moved, on the kept analysis");
    expectSame(computeModesFrom(other, otherSeeds->shapes, planned),
               computeModesFrom(other, otherSeeds->shapes, bare), "other tets, which ignore the plan");
    ModalOptions otherOrder = planned;
    otherOrder.order = order == ElementOrder::kQuadratic ? ElementOrder::kLinear : ElementOrder::kQuadratic;
    ModalOptions otherOrderBare = otherOrder;
    otherOrderBare.plan = nullptr;
    expectSame(computeModesFrom(mesh, seeds->shapes, otherOrder),
               computeModesFrom(mesh, seeds->shapes, otherOrderBare), "the other element order");
    expectSame(computeModesFrom(moved, seeds->shapes, planned), computeModesFrom(moved, seeds->shapes, bare),
               "the plan's tets again, after the others");
  }
}

// The seeded solve is block Lanczos, which hands over to the restarted single-vector Lanczos (Spectra's)
// when its seeds span fewer directions than its block; either way its modes are those of the restarted
// solver from a random start (computeModes). A cube's quadratic tets have repeated frequencies (its
// symmetry): where several modes share a frequency, each seeded shape lies in the plane or space of the
// reference's shapes at that frequency.
TEST(Modal, SeededBlockLanczosAgreesWithTheRestartedLanczos) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.0, 1.0, 1.0)), {.maxVolumeFraction = 1.0 / 60.0});
  const ModalOptions options{.modes = 12, .material = core::unitMaterial(0.3)};
  const Result<core::ModalData> reference = computeModes(mesh, options);
  ASSERT_TRUE(reference.ok()) << reference.error().message;
  const auto rows = 3 * static_cast<Eigen::Index>(mesh.nodeCount());
  std::mt19937 rng(13);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd random(rows, 12);
  for (Eigen::Index i = 0; i < random.size(); ++i)
    random.data()[i] = normal(rng);
  const Eigen::MatrixXd same = random.col(0).replicate(1, 6);  // one direction: the restarted solver
  const Eigen::MatrixXd near = reference->shapes + 0.1 * random;
  for (const auto& [name, seeds] : {std::pair{"random", random}, {"one direction", same}, {"near", near}}) {
    int solves = 0;
    const Result<core::ModalData> seeded = computeModesFrom(mesh, seeds, options, &solves);
    ASSERT_TRUE(seeded.ok()) << name << ": " << seeded.error().message;
    EXPECT_GT(solves, 0) << name;
    for (int m = 0; m < options.modes; ++m) {
      EXPECT_NEAR(seeded->eigenvalues[m] / reference->eigenvalues[m], 1.0, 1e-8) << name << " mode " << m;
      // The reference's modes of the same frequency (to 1e-6).
      int first = m, last = m;
      while (first > 0 && reference->eigenvalues[first - 1] > (1.0 - 1e-6) * reference->eigenvalues[m])
        --first;
      while (last + 1 < options.modes &&
             reference->eigenvalues[last + 1] < (1.0 + 1e-6) * reference->eigenvalues[m])
        ++last;
      const Eigen::MatrixXd span = reference->shapes.middleCols(first, last - first + 1);
      const Eigen::VectorXd x = seeded->shapes.col(m);
      const Eigen::VectorXd outside = x - span * span.colPivHouseholderQr().solve(x);
      EXPECT_LT(outside.norm(), 1e-3 * x.norm())
          << name << " mode " << m << " (modes " << first << "-" << last << ")";
    }
  }
}

// Masses lumped at nodes (the geometry correction's missing mass): the sparse solver, plain and seeded,
// against the dense oracle with the same masses, for both orders; every frequency falls (Rayleigh: more
// mass, the same stiffness); and masses that do not fit the mesh are refused.
TEST(Modal, PointMassesAgreeWithTheDenseSolver) {
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(1.3, 0.9, 0.6)), {.maxVolumeFraction = 1.0 / 15.0});
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> masses(mesh.nodeCount(), 0.0);
  for (double& m : masses)
    if (uniform(rng) < 0.3) m = 0.05 * uniform(rng);
  for (ElementOrder order : {ElementOrder::kLinear, ElementOrder::kQuadratic}) {
    const ModalOptions bare{.modes = 6, .material = core::unitMaterial(0.3), .order = order};
    ModalOptions options = bare;
    options.pointMasses = masses;
    Result<core::ModalData> dense = computeModesDense(mesh, options);
    Result<core::ModalData> sparse = computeModes(mesh, options);
    Result<core::ModalData> without = computeModes(mesh, bare);
    ASSERT_TRUE(dense.ok()) << dense.error().message;
    ASSERT_TRUE(sparse.ok()) << sparse.error().message;
    ASSERT_TRUE(without.ok()) << without.error().message;
    int solves = 0;
    Result<core::ModalData> seeded = computeModesFrom(mesh, without->shapes, options, &solves);
    ASSERT_TRUE(seeded.ok()) << seeded.error().message;
    for (int m = 0; m < 6; ++m) {
      EXPECT_NEAR(sparse->eigenvalues[m] / dense->eigenvalues[m], 1.0, 1e-8)
          << toString(order) << " mode " << m;
      EXPECT_NEAR(seeded->eigenvalues[m] / dense->eigenvalues[m], 1.0, 1e-8)
          << toString(order) << " mode " << m;
      EXPECT_LT(sparse->eigenvalues[m], without->eigenvalues[m]) << toString(order) << " mode " << m;
    }
  }
  ModalOptions wrong{.modes = 6};
  wrong.pointMasses.assign(mesh.nodeCount() + 1, 0.0);
  EXPECT_EQ(computeModes(mesh, wrong).error().code, ErrorCode::kInvalidArgument);
  wrong.pointMasses.assign(mesh.nodeCount(), -1.0);
  EXPECT_EQ(computeModes(mesh, wrong).error().code, ErrorCode::kInvalidArgument);
}

TEST(Modal, FreeFreeBeamOfLinearTetsMatchesEulerBernoulliWhenFine) {
  // A slender free-free beam, 1 × 0.05 × 0.05 (L/h = 20, where shear and rotary inertia move the first
  // three bending frequencies by under 3 %), unit material (E = ρ = 1, ν = 0.3), about 7,000 nodes:
  // fine enough that constant-strain tets, which are too stiff in bending, come within a few per cent.
  // Euler–Bernoulli: ω_n = (β_n L)² √(EI / ρA) / L², β_n L = 4.7300, 7.8532, 10.9956; I/A = h²/12.
  const double length = 1.0, h = 0.05;
  const TetMesh mesh =
      tetsOrDie(core::makeBox(Vec3(length, h, h)), {.maxRadiusEdgeRatio = 1.4, .maxVolumeFraction = 1e-4});
  Result<core::ModalData> modes = computeModes(
      mesh, ModalOptions{.modes = 8, .material = core::unitMaterial(0.3), .order = ElementOrder::kLinear});
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

// The database's default: quadratic tets at an entry's meshing (entryMeshing), a few hundred tets on the
// same beam, where linear ones ring tens of per cent high. Within 1.5 % of Euler–Bernoulli; at L/h = 20
// shear and rotary inertia lower the true first frequency by about 0.7 %.
TEST(Modal, FreeFreeBeamAtTheDefaultQuadraticMeshingMatchesEulerBernoulli) {
  const double length = 1.0, h = 0.05;
  const TetMesh mesh = tetsOrDie(core::makeBox(Vec3(length, h, h)), entryMeshing(ElementOrder::kQuadratic));
  Result<core::ModalData> modes =
      computeModes(mesh, ModalOptions{.modes = 4, .material = core::unitMaterial(0.3)});
  ASSERT_TRUE(modes.ok()) << modes.error().message;
  const double expected = 4.730041 * 4.730041 * h / std::sqrt(12.0) / (length * length);
  for (int i = 0; i < 2; ++i) {  // bending in y and in z
    const double omega = std::sqrt(modes->eigenvalues[i]);
    std::printf("beam (%zu quadratic tets) mode %d: ω = %.5f, Euler–Bernoulli %.5f (%+.2f %%)\n",
                mesh.tetCount(), i, omega, expected, 100.0 * (omega / expected - 1.0));
    EXPECT_NEAR(omega, expected, 0.015 * expected) << "mode " << i;
  }
}

// A hollow ball (its wall a fifth of its radius) rings well below the solid one of the same radius, as
// a thick spherical shell should (its lowest mode bends the wall): the tets leave the cavity empty. Filled,
// as TetGen fills a cavity it is not told of, the two would ring alike.
TEST(Modal, AHollowBallRingsBelowTheSolidOne) {
  const core::TriangleMesh solid = core::makeIcosphere(1.0, 3);
  const core::TriangleMesh hollow = test::withShell(solid, core::makeIcosphere(0.8, 3), Vec3::Zero(), true);
  const ModalOptions options{.modes = 3, .material = core::unitMaterial(0.3)};
  const TetMesh solidTets = tetsOrDie(solid, {.maxVolumeFraction = 1.0 / 300.0});
  const TetMesh hollowTets = tetsOrDie(hollow, {.maxVolumeFraction = 1.0 / 300.0});
  Result<core::ModalData> a = computeModes(solidTets, options);
  Result<core::ModalData> b = computeModes(hollowTets, options);
  ASSERT_TRUE(a.ok()) << a.error().message;
  ASSERT_TRUE(b.ok()) << b.error().message;
  EXPECT_LT(b->eigenvalues[0], 0.5 * a->eigenvalues[0]);  // frequencies: below 0.71 of the solid's
  EXPECT_NEAR(core::computeTetMassProperties(hollowTets).volume, core::computeMassProperties(hollow)->volume,
              1e-9);
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
  Result<core::ModalData> modes = computeModes(a, ModalOptions{.modes = 4, .material = core::unitMaterial()});
  ASSERT_FALSE(modes.ok());
  EXPECT_NE(modes.error().message.find("rigid"), std::string::npos) << modes.error().message;
}

// A factorization that runs out of memory says so, with the factor's size, rather than blaming the tets;
// with the memory back, the same mesh has its modes.
TEST(Modal, AFactorizationOutOfMemoryIsSaidSo) {
  std::mt19937_64 rng(21);
  const TetMesh grid = test::makeTetGrid(8, 8, 8, 0.1, rng);
  const ModalOptions options{.modes = 4, .material = core::unitMaterial(0.3), .order = ElementOrder::kLinear};
  {
    const test::CholmodMemoryLimit limit(std::size_t{1} << 20);
    const Result<core::ModalData> refused = computeModes(grid, options);
    ASSERT_FALSE(refused.ok());
    std::printf("%s\n", refused.error().message.c_str());
    EXPECT_EQ(refused.error().code, ErrorCode::kTooLarge);
    EXPECT_NE(
        refused.error().message.find("(2187 degrees of freedom) could not be factorized: out of memory"),
        std::string::npos)
        << refused.error().message;
    EXPECT_NE(refused.error().message.find("GB at least"), std::string::npos) << refused.error().message;
  }
  EXPECT_TRUE(computeModes(grid, options).ok());
}

}  // namespace
}  // namespace shapedb::volume
