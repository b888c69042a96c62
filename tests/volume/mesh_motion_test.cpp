// The morph's mesh-motion stiffness (mesh_motion.h): laid out once and assembled again by values, against
// the triplet assembly; the interior's displacement, solved with one kept analysis, against a dense solve.

#include "mesh_motion.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume::detail {
namespace {

using core::TetMesh;
using core::Vec3;

TetMesh ellipsoidTets() {
  Result<TetMesh> tets = tetrahedralize(core::makeUvEllipsoid(Vec3(1.0, 0.7, 0.45), 12, 6),
                                        entryMeshing(ElementOrder::kQuadratic));
  EXPECT_TRUE(tets.ok()) << tets.error().message;
  return tets.ok() ? *tets : TetMesh{};
}

/// `mesh` with every node moved by up to `amount` along each axis (small enough that no tet inverts).
TetMesh jiggled(TetMesh mesh, std::mt19937& rng, double amount) {
  std::uniform_real_distribution<double> d(-amount, amount);
  for (Vec3& p : mesh.nodes)
    p += Vec3(d(rng), d(rng), d(rng));
  return mesh;
}

TEST(MeshMotion, TheLaidOutStiffnessIsTheTripletOneWhereverTheNodesMove) {
  const TetMesh start = ellipsoidTets();
  ASSERT_GT(start.tetCount(), 50u);
  MotionStiffness stiffness(start);
  std::mt19937 rng(31);
  for (int trial = 0; trial < 6; ++trial) {
    const TetMesh moved = trial == 0 ? start : jiggled(start, rng, 0.01);
    const SparseMatrix reference = meshMotionStiffness(moved);
    const SparseMatrix& k = stiffness.assemble(moved);
    ASSERT_EQ(k.rows(), reference.rows());
    ASSERT_EQ(k.nonZeros(), reference.nonZeros()) << "the same sparsity";
    EXPECT_LE((Eigen::MatrixXd(k) - Eigen::MatrixXd(reference)).cwiseAbs().maxCoeff(),
              1e-12 * Eigen::MatrixXd(reference).cwiseAbs().maxCoeff())
        << "trial " << trial;
  }
  // valueIndex finds each value where it is, and nothing where two nodes share no tet.
  const SparseMatrix k = stiffness.assemble(jiggled(start, rng, 0.01));
  EXPECT_EQ(stiffness.matrix().nonZeros(), k.nonZeros());
  std::uniform_int_distribution<std::uint32_t> node(0, static_cast<std::uint32_t>(start.nodeCount() - 1));
  int shared = 0, apart = 0;
  for (int pick = 0; pick < 2000; ++pick) {
    const std::uint32_t u = node(rng), v = node(rng);
    const int i = pick % 3, j = (pick / 3) % 3;
    const Eigen::Index at = stiffness.valueIndex(u, v, i, j);
    bool share = false;
    for (const auto& tet : start.tets)
      share = share || (std::ranges::count(tet, u) && std::ranges::count(tet, v));
    ASSERT_EQ(at >= 0, share) << u << ", " << v;
    if (at < 0) {
      ++apart;
      continue;
    }
    ++shared;
    EXPECT_EQ(k.valuePtr()[at],
              k.coeff(3 * u + static_cast<std::uint32_t>(i), 3 * v + static_cast<std::uint32_t>(j)));
    const std::array<Eigen::Index, 3> diagonal = stiffness.diagonalIndices(u, v);
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(diagonal[static_cast<std::size_t>(c)], stiffness.valueIndex(u, v, c, c));
  }
  EXPECT_GT(apart, 0);
  EXPECT_GT(shared, 0);
}

TEST(MeshMotion, NodeNeighboursAreTheNodesThatShareATet) {
  // Against the plain definition, on a mesh's tets renumbered at random (the lists must not depend on the
  // numbering being the mesher's) and with an unused node.
  const TetMesh start = ellipsoidTets();
  std::mt19937 rng(17);
  for (int trial = 0; trial < 3; ++trial) {
    TetMesh mesh = start;
    std::vector<std::uint32_t> renumber(mesh.nodeCount() + 1);
    std::iota(renumber.begin(), renumber.end(), 0u);
    std::shuffle(renumber.begin(), renumber.end(), rng);
    mesh.nodes.push_back(Vec3::Zero());
    for (auto& tet : mesh.tets)
      for (std::uint32_t& v : tet)
        v = renumber[v];
    std::shuffle(mesh.tets.begin(), mesh.tets.end(), rng);
    std::vector<std::set<std::uint32_t>> expected(mesh.nodeCount());
    for (const auto& tet : mesh.tets)
      for (std::uint32_t a : tet)
        expected[a].insert(tet.begin(), tet.end());
    const NodeNeighbours got = nodeNeighbours(mesh);
    ASSERT_EQ(got.start.size(), mesh.nodeCount() + 1);
    for (std::uint32_t v = 0; v < mesh.nodeCount(); ++v)
      EXPECT_EQ(
          std::vector<std::uint32_t>(got.nodes.begin() + got.start[v], got.nodes.begin() + got.start[v + 1]),
          std::vector<std::uint32_t>(expected[v].begin(), expected[v].end()))
          << "trial " << trial << ", node " << v;
  }
}

TEST(MeshMotion, TheInteriorFollowsAsADenseSolveSaysCallAfterCall) {
  const TetMesh start = ellipsoidTets();
  std::vector<char> isBoundary(start.nodeCount(), 0);
  for (const core::BoundaryFace& f : core::boundaryFaces(start))
    for (std::uint32_t n : f.nodes)
      isBoundary[n] = 1;
  std::vector<std::uint32_t> boundary, inner;
  for (std::uint32_t v = 0; v < start.nodeCount(); ++v)
    (isBoundary[v] ? boundary : inner).push_back(v);
  ASSERT_FALSE(inner.empty());
  InteriorMotion motion(start, isBoundary);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-0.02, 0.02);
  TetMesh mesh = start;
  for (int call = 0; call < 3; ++call) {  // the later calls reuse the first's analysis, on moved nodes
    Eigen::VectorXd move(3 * static_cast<Eigen::Index>(boundary.size()));
    for (Eigen::Index i = 0; i < move.size(); ++i)
      move[i] = d(rng);
    // The oracle: K_ii u_i = −K_ib u_b, dense, K from triplets on the mesh before the move.
    const Eigen::MatrixXd k(meshMotionStiffness(mesh));
    Eigen::MatrixXd kii(3 * inner.size(), 3 * inner.size());
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(inner.size()));
    for (std::size_t a = 0; a < inner.size(); ++a)
      for (int i = 0; i < 3; ++i) {
        const auto row = static_cast<Eigen::Index>(3 * a) + i;
        for (std::size_t b = 0; b < inner.size(); ++b)
          for (int j = 0; j < 3; ++j)
            kii(row, static_cast<Eigen::Index>(3 * b) + j) = k(3 * inner[a] + i, 3 * inner[b] + j);
        for (std::size_t b = 0; b < boundary.size(); ++b)
          for (int j = 0; j < 3; ++j)
            rhs[row] -= k(3 * inner[a] + i, 3 * boundary[b] + j) * move[static_cast<Eigen::Index>(3 * b) + j];
      }
    const Eigen::VectorXd u = kii.ldlt().solve(rhs);
    TetMesh expected = mesh;
    for (std::size_t b = 0; b < boundary.size(); ++b)
      expected.nodes[boundary[b]] += move.segment<3>(static_cast<Eigen::Index>(3 * b));
    for (std::size_t a = 0; a < inner.size(); ++a)
      expected.nodes[inner[a]] += u.segment<3>(static_cast<Eigen::Index>(3 * a));

