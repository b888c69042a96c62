#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <shapedb/core/material.h>
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

/// Assembles K and M for `material` (the database uses core::unitMaterial(): frequencies then scale as
/// √(E/ρ), paper §5). Preconditions: core::validateTetMesh(mesh) passed; core::validPoissonRatio(ν).
FemMatrices assembleFem(const core::TetMesh& mesh, const core::Material& material = core::unitMaterial());

/// Quadratic (10-node) tets on a linear tet mesh, for bending: constant-strain tets lock, a plate two or
/// three tets thick comes out tens of per cent too stiff, while quadratic ones on the same mesh are within
/// a few per cent. The linear mesh's nodes come first with their own indices, then one node at the
/// midpoint of each edge; the edges are numbered in the order of their (smaller, larger) node pair.
struct QuadraticTetMesh {
  /// Corners 0–3 as in the linear tet, then the edges 01, 02, 03, 12, 13, 23.
  using Tet = std::array<std::uint32_t, 10>;
  std::vector<core::Vec3> nodes;
  std::vector<Tet> tets;
  std::size_t cornerCount = 0;  ///< the linear mesh's nodes: nodes[0, cornerCount)
  std::size_t nodeCount() const { return nodes.size(); }
};
QuadraticTetMesh makeQuadratic(const core::TetMesh& mesh);
/// The corners at the ends of the edges of QuadraticTetMesh::Tet, in order (nodes 4–9).
inline constexpr std::array<std::array<int, 2>, 6> kQuadraticTetEdges{
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

/// Shape functions of the 10-node tet at barycentric coordinates `l`: gradients (columns, node order of
/// QuadraticTetMesh::Tet) from the gradients of the barycentric coordinates (core::tetGradients).
Eigen::Matrix<double, 3, 10> quadraticGradients(const Eigen::Matrix<double, 3, 4>& barycentricGradients,
                                                const Eigen::Vector4d& l);

/// The reference scalar mass matrix of the 10-node tet: ∫ N_a N_b dV / V, exact.
const Eigen::Matrix<double, 10, 10>& quadraticReferenceMass();

/// The stiffness matrix of one 10-node tet of an isotropic `material` (30 × 30: x, y, z of each node in
/// the node order of QuadraticTetMesh::Tet), by the four-point rule that is exact for it, from the
/// gradients of the tet's barycentric coordinates and its volume (core::tetGradients). Per pair of nodes
/// the closed form of Bᵀ D B, λ ∇N_a ∇N_bᵀ + μ ∇N_b ∇N_aᵀ + μ (∇N_a · ∇N_b) I, in a quarter of its
/// arithmetic; tests compare it with the product.
Eigen::Matrix<double, 30, 30> quadraticElementStiffness(
    const Eigen::Matrix<double, 3, 4>& barycentricGradients, double volume, const core::Material& material);

/// K and M of the quadratic tets (stiffness by the exact four-point rule, consistent mass exact).
FemMatrices assembleFem(const QuadraticTetMesh& mesh, const core::Material& material = core::unitMaterial());

/// Which elements the modal analysis uses.
enum class ElementOrder : std::uint8_t { kLinear = 1, kQuadratic = 2 };
/// "linear", "quadratic", and back (nullopt for anything else).
const char* toString(ElementOrder order);
std::optional<ElementOrder> parseElementOrder(std::string_view name);

namespace detail {
struct ModalPlanState;
}

class ModalPlan;

/// How many modes, for which material, on which elements.
struct ModalOptions {
  int modes = 20;  ///< non-rigid modes wanted, ≥ 1
  core::Material material = core::unitMaterial();
  /// Quadratic (the default): the modes of the 10-node tets on the given mesh, their shapes reported at
  /// its nodes (the corners; the mid-edge values are dropped). Linear: constant-strain tets, which lock in
  /// bending (a plate two or three tets thick rings tens of per cent high) unless the mesh is very fine.
  ElementOrder order = ElementOrder::kQuadratic;
  /// Masses lumped at the mesh's nodes (the corners), one per node, added to the mass matrix's diagonal
  /// beside the tets' own; empty for none. The geometry correction puts there the mass of what its
  /// morphed tets do not reach. Each must be finite and ≥ 0.
  std::vector<double> pointMasses{};
  /// computeModesFrom only: when given, the solve gives up with kCancelled soon after this turns true
  /// (it is read before the assembly, after the factorization and at each step of the block Lanczos), for
  /// work whose answer may no longer be wanted (the geometry correction's speculative modes, io/database).
  const std::atomic<bool>* cancel = nullptr;
  /// computeModesFrom only: the connectivity's analysis, kept from one solve of the same tets to the next
  /// (ModalPlan); none where null.
  ModalPlan* plan = nullptr;
};

/// The first `modes` non-rigid modes of the free body, K φ = λ M φ, by shift-invert Lanczos (Spectra)
/// around a small negative shift, K − σM factorized once by sparse Cholesky (L Lᵀ), Lanczos run on the
/// symmetric L⁻¹ M L⁻ᵀ. The six smallest
/// eigenvalues must be the rigid modes (≈ 0 against the first elastic one); they are checked and
/// dropped. Mode shapes are M-orthonormal (quadratic order: over all ten nodes of each tet, before the
/// mid-edge values are dropped). Errors: kInvalidArgument (options, too few nodes), kParse when
/// the mesh is not one connected solid (more or fewer than six rigid modes) or Lanczos does not converge.
Result<core::ModalData> computeModes(const core::TetMesh& mesh, const ModalOptions& options = {});

/// The modes on every node of the quadratic mesh (shapes 3·quadratic.nodeCount() × m), M-orthonormal for
/// its mass matrix; computeModes of the quadratic order keeps their first 3·cornerCount rows.
Result<core::ModalData> computeModes(const QuadraticTetMesh& mesh, const ModalOptions& options = {});

/// computeModes started from approximate modes: `seeds` (3·mesh.nodeCount() × s, the corners' values;
/// s ≥ 1, typically the modes of a similar mesh, such as the entry a mesh was morphed from) start a block
/// Lanczos (four vectors a step, each a mixture of all the seeds; the restarted Lanczos of computeModes,
/// from the seeds' sum, where the block's basis fills first). The same modes as computeModes, converged
/// less far
/// (Lanczos stops at a relative residual of 1e-4, computeModes at 1e-10; on the default catalog's entries
/// the frequencies agree to ~1e-8 and the shapes, where the next frequency is over 1 % away, to ~1e-7),
/// in less time. `solves`, when given, receives the number of solves with the factorized K − σM (one per
/// vector of a block). Errors: computeModes', kInvalidArgument for seeds of the wrong size or not finite,
/// and kCancelled once options.cancel is true.
Result<core::ModalData> computeModesFrom(const core::TetMesh& mesh, const Eigen::MatrixXd& seeds,
                                         const ModalOptions& options, int* solves = nullptr);

/// What computeModesFrom works out from a tet mesh's connectivity alone, whatever its nodes' positions: the
/// symbolic analysis of its K − σM (the fill-reducing order, the factor's structure). The geometry
/// correction solves one database entry's tets, moved onto the query, at every query that entry answers:
/// given in ModalOptions::plan, a plan keeps the first solve's analysis, and the later solves of the same
/// tets factorize on it (the same factor and modes, to the bit, without a tenth of their time). It serves
/// the connectivity and element order it was first used with; a solve of other tets ignores it and
/// leaves it as it is. Thread-safe: concurrent solves may share one.
class ModalPlan {
 public:
  ModalPlan();
  ~ModalPlan();
  ModalPlan(const ModalPlan&) = delete;
  ModalPlan& operator=(const ModalPlan&) = delete;
  /// Whether a solve has left its analysis here.
  bool ready() const;

 private:
  friend Result<core::ModalData> computeModesFrom(const core::TetMesh&, const Eigen::MatrixXd&,
                                                  const ModalOptions&, int*);
  std::unique_ptr<detail::ModalPlanState> mState;
};

/// The oracle: the same modes from a dense generalized eigensolver over all 3n degrees of freedom
/// (Eigen's GeneralizedSelfAdjointEigenSolver, O(n³)), of options.order. For meshes of a few hundred nodes
/// (quadratic: nodes and edges): tests only.
Result<core::ModalData> computeModesDense(const core::TetMesh& mesh, const ModalOptions& options = {});

}  // namespace shapedb::volume
