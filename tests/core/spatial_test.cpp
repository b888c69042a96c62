// The spatial searches against brute force: the closest point on a surface (ClosestPointTree) and the
// tet holding a point, or the nearest boundary point outside (TetLocator).

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/physics.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

// The tree's closest point against every triangle's, at points spread `spread` times the surface's extent
// about it: unhinted, hinted by the previous point's answer, and hinted by an arbitrary triangle.
void expectAgreesWithEveryTriangle(const TriangleMesh& surface, std::mt19937_64& rng, double spread) {
  const ClosestPointTree tree(surface);
  const Bounds b = computeBounds(surface);
  std::uniform_real_distribution<double> u(0.5 - 0.5 * spread, 0.5 + 0.5 * spread);
  std::uint32_t previous = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = b.min + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(b.extent());
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : surface.triangles)
      best = std::min(best, closestPointOnTriangle(p, surface.vertices[t[0]], surface.vertices[t[1]],
                                                   surface.vertices[t[2]])
                                .squaredDistance);
    const std::uint32_t arbitrary = static_cast<std::uint32_t>(rng() % surface.triangles.size());
    for (const auto& hit : {tree.closest(p), tree.closest(p, previous), tree.closest(p, arbitrary)}) {
      ASSERT_NEAR(hit.closest.squaredDistance, best, 1e-12 * (1 + best)) << "point " << i;
      const auto& t = surface.triangles[hit.triangle];
      const auto& w = hit.closest.barycentric;
      const Vec3 q =
          w[0] * surface.vertices[t[0]] + w[1] * surface.vertices[t[1]] + w[2] * surface.vertices[t[2]];
      ASSERT_LT((q - hit.closest.point).norm(), 1e-9 + 1e-13 * q.norm());
    }
    previous = tree.closest(p).triangle;
  }
}

TEST(ClosestPointTree, AgreesWithEveryTriangleOnRandomPoints) {
  std::mt19937_64 rng(7);
  expectAgreesWithEveryTriangle(
      transformed(makeUvEllipsoid({1.0, 0.6, 0.3}, 24, 12), test::randomSimilarity(rng)), rng, 2.0);
}

// The boxes are single precision, rounded outward: where a float's step is as large as the triangles
// (a 2 cm scan 400 km from the origin) or coordinates are beyond float's range, the answers are still
// every triangle's closest, however near the surface the points are.
TEST(ClosestPointTree, AgreesWithEveryTriangleWhereFloatBoxesAreCoarse) {
  std::mt19937_64 rng(8);
  for (const Vec3& offset : {Vec3(4e5, -3e5, 2e5), Vec3(0, 0, 0)}) {
    TriangleMesh surface = makeUvEllipsoid({0.02, 0.012, 0.006}, 24, 12);
    for (Vec3& p : surface.vertices)
      p += offset;
    SCOPED_TRACE(offset.transpose());
    expectAgreesWithEveryTriangle(surface, rng, 1.2);
  }
  TriangleMesh huge = makeUvEllipsoid({1.0, 0.6, 0.3}, 16, 8);
  for (Vec3& p : huge.vertices)
    p *= 1e39;  // beyond float's largest, 3.4e38
  SCOPED_TRACE("beyond float's range");
  expectAgreesWithEveryTriangle(huge, rng, 1.5);
}

