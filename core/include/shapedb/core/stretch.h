#pragma once
// Stretch correction: an entry's modes carried to the entry stretched along its canonical axes, by
// Rayleigh–Ritz in the span of its own modes' displacement components.
//
// A retrieved entry rarely has the query's exact proportions: the database samples aspect ratios on a
// grid, and the descriptor weighs shape, not thickness. Frequencies are very sensitive to proportions (a
// plate's bending frequency is proportional to its thickness), so the paper's uniform scaling carries the
// grid's spacing straight into the error. Stretched along its principal axes until its second moments
// equal the query's, the entry keeps the character the descriptor matched and gains the proportions
// that an inertia-equivalent box has: its frequencies are then estimated without a new eigensolve.
//
// Rayleigh–Ritz needs a subspace that holds the stretched body's low modes. The entry's modes carried
// over node for node do not: a plate's bending mode ties its in-plane displacements to the slope of its
// deflection through the thickness, and a stretch that changes thickness and span differently breaks the
// tie (shear appears, the plate comes out far too stiff). So each mode is split into its x, y and z
// displacement fields, 3m vectors that can be rescaled independently, and the stretched body's three
// rigid rotations are projected out (their stiffness is zero, so only the projected mass changes);
// otherwise the Ritz values would mix rigid motion in and come out too low.
//
// For linear tets and a stretch x' = diag(a) x, the shape-function gradients become diag(g) ∇N with
// g = 1/a, the volume det(a) V: the split modes' stiffness is a quadratic form in g over matrices fixed
// per entry, their mass is fixed (det(a) cancels). A stretch then costs one 3m × 3m eigenproblem.
#include <array>

#include <Eigen/Dense>

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// What the correction needs of an entry, from its tet mesh and modes (unit density and Young's
/// modulus, the modes' Poisson ratio), with H_ij the T × m matrix of ∂_i φ_j per tet (weighted by √V).
/// O(T·m²) to compute; 18·m² + 9·m numbers.
struct StretchBasis {
  /// Per pair of displacement components (j, l), j ≤ l, in the order 00, 11, 22, 01, 02, 12:
  /// λ H_jjᵀ H_ll + μ H_ljᵀ H_jl, the block (j, l) of the split modes' stiffness, times g_j g_l.
  std::array<Eigen::MatrixXd, 6> coupling;
  /// Per (i, j), index 3i + j: μ H_ijᵀ H_ij, added to the block (j, j) times g_i².
  std::array<Eigen::MatrixXd, 9> shear;
  /// Per component j: ∫ φ_j φ_jᵀ dV (unit density), the block (j, j) of the split modes' mass.
  std::array<Eigen::MatrixXd, 3> mass;
  /// ∫ x_a φ_b dV (unit density) of each mode: row 3a + b, column = mode.
  Eigen::Matrix<double, 9, Eigen::Dynamic> firstMoments;
  /// The tet mesh's centre of mass (≈ the origin of the canonical frame) and ∫ (x − c)(x − c)ᵀ dV,
  /// from computeTetMassProperties.
  Vec3 centroid = Vec3::Zero();
  Mat3 secondMoments = Mat3::Zero();
  std::size_t modeCount() const { return static_cast<std::size_t>(firstMoments.cols()); }
};

/// The basis of an entry. Preconditions: validateTetMesh(mesh) passed and `modes` are its modes
/// (shapes 3·nodes × m). Thread-safe (pure function).
StretchBasis computeStretchBasis(const TetMesh& mesh, const ModalData& modes);

/// The entry's modes for its tet mesh stretched by `stretch` along x, y, z.
struct StretchedModes {
  Vec3 stretch = Vec3::Ones();
  /// λ of the stretched body's first m modes, ascending (Ritz values: each ≥ the stretched body's own;
  /// at a = 1 the entry's own).
  Eigen::VectorXd eigenvalues;
  /// 3·nodes × m on the unstretched nodes (the stretched body's displacements at its nodes are the
  /// same numbers), M-orthonormal for the unstretched mesh's mass matrix.
  Eigen::MatrixXd shapes;
};

/// Rayleigh–Ritz for the stretched mesh. Errors: kInvalidArgument when `stretch` is not finite and
/// positive or the basis does not fit the modes or the mesh; kInvalidArgument when fewer than m
/// independent directions are left once the rotations are projected out. Thread-safe.
Result<StretchedModes> stretchModes(const StretchBasis& basis, const ModalData& modes, const TetMesh& mesh,
                                    const Vec3& stretch);

/// The per-axis stretch that gives a body with second moments `body` (∫ x xᵀ dV, its own principal
/// frame) those of `target` along the same axes: a_k = sqrt(target_kk / body_kk).
Vec3 momentMatchingStretch(const Mat3& body, const Mat3& target);

}  // namespace shapedb::core
