#pragma once

#include <Eigen/SparseCore>

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>

namespace shapedb::volume {

/// Linear tetrahedral finite elements (constant strain) of an isotropic material: the stiffness matrix K
/// and the consistent mass matrix M, 3 degrees of freedom per node (x, y, z), both symmetric, lower and
/// upper triangles stored.
struct FemMatrices {
  Eigen::SparseMatrix<double> stiffness;
  Eigen::SparseMatrix<double> mass;
};

/// Material of the FEM: Young's modulus E (Pa), Poisson ratio ν, density ρ (kg/m³). The database uses
/// E = ρ = 1: frequencies then scale as √(E/ρ) (paper §5).
struct FemMaterial {
  double youngsModulus = 1.0;
  double poissonRatio = 0.3;
  double density = 1.0;
};

/// Assembles K and M. Preconditions: core::validateTetMesh(mesh) passed; 0 ≤ ν < 0.5.
FemMatrices assembleFem(const core::TetMesh& mesh, const FemMaterial& material = {});

/// How many modes, for which material.
struct ModalOptions {
  int modes = 20;  ///< non-rigid modes wanted, ≥ 1
  FemMaterial material;
};

/// The first `modes` non-rigid modes of the free body, K φ = λ M φ, by shift-invert Lanczos (Spectra)
/// around a small negative shift, K − σM factorized once by sparse Cholesky (LDLᵀ). The six smallest
/// eigenvalues must be the rigid modes (≈ 0 against the first elastic one); they are checked and
/// dropped. Mode shapes are M-orthonormal. Errors: kInvalidArgument (options, too few nodes), kParse when
/// the mesh is not one connected solid (more or fewer than six rigid modes) or Lanczos does not converge.
Result<core::ModalData> computeModes(const core::TetMesh& mesh, const ModalOptions& options = {});

/// The oracle: the same modes from a dense generalized eigensolver over all 3n degrees of freedom
/// (Eigen's GeneralizedSelfAdjointEigenSolver, O(n³)). For meshes of a few hundred nodes: tests only.
Result<core::ModalData> computeModesDense(const core::TetMesh& mesh, const ModalOptions& options = {});

}  // namespace shapedb::volume
