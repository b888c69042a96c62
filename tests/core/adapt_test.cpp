#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/adapt.h>
#include <shapedb/core/fidelity.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

/// A box [0,nx]×[0,ny]×[0,nz] of unit cubes, each split into six tets around its main diagonal (Kuhn),
/// interior nodes jittered by up to `jitter`: a conforming tet mesh with irregular tets.
TetMesh makeTetGrid(int nx, int ny, int nz, double jitter, std::mt19937_64& rng) {
  TetMesh mesh;
  std::uniform_real_distribution<double> u(-jitter, jitter);
  const auto id = [&](int x, int y, int z) {
    return static_cast<std::uint32_t>((z * (ny + 1) + y) * (nx + 1) + x);
  };
  for (int z = 0; z <= nz; ++z)
    for (int y = 0; y <= ny; ++y)
      for (int x = 0; x <= nx; ++x) {
        Vec3 p(x, y, z);
        for (int a = 0; a < 3; ++a) {
          const int i = a == 0 ? x : a == 1 ? y : z, n = a == 0 ? nx : a == 1 ? ny : nz;
          if (i > 0 && i < n) p[a] += u(rng);
        }
        mesh.nodes.push_back(p);
      }
  static constexpr int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        for (const auto& path : kPaths) {
          std::array<int, 3> c{x, y, z};
          TetMesh::Tet t;
          t[0] = id(c[0], c[1], c[2]);
          for (int k = 0; k < 3; ++k) {
            ++c[path[k]];
            t[k + 1] = id(c[0], c[1], c[2]);
          }
          if (tetVolume(TetMesh{mesh.nodes, {t}}, 0) < 0) std::swap(t[2], t[3]);
          mesh.tets.push_back(t);
        }
  return mesh;
}

Vec3 interpolate(const TetMesh& mesh, const TetLocation& l) {
  Vec3 x = Vec3::Zero();
  for (int k = 0; k < 4; ++k)
    x += l.weights[k] * mesh.nodes[mesh.tets[l.tet][k]];
  return x;
}

TEST(ClosestPointTree, AgreesWithEveryTriangleOnRandomPoints) {
  std::mt19937_64 rng(7);
  const TriangleMesh surface =
      transformed(makeUvEllipsoid({1.0, 0.6, 0.3}, 24, 12), test::randomSimilarity(rng));
  const ClosestPointTree tree(surface);
  const Bounds b = computeBounds(surface);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  std::uint32_t previous = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = b.min + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(b.extent());
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : surface.triangles)
      best = std::min(best, closestPointOnTriangle(p, surface.vertices[t[0]], surface.vertices[t[1]],
                                                   surface.vertices[t[2]])
                                .squaredDistance);
    // Unhinted, hinted by the previous point's answer, and hinted by an arbitrary triangle.
    const std::uint32_t arbitrary = static_cast<std::uint32_t>(rng() % surface.triangles.size());
    for (const auto& hit : {tree.closest(p), tree.closest(p, previous), tree.closest(p, arbitrary)}) {
      ASSERT_NEAR(hit.closest.squaredDistance, best, 1e-12 * (1 + best)) << "point " << i;
      const auto& t = surface.triangles[hit.triangle];
      const auto& w = hit.closest.barycentric;
      const Vec3 q =
          w[0] * surface.vertices[t[0]] + w[1] * surface.vertices[t[1]] + w[2] * surface.vertices[t[2]];
      ASSERT_LT((q - hit.closest.point).norm(), 1e-9);
    }
    previous = tree.closest(p).triangle;
  }
}

TEST(TetLocator, AgreesWithBruteForceInsideAndOutside) {
  std::mt19937_64 rng(11);
  const TetMesh mesh = makeTetGrid(6, 4, 3, 0.3, rng);
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
      ASSERT_LT((interpolate(mesh, fast) - p).norm(), 1e-12) << "an inside point is its weighted nodes";
    } else {
      // Several faces can be equally close (an edge, a corner): compare the distance and the point.
      ASSERT_NEAR(fast.distance, slow.distance, 1e-12);
      ASSERT_LT((interpolate(mesh, fast) - interpolate(mesh, slow)).norm(), 1e-9);
      ASSERT_NEAR((interpolate(mesh, fast) - p).norm(), fast.distance, 1e-9);
    }
  }
  // The grid fills 72 of the sampled 378 units³: about 1,520 points inside, the rest outside.
  EXPECT_GT(inside, 1000);
  EXPECT_LT(inside, 2000);
}