// The tree's first hit against every triangle's, for rays from points spread about an ellipsoid turned
// anywhere, in random directions, from its own triangles' centroids (skipping them) and along the axes
// (a zero in the direction: the slab test's special case), and at a surface far from the origin.
TEST(ClosestPointTree, FirstHitAgreesWithEveryTriangle) {
  std::mt19937_64 rng(9);
  for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(4e5, -3e5, 2e5)}) {
    TriangleMesh surface = transformed(makeUvEllipsoid({1.0, 0.6, 0.3}, 24, 12), test::randomSimilarity(rng));
    for (Vec3& p : surface.vertices)
      p += offset;
    SCOPED_TRACE(offset.transpose());
    const ClosestPointTree tree(surface);
    const Bounds b = computeBounds(surface);
    std::uniform_real_distribution<double> u(-0.5, 1.5);
    std::normal_distribution<double> g;
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
      Vec3 origin = b.min + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(b.extent());
      Vec3 direction(g(rng), g(rng), g(rng));
      std::uint32_t skip = std::numeric_limits<std::uint32_t>::max();
      if (i % 3 == 1) {
        skip = static_cast<std::uint32_t>(rng() % surface.triangles.size());
        const auto& t = surface.triangles[skip];
        origin = (surface.vertices[t[0]] + surface.vertices[t[1]] + surface.vertices[t[2]]) / 3.0;
      } else if (i % 3 == 2) {
        direction = Vec3::Zero();
        direction[static_cast<int>(rng() % 3)] = rng() % 2 ? 1.0 : -1.0;
      }
      const double minDistance = i % 5 == 0 ? 0.1 * b.extent().norm() : 0.0;
      const auto expected = firstHitBruteForce(surface, origin, direction, minDistance, skip);
      const auto hit = tree.firstHit(origin, direction, minDistance, skip);
      ASSERT_EQ(hit.has_value(), expected.has_value()) << "ray " << i;
      if (!hit) continue;
      ++hits;
      ASSERT_NE(hit->triangle, skip);
      ASSERT_NEAR(hit->distance, expected->distance, 1e-12 * (1.0 + expected->distance)) << "ray " << i;
      const auto& t = surface.triangles[hit->triangle];
      EXPECT_EQ(rayTriangleDistance(origin, direction, surface.vertices[t[0]], surface.vertices[t[1]],
                                    surface.vertices[t[2]]),
                hit->distance);
    }
    // Both answers were tried: rays that cross the surface and rays that miss it.
    EXPECT_GT(hits, 400);
    EXPECT_LT(hits, 2600);
  }
}

// A tree over tens of thousands of triangles builds its large subtrees on several threads. It is the tree
// a build on the calling thread alone makes: every closest point and first hit the same to the bit (the
// triangle named too), and on a sample of the points the closest of every triangle (the oracle).
TEST(ClosestPointTree, ALargeTreeBuiltOnSeveralThreadsIsTheOneBuiltOnOne) {
  std::mt19937_64 rng(11);
  const TriangleMesh surface =
      transformed(makeUvEllipsoid({1.0, 0.5, 0.3}, 160, 100), test::randomSimilarity(rng));
  ASSERT_GT(surface.triangleCount(), 30000u);
  const ClosestPointTree parallel(surface), serial(surface, /*parallel=*/false);
  ASSERT_EQ(parallel.triangleCount(), serial.triangleCount());
  const Bounds b = computeBounds(surface);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = b.min + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(b.extent());
    const ClosestPointTree::Hit x = parallel.closest(p), y = serial.closest(p);
    ASSERT_EQ(x.triangle, y.triangle) << "point " << i;
    ASSERT_EQ(x.closest.squaredDistance, y.closest.squaredDistance) << "point " << i;
    const Vec3 direction = Vec3(u(rng), u(rng), u(rng)) - Vec3::Constant(0.5);
    const auto hx = parallel.firstHit(p, direction), hy = serial.firstHit(p, direction);
    ASSERT_EQ(hx.has_value(), hy.has_value()) << "point " << i;
    if (hx) {
      ASSERT_EQ(hx->triangle, hy->triangle) << "point " << i;
      ASSERT_EQ(hx->distance, hy->distance) << "point " << i;
    }
    if (i % 20 != 0) continue;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : surface.triangles)
      best = std::min(best, closestPointOnTriangle(p, surface.vertices[t[0]], surface.vertices[t[1]],
                                                   surface.vertices[t[2]])
                                .squaredDistance);
    ASSERT_EQ(x.closest.squaredDistance, best) << "point " << i;
  }
}