    ASSERT_TRUE(motion.extend(mesh, move).ok());
    double worst = 0.0;
    for (std::size_t v = 0; v < mesh.nodeCount(); ++v)
      worst = std::max(worst, (mesh.nodes[v] - expected.nodes[v]).norm());
    EXPECT_LT(worst, 1e-10) << "call " << call;
    EXPECT_GT(u.cwiseAbs().maxCoeff(), 1e-4) << "the inner nodes did move";
    mesh = expected;
  }
}

TEST(MeshMotion, ExtendingFromAnAnchorIsExtendingToTheBit) {
  // The morph's projection tries several moves from one configuration, with other increments between:
  // extendFromAnchor reuses that configuration's factor and gives what extend gives, exactly, also once
  // it is called from other positions (a new anchor).
  const TetMesh start = ellipsoidTets();
  std::vector<char> isBoundary(start.nodeCount(), 0);
  std::size_t boundaryCount = 0;
  for (const core::BoundaryFace& f : core::boundaryFaces(start))
    for (std::uint32_t n : f.nodes)
      isBoundary[n] = 1;
  for (char b : isBoundary)
    boundaryCount += b ? 1 : 0;
  InteriorMotion plain(start, isBoundary), anchored(start, isBoundary);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> d(-0.02, 0.02);
  const auto randomMove = [&] {
    Eigen::VectorXd move(3 * static_cast<Eigen::Index>(boundaryCount));
    for (Eigen::Index i = 0; i < move.size(); ++i)
      move[i] = d(rng);
    return move;
  };
  TetMesh from = start;
  for (int anchor = 0; anchor < 2; ++anchor) {
    for (int call = 0; call < 3; ++call) {
      const Eigen::VectorXd move = randomMove();
      TetMesh expected = from, got = from;
      ASSERT_TRUE(plain.extend(expected, move).ok());
      ASSERT_TRUE(anchored.extendFromAnchor(got, move).ok());
      EXPECT_EQ(got.nodes, expected.nodes) << "anchor " << anchor << ", call " << call;
      EXPECT_NE(got.nodes, from.nodes);
      // An increment from elsewhere in between, as the morph's later increments are.
      const Eigen::VectorXd further = randomMove();
      ASSERT_TRUE(anchored.extend(got, further).ok());
      ASSERT_TRUE(plain.extend(expected, further).ok());
      EXPECT_EQ(got.nodes, expected.nodes);
    }
    ASSERT_TRUE(plain.extend(from, randomMove()).ok());  // the next anchor
  }
}

}  // namespace
}  // namespace shapedb::volume::detail