TEST(Link, WeightsSumToOneAndReproduceInsideVertices) {
  std::mt19937_64 rng(3);
  const TetMesh mesh = makeTetGrid(5, 5, 5, 0.25, rng);
  const TetLocator locator(mesh);
  // A placement of scale 2, turned and moved: the "query" lives in another frame than the entry.
  Placement placement{test::randomRotation(rng), Vec3(1, -2, 3), 2.0};
  std::vector<Vec3> vertices;
  std::uniform_real_distribution<double> u(-0.5, 5.5);
  for (int i = 0; i < 5000; ++i)
    vertices.push_back(placement.toQuery(Vec3(u(rng), u(rng), u(rng))));
  const SurfaceLink link = linkSurface(locator, placement, vertices);
  ASSERT_EQ(link.locations.size(), vertices.size());
  TetMesh placed = mesh;
  for (Vec3& x : placed.nodes)
    x = placement.toQuery(x);
  std::size_t outside = 0;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const TetLocation& l = link.locations[i];
    ASSERT_NEAR(l.weights[0] + l.weights[1] + l.weights[2] + l.weights[3], 1.0, 1e-12);
    const double error = (interpolate(placed, l) - vertices[i]).norm();
    if (l.inside()) {
      ASSERT_LT(error, 1e-11);
    } else {
      ++outside;
      ASSERT_NEAR(error, l.distance, 1e-9) << "outside: tied to the closest point, distance in query units";
    }
  }
  EXPECT_EQ(outside, link.outsideCount);
  EXPECT_GT(outside, 0u);

  // A rigid translation of every node moves every linked vertex by the same amount.
  Eigen::VectorXd shift(3 * static_cast<Eigen::Index>(placed.nodeCount()));
  for (Eigen::Index i = 0; i < shift.size() / 3; ++i)
    shift.segment<3>(3 * i) = Vec3(0.1, 0.2, -0.3);
  std::vector<Vec3> moved;
  deformSurface(link, placed, shift, vertices, moved);
  for (std::size_t i = 0; i < vertices.size(); ++i)
    ASSERT_LT((moved[i] - vertices[i] - Vec3(0.1, 0.2, -0.3)).norm(), 1e-12);
}

TEST(Adapt, ScalesMassFrequenciesAndModesAndPlacesTheTets) {
  std::mt19937_64 rng(5);
  PhysicalData entry;
  entry.tetMesh = makeTetGrid(2, 2, 2, 0.1, rng);
  for (Vec3& x : entry.tetMesh.nodes)
    x = (x - Vec3::Constant(1.0)) / 2.0;  // unit volume, centred
  entry.massProperties = computeTetMassProperties(entry.tetMesh);
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(entry.tetMesh.nodeCount());
  entry.modes.poissonRatio = 0.3;
  entry.modes.eigenvalues.resize(3);
  entry.modes.eigenvalues << 2.0, 5.0, 9.0;
  entry.modes.shapes = Eigen::MatrixXd::Random(n, 3);
  entry.collision.shapes.push_back(
      {CollisionShape::Type::kCapsule, Vec3(0.1, 0, 0), Mat3::Identity(), Vec3::Zero(), 0.2, 0.3});

  // The query: the same cube, scaled by 3 (L = 3), turned and moved.
  const double L = 3.0;
  Normalization q;
  q.scale = 1.0 / L;
  q.principalAxes = test::randomRotation(rng);
  q.meshFromCanonical.topLeftCorner<3, 3>() = L * q.principalAxes;
  q.meshFromCanonical.topRightCorner<3, 1>() = Vec3(4, 5, 6);
  MassProperties qm;
  qm.density = 1.0;
  qm.volume = L * L * L;
  qm.mass = qm.volume;
  qm.inertia = Mat3::Identity() * std::pow(L, 5) / 6.0;
  const Mat3 orientation = Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitY()).toRotationMatrix();

  Material steel = *materialPreset("Steel");
  auto a = adapt(entry, q, qm, orientation, steel, {2.0, 1e-6});
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_TRUE(a->warnings.empty());
  EXPECT_NEAR(a->massProperties.mass, 7850.0 * 27.0, 1e-6);
  EXPECT_NEAR(a->entryMassProperties.mass, 7850.0 * 27.0, 1e-6);
  EXPECT_LT((a->entryMassProperties.centerOfMass - Vec3(4, 5, 6)).norm(), 1e-9);
  const Eigen::VectorXd expected = entry.modes.frequenciesHz() * std::sqrt(200e9 / 7850.0) / L;
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(a->frequenciesHz()[i] / expected[i], 1.0, 1e-12);
  // Placement: node i sits at c + L R Oᵀ e.
  const Mat3 A = q.principalAxes * orientation.transpose();
  for (std::size_t i = 0; i < entry.tetMesh.nodeCount(); ++i)
    ASSERT_LT((a->tetMesh.nodes[i] - (Vec3(4, 5, 6) + L * A * entry.tetMesh.nodes[i])).norm(), 1e-12);
  // Tet mass properties of the placed mesh at steel's density equal the scaled entry's.
  const MassProperties placed = computeTetMassProperties(a->tetMesh, steel.density);
  EXPECT_NEAR(placed.mass / a->entryMassProperties.mass, 1.0, 1e-12);
  EXPECT_LT((placed.inertia - a->entryMassProperties.inertia).norm() / placed.inertia.norm(), 1e-12);
  // Mode shapes: rotated node by node, scaled by 1/sqrt(ρL³).
  const double s = 1.0 / std::sqrt(steel.density * L * L * L);
  for (Eigen::Index i = 0; i < n / 3; ++i)
    ASSERT_LT((a->modeShapes.block<3, 3>(3 * i, 0) - s * A * entry.modes.shapes.block<3, 3>(3 * i, 0)).norm(),
              1e-12);
  // Collision: centre placed, sizes scaled.
  const CollisionShape& c = a->collision.shapes[0];
  EXPECT_LT((c.center - (Vec3(4, 5, 6) + L * A * Vec3(0.1, 0, 0))).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.radius, 0.6);
  EXPECT_DOUBLE_EQ(c.halfLength, 0.9);

  Material rubber = *materialPreset("rubber");
  auto r = adapt(entry, q, qm, orientation, rubber, {});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->warnings.size(), 1u) << "rubber's Poisson ratio is not the database's";
  EXPECT_FALSE(materialPreset("unobtainium"));
  EXPECT_FALSE(adapt(entry, q, qm, orientation, Material{"bad", -1.0, 1.0, 0.3}, {}));
}