// A plate's thickness is its thinnest side at every vertex, corners included; a ball's is its diameter
// wherever the rays pass near its centre.
// Every size of tree from one triangle up: a node holds one to four children, leaves of up to four
// triangles, so the smallest trees are the build's edge cases. Closest points, first hits and the
// triangles whose boxes meet a box, each against every triangle, on soups of random triangles.
TEST(ClosestPointTree, EverySizeAgreesWithEveryTriangle) {
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto point = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  for (std::uint32_t n = 1; n <= 40; ++n) {
    SCOPED_TRACE(n);
    TriangleMesh soup;
    for (std::uint32_t t = 0; t < n; ++t) {
      const Vec3 corner = point();
      for (int k = 0; k < 3; ++k)
        soup.vertices.push_back(corner + 0.2 * (point() - Vec3::Constant(0.5)));
      soup.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
    }
    const ClosestPointTree tree(soup);
    ASSERT_EQ(tree.triangleCount(), n);
    for (int i = 0; i < 50; ++i) {
      const Vec3 p = 1.4 * point() - Vec3::Constant(0.2);
      double best = std::numeric_limits<double>::infinity();
      for (const auto& t : soup.triangles)
        best = std::min(
            best, closestPointOnTriangle(p, soup.vertices[t[0]], soup.vertices[t[1]], soup.vertices[t[2]])
                      .squaredDistance);
      ASSERT_EQ(tree.closest(p).closest.squaredDistance, best);

      const Vec3 direction = point() - Vec3::Constant(0.5);
      const auto hit = tree.firstHit(p, direction);
      const auto expected = firstHitBruteForce(soup, p, direction);
      ASSERT_EQ(hit.has_value(), expected.has_value());
      if (hit) {
        ASSERT_EQ(hit->distance, expected->distance);
      }

      const Vec3 a = point(), b = point(), lo = a.cwiseMin(b), hi = a.cwiseMax(b);
      std::vector<std::uint32_t> found;
      tree.overlapping(lo, hi, found);
      std::sort(found.begin(), found.end());
      ASSERT_TRUE(std::adjacent_find(found.begin(), found.end()) == found.end()) << "a triangle twice";
      for (std::uint32_t t = 0; t < n; ++t) {
        Vec3 tlo = soup.vertices[3 * t], thi = tlo;
        for (std::uint32_t k = 1; k < 3; ++k) {
          tlo = tlo.cwiseMin(soup.vertices[3 * t + k]);
          thi = thi.cwiseMax(soup.vertices[3 * t + k]);
        }
        if ((tlo.array() <= hi.array()).all() && (lo.array() <= thi.array()).all()) {
          ASSERT_TRUE(std::binary_search(found.begin(), found.end(), t)) << "triangle " << t << " missed";
        }
      }
    }
  }
}

TEST(WallThickness, IsAPlatesThicknessAndABallsDiameter) {
  std::mt19937_64 rng(10);
  const Mat4 placed = test::randomSimilarity(rng);
  const double scale = std::cbrt(placed.topLeftCorner<3, 3>().determinant());
  TriangleMesh plate = transformed(makeBox({2.0, 1.0, 0.1}), placed);
  for (const double t : wallThickness(plate))
    EXPECT_NEAR(t, 0.1 * scale, 1e-9 * scale);
  const TriangleMesh ball = makeIcosphere(0.5, 3);
  const std::vector<double> diameters = wallThickness(ball);
  ASSERT_EQ(diameters.size(), ball.vertices.size());
  for (const double t : diameters) {
    EXPECT_GT(t, 0.97);
    EXPECT_LE(t, 1.0);
  }
}

