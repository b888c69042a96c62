// Welding: the hash-grid weld against the every-pair oracle, and a soup that becomes a closed surface.

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/core/topology.h>
#include <shapedb/core/weld.h>

#include "support/mesh_files.h"

namespace shapedb::core {
namespace {

TEST(Weld, ASoupOfAClosedSurfaceBecomesThatSurface) {
  const TriangleMesh box = makeBox({0.3, 0.2, 0.1});
  TriangleMesh soup = test::soupOf(box);
  ASSERT_FALSE(analyzeTopology(soup).isClosed());
  const WeldReport report = weldVertices(soup);
  EXPECT_EQ(soup.vertices.size(), box.vertices.size());
  EXPECT_EQ(soup.triangles.size(), box.triangles.size());
  EXPECT_EQ(report.verticesMerged, 3 * box.triangles.size() - box.vertices.size());
  EXPECT_EQ(report.facesCollapsed, 0u);
  const TopologyReport topology = analyzeTopology(soup);
  EXPECT_TRUE(topology.isClosed());
  EXPECT_TRUE(topology.isConsistentlyOriented());
}

TEST(Weld, WithinAToleranceNearbyCornersMergeAndSliversGo) {
  TriangleMesh soup = test::soupOf(makeBox({0.3, 0.2, 0.1}));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> jitter(-1e-7, 1e-7);
  for (Vec3& p : soup.vertices)
    p += Vec3(jitter(rng), jitter(rng), jitter(rng));
  TriangleMesh exact = soup;
  EXPECT_EQ(weldVertices(exact).verticesMerged, 0u);  // nothing is exactly equal any more
  weldVertices(soup, 1e-6);
  EXPECT_TRUE(analyzeTopology(soup).isClosed());
  EXPECT_EQ(soup.vertices.size(), 8u);
}

TEST(Weld, TheHashGridAgreesWithEveryPairOnRandomClusters) {
  std::mt19937_64 rng(2026);
  for (int trial = 0; trial < 40; ++trial) {
    SCOPED_TRACE(trial);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const double tolerance = trial % 4 == 0 ? 0.0 : std::pow(10.0, -1.0 - trial % 3);
    // Clusters of points around random centres, some within the tolerance of each other and some not,
    // with exact duplicates, on and around cell boundaries.
    TriangleMesh mesh;
    std::vector<Vec3> centres(30);
    for (Vec3& c : centres)
      c = Vec3(unit(rng), unit(rng), unit(rng));
    std::uniform_int_distribution<std::size_t> pick(0, centres.size() - 1);
    for (int i = 0; i < 300; ++i) {
      const Vec3& c = centres[pick(rng)];
      const double spread = (i % 3 == 0 ? 0.0 : 2.0 * tolerance + 1e-3 * (i % 2));
      mesh.vertices.push_back(c + spread * Vec3(unit(rng), unit(rng), unit(rng)));
    }
    std::uniform_int_distribution<std::uint32_t> vertex(0,
                                                        static_cast<std::uint32_t>(mesh.vertices.size() - 1));
    for (int i = 0; i < 400; ++i)
      mesh.triangles.push_back({vertex(rng), vertex(rng), vertex(rng)});
    TriangleMesh fast = mesh, plain = mesh;
    const WeldReport a = weldVertices(fast, tolerance);
    const WeldReport b = weldVerticesBruteForce(plain, tolerance);
    EXPECT_EQ(a.verticesMerged, b.verticesMerged);
    EXPECT_EQ(a.facesCollapsed, b.facesCollapsed);
    EXPECT_EQ(fast.vertices, plain.vertices);
    EXPECT_EQ(fast.triangles, plain.triangles);
    EXPECT_GT(a.verticesMerged, 0u);
  }
}

// Coordinates whose cell index would not fit an integer (1e300 over a tolerance of 1e-6), and
// tolerances outside the contract (NaN, ∞, negative: exact equals only), agree with the oracle; under
// UBSan this is also the check that no conversion overflows (a fuzzed OBJ found one).
TEST(Weld, HugeCoordinatesAndTolerancesOutsideTheContractAgreeWithTheOracle) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(1e300, 0, 0),  Vec3(1e300, 0, 0), Vec3(-1e300, 1e-7, 0),
                   Vec3(-1e300, 0, 0), Vec3(0, 0, 1),     Vec3(0, 0, 1 + 1e-7)};
  mesh.triangles = {{0, 2, 4}, {1, 3, 5}, {0, 1, 4}};
  for (const double tolerance : {1e-6, 0.0, std::nan(""), std::numeric_limits<double>::infinity(), -1.0}) {
    TriangleMesh fast = mesh, plain = mesh;
    const WeldReport a = weldVertices(fast, tolerance);
    const WeldReport b = weldVerticesBruteForce(plain, tolerance);
    EXPECT_EQ(a.verticesMerged, b.verticesMerged) << tolerance;
    EXPECT_EQ(fast.vertices, plain.vertices) << tolerance;
    EXPECT_EQ(fast.triangles, plain.triangles) << tolerance;
    // The exact duplicate always merges; the near ones only within a finite positive tolerance.
    EXPECT_EQ(a.verticesMerged, tolerance == 1e-6 ? 3u : 1u) << tolerance;
  }
}

TEST(RemoveUnusedVertices, KeepsTheUsedOnesInTheirOrder) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {9, 9, 9}, {1, 0, 0}, {0, 1, 0}, {8, 8, 8}, {0, 0, 1}};
  mesh.triangles = {{0, 3, 2}, {0, 2, 5}, {2, 3, 5}, {0, 5, 3}};
  EXPECT_EQ(removeUnusedVertices(mesh), 2u);
  const std::vector<Vec3> kept = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_EQ(mesh.vertices, kept);
  const std::vector<TriangleMesh::Triangle> renumbered = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  EXPECT_EQ(mesh.triangles, renumbered);
  EXPECT_EQ(removeUnusedVertices(mesh), 0u);
}

// Two tetrahedra's surfaces in one mesh: dropping the second's triangles drops its vertices too, and
// leaves the first as it was.
TEST(RemoveTriangles, DropsTheFlaggedTrianglesAndTheVerticesOnlyTheyUsed) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {5, 5, 5}, {1, 0, 0}, {6, 5, 5}, {0, 1, 0}, {5, 6, 5}, {0, 0, 1}, {5, 5, 6}};
  mesh.triangles = {{0, 4, 2}, {1, 5, 3}, {0, 2, 6}, {1, 3, 7}, {2, 4, 6}, {3, 5, 7}, {0, 6, 4}, {1, 7, 5}};
  const std::vector<bool> dropped = {false, true, false, true, false, true, false, true};
  removeTriangles(mesh, dropped);
  const std::vector<Vec3> kept = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_EQ(mesh.vertices, kept);
  const std::vector<TriangleMesh::Triangle> first = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  EXPECT_EQ(mesh.triangles, first);
}

}  // namespace
}  // namespace shapedb::core