TEST(Fidelity, ZeroForTheSameShapeAndGrowsWithTheDifference) {
  std::mt19937_64 rng(9);
  // The same unit cube as entry (tets) and as query (surface), the query turned, moved and scaled.
  TetMesh tets = makeTetGrid(3, 3, 3, 0.0, rng);
  for (Vec3& x : tets.nodes)
    x = (x - Vec3::Constant(1.5)) / 3.0;
  const TetLocator locator(tets);
  const MassProperties entryMass = computeTetMassProperties(tets);
  const double L = 2.0;
  const Mat3 R = test::randomRotation(rng);
  Normalization q;
  q.scale = 1.0 / L;
  q.principalAxes = R;
  q.meshFromCanonical.topRightCorner<3, 1>() = Vec3(1, 2, 3);
  q.canonicalMoments = Vec3::Constant(1.0 / 6.0);
  const Placement placement = placementOf(q, Mat3::Identity());
  TriangleMesh query = locator.boundary();
  for (Vec3& v : query.vertices)
    v = placement.toQuery(v);
  const Fidelity same = assessFidelity(query, ClosestPointTree(query), q, locator, entryMass, placement, 0.0);
  EXPECT_LT(same.maxDeviation, 1e-12);
  EXPECT_LT(same.maxMomentError, 1e-12);
  EXPECT_EQ(same.samples, 2048);

  // Stretch the query by 10 % along one axis: deviations of a few per cent of L, moments off.
  TriangleMesh stretched = query;
  for (Vec3& v : stretched.vertices)
    v = Vec3(1, 2, 3) + R * (Vec3(1.1, 1.0, 1.0).asDiagonal() * (R.transpose() * (v - Vec3(1, 2, 3))));
  q.canonicalMoments = Vec3(1.0, 1.0, 1.0);  // any different moments
  const Fidelity off =
      assessFidelity(stretched, ClosestPointTree(stretched), q, locator, entryMass, placement, 0.3);
  EXPECT_GT(off.meanDeviation, 0.005);
  EXPECT_NEAR(off.maxDeviation, 0.05, 0.01) << "the stretched faces stand 0.1 L / 2 off the entry's";
  EXPECT_GT(off.maxMomentError, 0.5);
  EXPECT_DOUBLE_EQ(off.descriptorDistance, 0.3);
}

}  // namespace
}  // namespace shapedb::core
