// Where a surface passes through itself: the tree-pruned search against every pair of triangles, and the
// crossings it must find (and the contacts it must not) on closed surfaces.

#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/core/self_intersection.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

/// Two closed surfaces written as one mesh (the second's vertices after the first's).
TriangleMesh together(TriangleMesh first, const TriangleMesh& second) {
  const auto offset = static_cast<std::uint32_t>(first.vertices.size());
  first.vertices.insert(first.vertices.end(), second.vertices.begin(), second.vertices.end());
  for (const auto& t : second.triangles)
    first.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return first;
}

TriangleMesh moved(const TriangleMesh& mesh, const Vec3& by) {
  TriangleMesh out = mesh;
  for (Vec3& v : out.vertices)
    v += by;
  return out;
}

// Random triangles over a small pool of points, so that many pairs share a corner or an edge, near the
// origin and 10⁵ m from it: the same pairs, in the same order, at the same points as every pair tried.
TEST(SelfIntersections, AgreeWithEveryPairOfTriangles) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(1e5, -2e5, 3e4)}) {
    SCOPED_TRACE(offset.transpose());
    std::size_t sharingCorner = 0, crossingWithCorner = 0, total = 0;
    for (int round = 0; round < 20; ++round) {
      TriangleMesh soup;
      for (int i = 0; i < 40; ++i)
        soup.vertices.push_back(offset + Vec3(u(rng), u(rng), 0.2 * u(rng)));
      for (int i = 0; i < 60; ++i) {
        std::uint32_t a = rng() % 40, b = rng() % 40, c = rng() % 40;
        if (a == b || b == c || a == c) continue;
        soup.triangles.push_back({a, b, c});
      }
      const std::vector<TriangleCrossing> expected = findSelfIntersectionsBruteForce(soup);
      const std::vector<TriangleCrossing> found = findSelfIntersections(soup);
      ASSERT_EQ(found.size(), expected.size()) << "round " << round;
      for (std::size_t i = 0; i < found.size(); ++i) {
        ASSERT_EQ(found[i].first, expected[i].first);
        ASSERT_EQ(found[i].second, expected[i].second);
        ASSERT_EQ(found[i].point, expected[i].point);
        ASSERT_LT(found[i].first, found[i].second);
      }
      total += found.size();
      // Pairs that share one corner: tested, and some of them cross.
      std::set<std::pair<std::uint32_t, std::uint32_t>> crossing;
      for (const TriangleCrossing& c : found)
        crossing.insert({c.first, c.second});
      for (std::uint32_t s = 0; s < soup.triangles.size(); ++s)
        for (std::uint32_t t = s + 1; t < soup.triangles.size(); ++t) {
          int shared = 0;
          for (const std::uint32_t v : soup.triangles[s])
            for (const std::uint32_t w : soup.triangles[t])
              shared += v == w;
          if (shared != 1) continue;
          ++sharingCorner;
          crossingWithCorner += crossing.count({s, t});
        }
    }
    EXPECT_GT(total, 200u);
    EXPECT_GT(crossingWithCorner, 10u);
    EXPECT_LT(crossingWithCorner, sharingCorner);
  }
}

TEST(SelfIntersections, ClosedSolidsHaveNoneAndOverlappingOnesDo) {
  std::mt19937_64 rng(32);
  const Mat4 placed = test::randomSimilarity(rng);
  for (const TriangleMesh& solid :
       {makeBox({1.0, 2.0, 3.0}), makeUvEllipsoid({1.0, 0.6, 0.3}, 48, 24), makeIcosphere(1.0, 4),
        makeCapsule(0.2, 2.0, 24, 6), together(makeBox({1, 1, 1}), moved(makeBox({1, 1, 1}), {3, 0, 0}))}) {
    EXPECT_TRUE(findSelfIntersections(solid).empty());
    EXPECT_TRUE(findSelfIntersections(transformed(solid, placed)).empty());
  }
  // Two boxes written as one mesh, overlapping as an export of parts does: each crossing point lies on
  // both boxes' surfaces, where one's edge passes through the other's face.
  const TriangleMesh overlap =
      transformed(together(makeBox({1, 1, 1}), moved(makeBox({1, 1, 1}), {0.5, 0.3, 0.2})), placed);
  const std::vector<TriangleCrossing> crossings = findSelfIntersections(overlap);
  ASSERT_FALSE(crossings.empty());
  for (const TriangleCrossing& c : crossings) {
    EXPECT_LT(c.first, 12u);  // the first box's triangles come first
    EXPECT_GE(c.second, 12u);
  }
  // A box's top corner pushed down through its bottom face: the triangles around it cross the bottom's.
  TriangleMesh dented = makeBox({1, 1, 1});
  std::size_t corner = 0;
  for (std::size_t v = 1; v < dented.vertices.size(); ++v)
    if (dented.vertices[v].sum() > dented.vertices[corner].sum()) corner = v;
  const double bottom = computeBounds(dented).min.z();
  dented.vertices[corner] = Vec3(0.6, 0.7, 0.0) * dented.vertices[corner].x() + Vec3(0, 0, bottom - 0.3);
  EXPECT_FALSE(findSelfIntersections(dented).empty());
}

// Two triangles sharing a corner: one's opposite edge through the other is a crossing; meeting at the
// corner alone, or along an edge, is not.
TEST(SelfIntersections, TrianglesThatShareACornerCrossOnlyThroughTheirOppositeEdges) {
  TriangleMesh pair;
  pair.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, 1}, {0.5, 0.5, -1}, {1, 1, 1}, {1, 2, 1}};
  pair.triangles = {{0, 1, 2}, {0, 3, 4}};
  std::vector<TriangleCrossing> crossings = findSelfIntersections(pair);
  ASSERT_EQ(crossings.size(), 1u);
  EXPECT_LT((crossings[0].point - Vec3(0.5, 0.5, 0)).norm(), 1e-12);
  pair.triangles = {{0, 1, 2}, {0, 5, 6}};  // a corner in common, nothing else
  EXPECT_TRUE(findSelfIntersections(pair).empty());
  pair.triangles = {{0, 1, 2}, {1, 0, 3}};  // an edge in common
  EXPECT_TRUE(findSelfIntersections(pair).empty());
}

}  // namespace
}  // namespace shapedb::core