// SurfaceSide against the winding number: points spread over the surface's box, and points just off the
// surface beside its vertices and edges, where the closest point is a corner or on an edge and only the
// pseudonormals there tell the side.
void expectSidesAgreeWithWindingNumber(const TriangleMesh& surface, std::mt19937_64& rng) {
  const SurfaceSide side(surface);
  const ClosestPointTree tree(surface);
  const Bounds b = computeBounds(surface);
  std::uniform_real_distribution<double> u(-0.25, 1.25), jitter(-1.0, 1.0);
  std::vector<Vec3> points;
  for (int i = 0; i < 1500; ++i)
    points.push_back(b.min + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(b.extent()));
  const double near = 1e-3 * b.extent().norm();
  for (int i = 0; i < 1500; ++i) {
    const auto& t = surface.triangles[rng() % surface.triangles.size()];
    const Vec3 corner = surface.vertices[t[rng() % 3]],
               edge = 0.5 * (surface.vertices[t[0]] + surface.vertices[t[1]]);
    points.push_back((i % 2 ? corner : edge) + near * Vec3(jitter(rng), jitter(rng), jitter(rng)));
  }
  int insides = 0;
  // Every other search started from the triangle found for the point before, an unrelated one: the start
  // must not change the answer.
  std::uint32_t hint = ClosestPointTree::kNoHint;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double winding = windingNumber(surface, points[i]);
    ASSERT_LT(std::min(std::abs(winding), std::abs(winding - 1.0)), 1e-6) << "point " << i;
    ASSERT_EQ(side.inside(points[i]), winding > 0.5) << "point " << i << ", winding " << winding;
    const double distance = std::sqrt(tree.closest(points[i]).closest.squaredDistance);
    ASSERT_NEAR(std::abs(side.signedDistance(points[i])), distance, 1e-12);
    if (i % 2 == 1) {
      const double started = side.signedDistance(points[i], hint);
      ASSERT_EQ((started < 0.0), (winding > 0.5)) << "point " << i << ", started from a hint";
      ASSERT_NEAR(std::abs(started), distance, 1e-12);
    } else {
      static_cast<void>(side.signedDistance(points[i], hint));  // sets `hint` for the next point
    }
    insides += winding > 0.5;
  }
  // Both sides were tried, near the surface as well as far from it.
  EXPECT_GT(insides, 600);
  EXPECT_LT(insides, 2400);
}

TEST(SurfaceSide, AgreesWithTheWindingNumber) {
  std::mt19937_64 rng(9);
  {
    SCOPED_TRACE("torus");
    expectSidesAgreeWithWindingNumber(test::makeTorus(1.0, 0.35, 24, 12), rng);
  }
  {
    SCOPED_TRACE("ellipsoid");
    expectSidesAgreeWithWindingNumber(
        transformed(makeUvEllipsoid({1.0, 0.6, 0.3}, 24, 12), test::randomSimilarity(rng)), rng);
  }
  {
    SCOPED_TRACE("box");
    expectSidesAgreeWithWindingNumber(makeBox({1.0, 2.0, 0.5}), rng);
  }
}

TEST(TetLocator, AgreesWithBruteForceInsideAndOutside) {
  std::mt19937_64 rng(11);
  const TetMesh mesh = test::makeTetGrid(6, 4, 3, 0.3, rng);
  ASSERT_TRUE(validateTetMesh(mesh));
  const TetLocator locator(mesh);
  EXPECT_EQ(locator.boundary().triangleCount(), 2u * 2 * (6 * 4 + 4 * 3 + 6 * 3));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int inside = 0;
  TetLocator::Hint hint;
  for (int i = 0; i < 8000; ++i) {
    const Vec3 p(3 + 4.5 * u(rng), 2 + 3.5 * u(rng), 1.5 + 3 * u(rng));
    // Even points with odd ones: a hint from an unrelated point must not change the answer.
    const TetLocation fast = i % 2 == 0 ? locator.locate(p) : locator.locate(p, hint);
    const TetLocation slow = locateBruteForce(locator, p);
    double sum = 0.0;
    for (double w : fast.weights) {
      ASSERT_GT(w, -1e-9);
      sum += w;
    }
    ASSERT_NEAR(sum, 1.0, 1e-12);
    ASSERT_EQ(fast.inside(), slow.inside()) << "point " << i;
    if (fast.inside()) {
      ++inside;
      ASSERT_EQ(fast.tet, slow.tet);
      ASSERT_LT((test::interpolate(mesh, fast) - p).norm(), 1e-12) << "an inside point is its weighted nodes";
    } else {
      // Several faces can be equally close (an edge, a corner): compare the distance and the point.
      ASSERT_NEAR(fast.distance, slow.distance, 1e-12);
      ASSERT_LT((test::interpolate(mesh, fast) - test::interpolate(mesh, slow)).norm(), 1e-9);
      ASSERT_NEAR((test::interpolate(mesh, fast) - p).norm(), fast.distance, 1e-9);
    }
  }
  // The grid fills 72 of the sampled 378 units³: about 1,520 points inside, the rest outside.
  EXPECT_GT(inside, 1000);
  EXPECT_LT(inside, 2000);
}

