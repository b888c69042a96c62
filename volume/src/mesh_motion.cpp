#include "mesh_motion.h"

#include <algorithm>

namespace shapedb::volume::detail {
namespace {

using core::TetMesh;
using core::Vec3;

/// The 3 × 3 block of a tet's element stiffness in meshMotionStiffness for its nodes a and b, from their
/// shape functions' gradients: ∫ λ div u div v + μ (∇u + ∇uᵀ) : ∇v over the tet, times 1/V (the V
/// cancels).
core::Mat3 elementBlock(const Vec3& ga, const Vec3& gb) {
  constexpr double nu = 0.3, lambda = nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = 0.5 / (1.0 + nu);
  return lambda * ga * gb.transpose() + mu * gb * ga.transpose() + mu * ga.dot(gb) * core::Mat3::Identity();
}

/// Calls sink(a, b, block) with each 3 × 3 block of tet t's element stiffness (elementBlock).
template <class Sink>
void forEachElementBlock(const TetMesh& mesh, std::size_t t, Sink&& sink) {
  const auto [grad, volume] = core::tetGradients(mesh, t);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      sink(a, b, elementBlock(grad.col(a), grad.col(b)));
}

}  // namespace

SparseMatrix meshMotionStiffness(const TetMesh& mesh) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(144 * mesh.tetCount());
  for (std::size_t t = 0; t < mesh.tetCount(); ++t)
    forEachElementBlock(mesh, t, [&](int a, int b, const core::Mat3& block) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          triplets.emplace_back(3 * static_cast<int>(mesh.tets[t][static_cast<std::size_t>(a)]) + i,
                                3 * static_cast<int>(mesh.tets[t][static_cast<std::size_t>(b)]) + j,
                                block(i, j));
    });
  const auto n = static_cast<Eigen::Index>(3 * mesh.nodeCount());
  SparseMatrix k(n, n);
  k.setFromTriplets(triplets.begin(), triplets.end());
  return k;
}

MotionStiffness::MotionStiffness(const TetMesh& mesh) : mNeighbours(nodeNeighbours(mesh)) {
  mNeighbours.nodes.shrink_to_fit();  // kept beside a database entry (volume::MorphPlan)
  mSlots.resize(mesh.tetCount());
  for (std::size_t t = 0; t < mesh.tetCount(); ++t)
    for (std::size_t a = 0; a < 4; ++a)
      for (std::size_t b = 0; b < 4; ++b) {
        const std::uint32_t u = mesh.tets[t][a], v = mesh.tets[t][b];
        const auto begin = mNeighbours.nodes.begin() + mNeighbours.start[v];
        mSlots[t][4 * a + b] = static_cast<std::uint32_t>(
            std::lower_bound(begin, mNeighbours.nodes.begin() + mNeighbours.start[v + 1], u) - begin);
      }
}

SparseMatrix MotionStiffness::matrix() const {
  // A node's three columns have the same rows, and a node's three rows are consecutive.
  const std::size_t nodes = mNeighbours.start.size() - 1;
  const auto n = static_cast<Eigen::Index>(3 * nodes);
  SparseMatrix k(n, n);
  k.resizeNonZeros(static_cast<Eigen::Index>(9 * mNeighbours.nodes.size()));
  int* outer = k.outerIndexPtr();
  int* inner = k.innerIndexPtr();
  for (std::uint32_t v = 0; v < nodes; ++v) {
    const std::uint32_t first = mNeighbours.start[v], degree = mNeighbours.start[v + 1] - first;
    for (int j = 0; j < 3; ++j) {
      const auto column = static_cast<int>(columnStart(v, j));
      outer[3 * v + static_cast<std::uint32_t>(j)] = column;
      for (std::uint32_t u = 0; u < degree; ++u)
        for (std::uint32_t i = 0; i < 3; ++i)
          inner[column + static_cast<int>(3 * u + i)] =
              static_cast<int>(3 * mNeighbours.nodes[first + u] + i);
    }
  }
  outer[n] = static_cast<int>(9 * mNeighbours.nodes.size());
  std::fill_n(k.valuePtr(), k.nonZeros(), 0.0);
  return k;
}

SparseMatrix MotionStiffness::assemble(const TetMesh& mesh) const {
  SparseMatrix k = matrix();
  assemble(mesh, k);
  return k;
}

