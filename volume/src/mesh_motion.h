#pragma once
// The mesh-motion stiffness that carries a morph's boundary displacement into a tet mesh, assembled as
// often as the mesh moves: a morph assembles it once per interior increment and fits the registration with
// it. The tets fix its sparsity (a 3 × 3 block for every two nodes that share a tet), so it is laid out once
// and assembled again by writing values only, and the interior's system keeps one symbolic factorization.
// Private to the volume module.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>

#include "node_neighbours.h"

namespace shapedb::volume::detail {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// Per node of a tet mesh, the nodes that share a tet with it, itself included, ascending.
inline NodeNeighbours nodeNeighbours(const core::TetMesh& mesh) {
  return nodeNeighbours(mesh.nodeCount(), mesh.tets);
}

/// Stiffness of the linear elastic body that carries a boundary displacement inwards (ν = 0.3,
/// constant-strain tets), each tet's modulus 1/V_t so that small tets, which a given displacement would
/// distort most, move most rigidly (the "Jacobian-based stiffening" of mesh-moving methods). Assembled
/// from triplets: the reference that MotionStiffness is tested against.
SparseMatrix meshMotionStiffness(const core::TetMesh& mesh);

/// meshMotionStiffness with its sparsity laid out once for a mesh's tets: assemble() on the nodes' current
/// positions writes values only (the same values, summed in another order). Holds the layout alone (the
/// nodes' neighbours and where each tet's blocks go), a few bytes per tet: kept beside a database entry
/// (volume::MorphPlan) and shared by its morphs, each assembling into a matrix of its own.
class MotionStiffness {
 public:
  explicit MotionStiffness(const core::TetMesh& mesh);

  /// A new matrix of K's sparsity, its values 0.
  SparseMatrix matrix() const;
  /// K at `mesh`'s node positions; `mesh` has the tets this was made for.
  SparseMatrix assemble(const core::TetMesh& mesh) const;
  /// The same into `into`, a matrix of K's sparsity (matrix()), its values overwritten.
  void assemble(const core::TetMesh& mesh, SparseMatrix& into) const;
  const NodeNeighbours& neighbours() const { return mNeighbours; }
  /// Index in matrix().valuePtr() of row 3u + i, column 3v + j; −1 when nodes u and v share no tet.
  Eigen::Index valueIndex(std::uint32_t u, std::uint32_t v, int i, int j) const;
  /// valueIndex(u, v, c, c) for c = 0, 1, 2 (one search); all −1 when u and v share no tet.
  std::array<Eigen::Index, 3> diagonalIndices(std::uint32_t u, std::uint32_t v) const;

 private:
  /// Where column 3v + j starts among K's values: column 3v + j holds rows 3u + i for every neighbour u of
  /// v (ascending) and i = 0, 1, 2.
  Eigen::Index columnStart(std::uint32_t v, int j) const {
    const std::uint32_t first = mNeighbours.start[v], degree = mNeighbours.start[v + 1] - first;
    return static_cast<Eigen::Index>(9 * first + 3 * static_cast<std::uint32_t>(j) * degree);
  }
  NodeNeighbours mNeighbours;
  /// Per tet, per (a, b): where node a sits among node b's neighbours.
  std::vector<std::array<std::uint32_t, 16>> mSlots;
};

/// Carries a boundary displacement into the interior of a mesh whose tets and boundary stay the same from
/// call to call: K_ii u_i = −K_ib u_b with K assembled on the mesh as it stands. Only what the system needs
/// is assembled, straight into K_ii and the right-hand side: the blocks of the rows of inner nodes, from
/// the tets that have one (a coarse entry's nodes are mostly on its boundary, and a morph extends tens of
/// increments). The inner system's sparsity and its fill-reducing order are worked out on the first call
/// and kept.
class InteriorMotion {
 public:
  /// What depends on the tets and the boundary alone: the mesh-motion stiffness's layout, the inner nodes'
  /// numbering, K_ii's sparsity and where each tet's blocks go in it. Immutable once made: shared by the
  /// motions of the same tets (volume::MorphPlan).
  struct Layout {
    Layout(const core::TetMesh& mesh, std::span<const char> isBoundary);
    MotionStiffness stiffness;
    std::vector<int> inner;         ///< per node: its index among the inner nodes, or −1
    std::vector<int> boundarySlot;  ///< per node: its index among the boundary nodes, or −1
    int innerCount = 0;
    std::vector<int> kiiOuter, kiiInner;  ///< K_ii's sparsity (compressed columns)
    /// A tet with an inner node, and per pair (a, b) of its nodes, both inner: where K_ii's block of rows
    /// a and columns b starts in K_ii's values (its column j is j lengths of b's K_ii columns further on);
    /// −1 where a or b is on the boundary.
    struct ActiveTet {
      std::uint32_t tet;
      std::array<int, 16> blockStart;
    };
    std::vector<ActiveTet> activeTets;
  };

  /// `isBoundary[v]`: node v's displacement is given.
  InteriorMotion(const core::TetMesh& mesh, std::span<const char> isBoundary);
  /// On a layout made before (for the same tets and boundary), shared.
  explicit InteriorMotion(std::shared_ptr<const Layout> layout);

  const std::shared_ptr<const Layout>& layout() const { return mLayout; }
  /// The mesh-motion stiffness of the same tets, laid out (for others to assemble on them).
  const MotionStiffness& stiffness() const { return mLayout->stiffness; }

  /// Moves `mesh`'s boundary nodes by `boundaryMove` (3 per boundary node, ascending node order) and its
  /// inner nodes as the elastic body would. Errors when the system cannot be factorized.
  Status extend(core::TetMesh& mesh, const Eigen::VectorXd& boundaryMove);
  /// extend from one configuration again and again: the first call (or one from other positions) assembles
  /// and factorizes the system at `mesh`'s positions as extend does, and keeps the factor and the right-hand
  /// side's blocks; a later call from the same positions reuses them. The same result as extend, to the bit.
  /// The morph's projection starts each of its attempts from one configuration.
  Status extendFromAnchor(core::TetMesh& mesh, const Eigen::VectorXd& boundaryMove);

 private:
  /// One block of −K_ib u_b: inner row `row` (an index among the inner nodes) takes `block` times the move
  /// of the boundary node in slot `slot`.
  struct RhsBlock {
    int row, slot;
    core::Mat3 block;
  };
  /// K_ii into mKii's values and −K_ib u_b at `mesh`'s positions, before `boundaryMove`; the blocks of the
  /// latter also into `blocks` where given, in the order they were added.
  Eigen::VectorXd assemble(const core::TetMesh& mesh, const Eigen::VectorXd& boundaryMove,
                           std::vector<RhsBlock>* blocks);
  /// Moves the boundary nodes by `boundaryMove` and the inner ones by `inner`.
  void move(core::TetMesh& mesh, const Eigen::VectorXd& boundaryMove, const Eigen::VectorXd& inner) const;

  std::shared_ptr<const Layout> mLayout;
  SparseMatrix mKii;  ///< K_ii of the layout's sparsity, with this motion's values
  Eigen::SimplicialLDLT<SparseMatrix> mSolver;
  bool mAnalyzed = false;
  /// extendFromAnchor's: the positions it was factorized at, its factor, its right-hand side's blocks.
  std::vector<core::Vec3> mAnchor;
  Eigen::SimplicialLDLT<SparseMatrix> mAnchorSolver;
  std::vector<RhsBlock> mAnchorBlocks;
};

}  // namespace shapedb::volume::detail