// A hint carries the last point's tet and boundary face: along a walk of small steps, in and out of the
// mesh and across its tets' faces, as a surface's vertices follow each other, every answer is still
// brute force's.
TEST(TetLocator, AHintAlongAWalkAgreesWithBruteForce) {
  std::mt19937_64 rng(13);
  const TetMesh mesh = test::makeTetGrid(6, 4, 3, 0.3, rng);
  const TetLocator locator(mesh);
  std::normal_distribution<double> step(0.0, 0.12);
  TetLocator::Hint hint;
  Vec3 p(3.0, 2.0, 1.5);
  int inside = 0, staysInTet = 0;
  std::uint32_t lastTet = std::numeric_limits<std::uint32_t>::max();
  for (int i = 0; i < 6000; ++i) {
    p += Vec3(step(rng), step(rng), step(rng));
    // Drawn back towards the middle, so that the walk crosses the boundary both ways many times.
    p += 0.002 * (Vec3(3.0, 2.0, 1.5) - p);
    const TetLocation fast = locator.locate(p, hint);
    const TetLocation slow = locateBruteForce(locator, p);
    ASSERT_EQ(fast.inside(), slow.inside()) << "step " << i;
    if (fast.inside()) {
      ++inside;
      staysInTet += fast.tet == lastTet;
      lastTet = fast.tet;
      ASSERT_EQ(fast.tet, slow.tet) << "step " << i;
      for (std::size_t k = 0; k < 4; ++k)
        ASSERT_EQ(fast.weights[k], slow.weights[k]) << "step " << i;
    } else {
      ASSERT_NEAR(fast.distance, slow.distance, 1e-12) << "step " << i;
      ASSERT_LT((test::interpolate(mesh, fast) - test::interpolate(mesh, slow)).norm(), 1e-9);
    }
  }
  // Both sides, and many steps that stay in the tet of the step before (the hint's case).
  EXPECT_GT(inside, 1000);
  EXPECT_LT(inside, 5000);
  EXPECT_GT(staysInTet, 300);
}

// boundaryFaces (a counting sort by smallest node) against faces counted in a map: the same faces, the
// same winding and owner, in the order of their sorted nodes. Random tets are taken out of a jittered grid,
// which leaves inner cavities and faces that two removed tets shared, and the nodes are renumbered at
// random, so that a node's faces come from anywhere in the tet list.
TEST(BoundaryFaces, AgreeWithFacesCountedInAMap) {
  std::mt19937_64 rng(12);
  for (int round = 0; round < 20; ++round) {
    TetMesh mesh = test::makeTetGrid(5, 4, 3, 0.3, rng);
    std::shuffle(mesh.tets.begin(), mesh.tets.end(), rng);
    mesh.tets.resize(mesh.tets.size() * static_cast<std::size_t>(60 + round) / 100);
    std::vector<std::uint32_t> renumber(mesh.nodes.size());
    std::iota(renumber.begin(), renumber.end(), 0u);
    std::shuffle(renumber.begin(), renumber.end(), rng);
    for (TetMesh::Tet& tet : mesh.tets)
      for (std::uint32_t& v : tet)
        v = renumber[v];

    std::map<std::array<std::uint32_t, 3>, std::vector<BoundaryFace>> seen;
    for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
      const auto& [a, b, c, d] = mesh.tets[t];
      for (const std::array<std::uint32_t, 3>& f :
           {std::array{a, c, b}, std::array{a, b, d}, std::array{b, c, d}, std::array{a, d, c}}) {
        std::array<std::uint32_t, 3> key = f;
        std::sort(key.begin(), key.end());
        seen[key].push_back({f, t});
      }
    }
    std::vector<BoundaryFace> expected;
    for (const auto& [key, faces] : seen)
      if (faces.size() == 1) expected.push_back(faces.front());

    const std::vector<BoundaryFace> found = boundaryFaces(mesh);
    ASSERT_EQ(found.size(), expected.size()) << "round " << round;
    for (std::size_t i = 0; i < found.size(); ++i) {
      ASSERT_EQ(found[i].nodes, expected[i].nodes) << "round " << round << ", face " << i;
      ASSERT_EQ(found[i].tet, expected[i].tet) << "round " << round << ", face " << i;
    }
  }
}

}  // namespace
}  // namespace shapedb::core