void MotionStiffness::assemble(const TetMesh& mesh, SparseMatrix& into) const {
  double* values = into.valuePtr();
  std::fill_n(values, into.nonZeros(), 0.0);
  const int* outer = into.outerIndexPtr();
  for (std::size_t t = 0; t < mesh.tetCount(); ++t)
    forEachElementBlock(mesh, t, [&](int a, int b, const core::Mat3& block) {
      const std::uint32_t v = mesh.tets[t][static_cast<std::size_t>(b)];
      const std::uint32_t k = mSlots[t][static_cast<std::size_t>(4 * a + b)];
      for (int j = 0; j < 3; ++j) {
        double* column = values + outer[3 * v + static_cast<std::uint32_t>(j)] + 3 * k;
        for (int i = 0; i < 3; ++i)
          column[i] += block(i, j);
      }
    });
}

Eigen::Index MotionStiffness::valueIndex(std::uint32_t u, std::uint32_t v, int i, int j) const {
  const auto begin = mNeighbours.nodes.begin() + mNeighbours.start[v],
             end = mNeighbours.nodes.begin() + mNeighbours.start[v + 1];
  const auto at = std::lower_bound(begin, end, u);
  if (at == end || *at != u) return -1;
  return columnStart(v, j) + 3 * (at - begin) + i;
}

std::array<Eigen::Index, 3> MotionStiffness::diagonalIndices(std::uint32_t u, std::uint32_t v) const {
  const Eigen::Index first = valueIndex(u, v, 0, 0);
  if (first < 0) return {-1, -1, -1};
  return {first, first - columnStart(v, 0) + columnStart(v, 1) + 1,
          first - columnStart(v, 0) + columnStart(v, 2) + 2};
}

InteriorMotion::Layout::Layout(const TetMesh& mesh, std::span<const char> isBoundary) : stiffness(mesh) {
  const std::size_t n = mesh.nodeCount();
  inner.assign(n, -1);
  boundarySlot.assign(n, -1);
  int boundaryCount = 0;
  for (std::size_t v = 0; v < n; ++v) {
    if (isBoundary[v])
      boundarySlot[v] = boundaryCount++;
    else
      inner[v] = innerCount++;
  }
  if (innerCount == 0) return;
  // K_ii: K's rows and columns of the inner nodes. Inner nodes are numbered in the mesh's order, so each
  // column's rows stay ascending, and a node's three columns have the same rows, as in K.
  const SparseMatrix k = stiffness.matrix();
  std::vector<int> toInner(static_cast<std::size_t>(k.nonZeros()), -1);  // K's value → K_ii's
  kiiOuter.assign(static_cast<std::size_t>(3 * innerCount) + 1, 0);
  for (Eigen::Index col = 0; col < k.outerSize(); ++col) {
    const int v = inner[static_cast<std::size_t>(col / 3)];
    if (v < 0) continue;
    const auto innerCol = static_cast<std::size_t>(3 * v + col % 3);
    for (Eigen::Index at = k.outerIndexPtr()[col]; at < k.outerIndexPtr()[col + 1]; ++at) {
      const int row = k.innerIndexPtr()[at], u = inner[static_cast<std::size_t>(row / 3)];
      if (u < 0) continue;
      toInner[static_cast<std::size_t>(at)] = static_cast<int>(kiiInner.size());
      kiiInner.push_back(3 * u + row % 3);
    }
    kiiOuter[innerCol + 1] = static_cast<int>(kiiInner.size());
  }
  for (std::size_t t = 0; t < mesh.tetCount(); ++t) {
    const auto& tet = mesh.tets[t];
    if (std::none_of(tet.begin(), tet.end(), [&](std::uint32_t v) { return inner[v] >= 0; })) continue;
    ActiveTet& active = activeTets.emplace_back();
    active.tet = static_cast<std::uint32_t>(t);
    for (std::size_t a = 0; a < 4; ++a)
      for (std::size_t b = 0; b < 4; ++b) {
        const bool both = inner[tet[a]] >= 0 && inner[tet[b]] >= 0;
        active.blockStart[4 * a + b] =
            both ? toInner[static_cast<std::size_t>(stiffness.valueIndex(tet[a], tet[b], 0, 0))] : -1;
      }
  }
}

InteriorMotion::InteriorMotion(const TetMesh& mesh, std::span<const char> isBoundary)
    : InteriorMotion(std::make_shared<const Layout>(mesh, isBoundary)) {}

InteriorMotion::InteriorMotion(std::shared_ptr<const Layout> layout) : mLayout(std::move(layout)) {
  const Layout& l = *mLayout;
  mKii.resize(3 * l.innerCount, 3 * l.innerCount);
  mKii.resizeNonZeros(static_cast<Eigen::Index>(l.kiiInner.size()));
  std::copy(l.kiiOuter.begin(), l.kiiOuter.end(), mKii.outerIndexPtr());
  std::copy(l.kiiInner.begin(), l.kiiInner.end(), mKii.innerIndexPtr());
  std::fill_n(mKii.valuePtr(), mKii.nonZeros(), 0.0);
}

Eigen::VectorXd InteriorMotion::assemble(const TetMesh& mesh, const Eigen::VectorXd& boundaryMove,
                                         std::vector<RhsBlock>* blocks) {
  // K_ii and −K_ib u_b, assembled on the mesh as it stands before this increment: the blocks of the inner
  // nodes' rows only.
  double* kii = mKii.valuePtr();
  const int* kiiColumns = mKii.outerIndexPtr();
  std::fill_n(kii, mKii.nonZeros(), 0.0);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(3 * mLayout->innerCount);
  for (const Layout::ActiveTet& active : mLayout->activeTets) {
    const auto& tet = mesh.tets[active.tet];
    const auto [grad, volume] = core::tetGradients(mesh, active.tet);
    for (std::size_t a = 0; a < 4; ++a) {
      const int row = mLayout->inner[tet[a]];
      if (row < 0) continue;
      for (std::size_t b = 0; b < 4; ++b) {
        const core::Mat3 block =
            elementBlock(grad.col(static_cast<Eigen::Index>(a)), grad.col(static_cast<Eigen::Index>(b)));
        if (const Eigen::Index start = active.blockStart[4 * a + b]; start >= 0) {
          const int column = 3 * mLayout->inner[tet[b]];  // b's three K_ii columns are of one length
          const Eigen::Index stride = kiiColumns[column + 1] - kiiColumns[column];
          for (Eigen::Index j = 0; j < 3; ++j)
            for (Eigen::Index r = 0; r < 3; ++r)
              kii[start + j * stride + r] += block(r, j);
        } else {
          const int slot = mLayout->boundarySlot[tet[b]];
          rhs.segment<3>(3 * row) -= block * boundaryMove.segment<3>(3 * slot);
          if (blocks) blocks->push_back({row, slot, block});
        }
      }
    }
  }
  return rhs;
}

void InteriorMotion::move(TetMesh& mesh, const Eigen::VectorXd& boundaryMove,
                          const Eigen::VectorXd& inner) const {
  for (std::size_t v = 0; v < mesh.nodeCount(); ++v)
    if (const int slot = mLayout->boundarySlot[v]; slot >= 0)
      mesh.nodes[v] += boundaryMove.segment<3>(3 * slot);
  for (std::size_t v = 0; v < mesh.nodeCount(); ++v)
    if (const int i = mLayout->inner[v]; i >= 0) mesh.nodes[v] += inner.segment<3>(3 * i);
}

Status InteriorMotion::extend(TetMesh& mesh, const Eigen::VectorXd& boundaryMove) {
  if (mLayout->innerCount == 0) {
    move(mesh, boundaryMove, Eigen::VectorXd());
    return Ok{};
  }
  const Eigen::VectorXd rhs = assemble(mesh, boundaryMove, nullptr);
  if (!mAnalyzed) {
    mSolver.analyzePattern(mKii);
    mAnalyzed = true;
  }
  mSolver.factorize(mKii);
  if (mSolver.info() != Eigen::Success)
    return Error{ErrorCode::kInvalidArgument, "the mesh-motion system could not be factorized"};
  move(mesh, boundaryMove, mSolver.solve(rhs));
  return Ok{};
}

Status InteriorMotion::extendFromAnchor(TetMesh& mesh, const Eigen::VectorXd& boundaryMove) {
  if (mLayout->innerCount == 0) return extend(mesh, boundaryMove);
  Eigen::VectorXd rhs;
  if (mesh.nodes == mAnchor) {
    // −K_ib u_b from the kept blocks, in the order extend adds them.
    rhs = Eigen::VectorXd::Zero(3 * mLayout->innerCount);
    for (const RhsBlock& b : mAnchorBlocks)
      rhs.segment<3>(3 * b.row) -= b.block * boundaryMove.segment<3>(3 * b.slot);
  } else {
    mAnchor.clear();
    mAnchorBlocks.clear();
    rhs = assemble(mesh, boundaryMove, &mAnchorBlocks);
    mAnchorSolver.compute(mKii);
    if (mAnchorSolver.info() != Eigen::Success)
      return Error{ErrorCode::kInvalidArgument, "the mesh-motion system could not be factorized"};
    mAnchor = mesh.nodes;
  }
  move(mesh, boundaryMove, mAnchorSolver.solve(rhs));
  return Ok{};
}

}  // namespace shapedb::volume::detail
