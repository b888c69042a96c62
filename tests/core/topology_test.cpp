#include <algorithm>
#include <numeric>
#include <optional>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <shapedb/core/disjoint_sets.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/topology.h>

#include "support/test_support.h"

namespace shapedb::core {
namespace {

TEST(Topology, ClosedBoxIsClosedOrientedSphere) {
  const TopologyReport t = analyzeTopology(makeBox({1, 2, 3}));
  EXPECT_EQ(t.vertexCount, 8u);
  EXPECT_EQ(t.triangleCount, 12u);
  EXPECT_EQ(t.edgeCount, 18u);
  EXPECT_EQ(t.boundaryEdges, 0u);
  EXPECT_EQ(t.nonManifoldEdges, 0u);
  EXPECT_EQ(t.inconsistentEdges, 0u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.eulerCharacteristic(), 2);
  EXPECT_TRUE(t.isClosed());
  EXPECT_TRUE(requireClosedOriented(t).ok());
}

TEST(Topology, MissingFaceLeavesThreeBoundaryEdges) {
  TriangleMesh box = makeBox({1, 1, 1});
  box.triangles.pop_back();
  const TopologyReport t = analyzeTopology(box);
  EXPECT_EQ(t.boundaryEdges, 3u);
  EXPECT_FALSE(t.isClosed());
  const Status s = requireClosedOriented(t);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kNotClosed);
  EXPECT_EQ(s.error().message, "mesh is not closed (3 boundary edges)");
}

TEST(Topology, FlippedFaceMakesThreeInconsistentEdges) {
  TriangleMesh box = makeBox({1, 1, 1});
  std::swap(box.triangles[4][1], box.triangles[4][2]);
  const TopologyReport t = analyzeTopology(box);
  EXPECT_TRUE(t.isClosed());
  EXPECT_EQ(t.inconsistentEdges, 3u);
  EXPECT_EQ(requireClosedOriented(t).error().code, ErrorCode::kInconsistentOrientation);
}

TEST(Topology, FinOnAnEdgeIsNonManifold) {
  TriangleMesh box = makeBox({1, 1, 1});
  box.vertices.emplace_back(2.0, 2.0, 2.0);
  const auto& t0 = box.triangles[0];
  box.triangles.push_back({t0[0], t0[1], 8});
  const TopologyReport t = analyzeTopology(box);
  EXPECT_EQ(t.nonManifoldEdges, 1u);
  EXPECT_EQ(t.boundaryEdges, 2u);
  EXPECT_EQ(requireClosedOriented(t).error().code, ErrorCode::kNotClosed);
}

TEST(Topology, CountsComponentsAndUnreferencedVertices) {
  TriangleMesh a = makeBox({1, 1, 1});
  const TriangleMesh b = makeIcosphere(1.0, 1);
  const auto offset = static_cast<std::uint32_t>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles)
    a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  a.vertices.emplace_back(9.0, 9.0, 9.0);
  const TopologyReport t = analyzeTopology(a);
  EXPECT_EQ(t.components, 2u);
  EXPECT_EQ(t.eulerCharacteristic(), 4);
  EXPECT_EQ(t.unreferencedVertices, 1u);
}

void expectSameReport(const TopologyReport& a, const TopologyReport& b) {
  EXPECT_EQ(a.vertexCount, b.vertexCount);
  EXPECT_EQ(a.unreferencedVertices, b.unreferencedVertices);
  EXPECT_EQ(a.triangleCount, b.triangleCount);
  EXPECT_EQ(a.edgeCount, b.edgeCount);
  EXPECT_EQ(a.boundaryEdges, b.boundaryEdges);
  EXPECT_EQ(a.nonManifoldEdges, b.nonManifoldEdges);
  EXPECT_EQ(a.inconsistentEdges, b.inconsistentEdges);
  EXPECT_EQ(a.components, b.components);
}

// The bucketed analysis against the global sort, on random soups (every defect at once: repeated
// indices, fins, flipped and doubled faces) and on damaged closed meshes with shuffled vertex ids.
TEST(Topology, BucketedAnalysisAgreesWithTheGlobalSortOnRandomMeshes) {
  std::mt19937 rng(20261122);
  for (int trial = 0; trial < 300; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    TriangleMesh mesh;
    if (trial % 2 == 0) {
      const int vertexCount = std::uniform_int_distribution<int>(3, 40)(rng);
      mesh.vertices.assign(static_cast<std::size_t>(vertexCount), Vec3::Zero());
      std::uniform_int_distribution<std::uint32_t> index(0, static_cast<std::uint32_t>(vertexCount - 1));
      const int faceCount = std::uniform_int_distribution<int>(1, 200)(rng);
      for (int f = 0; f < faceCount; ++f)
        mesh.triangles.push_back({index(rng), index(rng), index(rng)});
    } else {
      mesh = makeIcosphere(1.0, 2);
      std::vector<std::uint32_t> relabel(mesh.vertices.size());
      std::iota(relabel.begin(), relabel.end(), 0u);
      std::shuffle(relabel.begin(), relabel.end(), rng);
      for (auto& t : mesh.triangles)
        for (auto& v : t)
          v = relabel[v];
      std::uniform_int_distribution<std::size_t> face(0, mesh.triangles.size() - 1);
      for (int damage = trial % 7; damage > 0; --damage) {
        switch (damage % 3) {
          case 0:
            mesh.triangles.erase(mesh.triangles.begin() + static_cast<std::ptrdiff_t>(face(rng)));
            break;
          case 1:
            mesh.triangles.push_back(mesh.triangles[face(rng)]);
            break;
          default: {
            auto& flipped = mesh.triangles[face(rng)];
            std::swap(flipped[0], flipped[1]);
          }
        }
      }
    }
    expectSameReport(analyzeTopology(mesh), analyzeTopologyBySorting(mesh));
  }
}

// Shells: each component's enclosed volume, signed by its winding. A hollow box (an inner box wound
// inward) is a solid shell and a cavity whose volumes sum to the solid's; two boxes apart are two solids;
// far from the origin the volumes are as exact (each is summed about a vertex of its own).
TEST(Topology, ShellsAreSignedByTheirWinding) {
  for (const Vec3& far : {Vec3(0, 0, 0), Vec3(1e6, -2e6, 3e5)}) {
    const TriangleMesh hollow = test::withShell(test::withShell({}, makeBox(Vec3(2, 2, 2)), far, false),
                                                makeBox(Vec3(1, 1, 0.5)), far + Vec3(0.2, 0.1, 0.0), true);
    const std::vector<Shell> shells = findShells(hollow);
    ASSERT_EQ(shells.size(), 2u);
    EXPECT_NEAR(shells[0].volume, 8.0, 1e-9);
    EXPECT_NEAR(shells[1].volume, -0.5, 1e-9);
    EXPECT_EQ(shells[0].triangles.size(), 12u);
    EXPECT_EQ(shells[1].triangles.front(), 12u);
    const ShellCount hollowCount = countShells(shells);
    EXPECT_EQ(hollowCount.solids, 1u);
    EXPECT_EQ(hollowCount.cavities, 1u);
    EXPECT_DOUBLE_EQ(hollowCount.largestSolidShare, 1.0);

    const TriangleMesh apart = test::withShell(test::withShell({}, makeBox(Vec3(1, 1, 1)), far, false),
                                               makeBox(Vec3(1, 2, 1)), far + Vec3(3, 0, 0), false);
    const std::vector<Shell> two = findShells(apart);
    ASSERT_EQ(two.size(), 2u);
    EXPECT_NEAR(two[0].volume, 1.0, 1e-9);
    EXPECT_NEAR(two[1].volume, 2.0, 1e-9);
    const ShellCount twoCount = countShells(two);
    EXPECT_EQ(twoCount.solids, 2u);
    EXPECT_EQ(twoCount.cavities, 0u);
    EXPECT_NEAR(twoCount.largestSolidShare, 2.0 / 3.0, 1e-12);
  }
  const std::vector<Shell> one = findShells(makeIcosphere(1.0, 2));
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].triangles.size(), 320u);
  EXPECT_GT(one[0].volume, 4.0);  // a bit under 4π/3 = 4.19
}

// A T-junction on a random face abx of closed, oriented `original` (as it stands in `mesh`, which has
// original's faces first): a vertex m put on the edge ab, 0.2 to 0.8 along it and lifted lift·|ab| off it
// into abx (0: on it), abx split into amx and mbx, and the face abm (wound a → b against the other side's
// b → a) closing the surface again. Neither abx nor the face across ab may be `used`; both are marked.
// The area of the face across ab, or nothing when a used face was drawn.
std::optional<double> addJunction(TriangleMesh& mesh, const TriangleMesh& original, std::vector<char>& used,
                                  double lift, std::mt19937_64& rng) {
  const auto t = static_cast<std::uint32_t>(rng() % original.triangles.size());
  if (used[t]) return std::nullopt;
  const int k = static_cast<int>(rng() % 3);
  const std::uint32_t a = original.triangles[t][k], b = original.triangles[t][(k + 1) % 3],
                      x = original.triangles[t][(k + 2) % 3];
  std::size_t across = 0;  // the face with the edge b → a
  for (; across < original.triangles.size(); ++across) {
    const auto& f = original.triangles[across];
    if ((f[0] == b && f[1] == a) || (f[1] == b && f[2] == a) || (f[2] == b && f[0] == a)) break;
  }
  EXPECT_LT(across, original.triangles.size());
  if (across == original.triangles.size() || used[across]) return std::nullopt;
  used[t] = used[across] = 1;
  const Vec3 &pa = original.vertices[a], &pb = original.vertices[b], &px = original.vertices[x];
  const double where = std::uniform_real_distribution<double>(0.2, 0.8)(rng);
  const Vec3 ab = pb - pa;
  const Vec3 inward = ((px - pa) - (px - pa).dot(ab) / ab.squaredNorm() * ab).normalized();
  const auto m = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.push_back((1.0 - where) * pa + where * pb + lift * ab.norm() * inward);
  mesh.triangles[t] = {a, m, x};
  mesh.triangles.push_back({m, b, x});
  mesh.triangles.push_back({a, b, m});
  const auto& f = original.triangles[across];
  return 0.5 * (original.vertices[f[1]] - original.vertices[f[0]])
                   .cross(original.vertices[f[2]] - original.vertices[f[0]])
                   .norm();
}

// T-junctions, as CAD tessellations and STL exports leave them: a vertex m put on an edge ab of a closed
// surface on one side only (the triangle abx split into amx and mbx), and the zero-area face abm that
// closes the surface again. Flipped away, on random surfaces with random such junctions: no zero-area face
// is left, the surface is closed and wound as before, its vertices are untouched, and its volume, centroid
// and second moments are those of the surface before the junctions (the oracle), to round-off.
TEST(Topology, ZeroAreaFacesOfTJunctionsAreFlippedAwayLeavingTheSameSurface) {
  std::mt19937_64 rng(31);
  const auto moments = [](const TriangleMesh& mesh) {
    // Volume, first and second moments about the origin: sums over tets (0, a, b, c).
    Eigen::Matrix<double, 10, 1> out = Eigen::Matrix<double, 10, 1>::Zero();
    for (const auto& t : mesh.triangles) {
      const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
      const double v = a.dot(b.cross(c)) / 6.0;
      const Vec3 s = a + b + c;
      out[0] += v;
      out.segment<3>(1) += v * s / 4.0;
      int k = 4;
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
          out[k++] += v / 20.0 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
    }
    return out;
  };
  for (int trial = 0; trial < 20; ++trial) {
    const TriangleMesh original = trial % 2 == 0 ? makeIcosphere(1.0, 2) : makeBox(Vec3(2.0, 1.0, 0.5));
    TriangleMesh mesh = original;
    const int junctions = 1 + static_cast<int>(rng() % 6);
    int made = 0;
    std::vector<char> used(original.triangles.size(), 0);  // split, or across a split edge
    for (int tries = 0; made < junctions && tries < 100; ++tries)
      if (addJunction(mesh, original, used, 0.0, rng)) ++made;
    ASSERT_GT(made, 0);
    const TopologyReport before = analyzeTopology(mesh);
    ASSERT_TRUE(before.isClosed() && before.isConsistentlyOriented());
    ASSERT_EQ(findDefects(mesh).zeroAreaFaces, static_cast<std::size_t>(made));
    const std::vector<Vec3> vertices = mesh.vertices;
    EXPECT_EQ(flipZeroAreaFaces(mesh), static_cast<std::size_t>(made)) << "trial " << trial;
    EXPECT_EQ(findDefects(mesh).zeroAreaFaces, 0u) << "trial " << trial;
    const TopologyReport after = analyzeTopology(mesh);
    EXPECT_TRUE(after.isClosed() && after.isConsistentlyOriented()) << "trial " << trial;
    EXPECT_EQ(after.eulerCharacteristic(), before.eulerCharacteristic());
    EXPECT_EQ(mesh.vertices, vertices);
    EXPECT_LT((moments(mesh) - moments(original)).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
  }
}

// Caps, as CAD tessellations leave them: the T-junctions above with the vertex m lifted a hair off the edge
// ab, into the triangle it splits (so that amx and mbx stay wound as abx was), which makes abm a sliver of
// height h = lift·|ab| instead of a flat face. Flipped away at a relative height over the lifts: none is
// left, the surface is closed and wound as before, its vertices are untouched, and its volume moves by at
// most Σ h·area(the face across ab)/3 (the tets a, b, m, x each flip adds or removes: the oracle bound).
// At a relative height under the lifts nothing is flipped, and flipZeroAreaFaces flips none.
TEST(Topology, CapsAreFlippedAwayMovingTheSurfaceByNoMoreThanTheirHeights) {
  std::mt19937_64 rng(47);
  const auto volumeOf = [](const TriangleMesh& mesh) {
    double v = 0.0;
    for (const auto& t : mesh.triangles)
      v += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
    return v;
  };
  for (int trial = 0; trial < 20; ++trial) {
    const TriangleMesh original = trial % 2 == 0 ? makeIcosphere(1.0, 2) : makeBox(Vec3(2.0, 1.0, 0.5));
    TriangleMesh mesh = original;
    std::vector<char> used(original.triangles.size(), 0);
    int made = 0;
    double bound = 0.0;
    for (int tries = 0; made < 4 && tries < 100; ++tries) {
      const double lift = std::pow(10.0, std::uniform_real_distribution<double>(-7.0, -5.0)(rng));
      const std::optional<double> acrossArea = addJunction(mesh, original, used, lift, rng);
      if (!acrossArea) continue;
      // The cap abm is the last face added: m lies lift·|ab| off ab.
      const auto& cap = mesh.triangles.back();
      bound += lift * (mesh.vertices[cap[1]] - mesh.vertices[cap[0]]).norm() * *acrossArea / 3.0;
      ++made;
    }
    ASSERT_GT(made, 0);
    const TopologyReport before = analyzeTopology(mesh);
    ASSERT_TRUE(before.isClosed() && before.isConsistentlyOriented());
    ASSERT_EQ(findDefects(mesh).zeroAreaFaces, 0u);
    TriangleMesh unchanged = mesh;
    EXPECT_EQ(flipZeroAreaFaces(unchanged), 0u);
    EXPECT_EQ(flipThinFaces(unchanged, 1e-8), 0u);
    const std::vector<Vec3> vertices = mesh.vertices;
    const double volume = volumeOf(mesh);
    EXPECT_EQ(flipThinFaces(mesh, 1e-4), static_cast<std::size_t>(made)) << "trial " << trial;
    EXPECT_EQ(flipThinFaces(mesh, 1e-4), 0u) << "trial " << trial;  // none is left
    const TopologyReport after = analyzeTopology(mesh);
    EXPECT_TRUE(after.isClosed() && after.isConsistentlyOriented()) << "trial " << trial;
    EXPECT_EQ(after.eulerCharacteristic(), before.eulerCharacteristic());
    EXPECT_EQ(mesh.vertices, vertices);
    EXPECT_LE(std::abs(volumeOf(mesh) - volume), bound * (1.0 + 1e-9) + 1e-15) << "trial " << trial;
    EXPECT_GT(std::abs(volumeOf(mesh) - volume), 0.0) << "trial " << trial;  // the surface did move
  }
}

TEST(Validate, AcceptsAGoodMesh) {
  EXPECT_TRUE(validateMesh(makeIcosphere(1.0, 2)).ok());
}

TEST(Validate, RejectsEachDefectWithItsCode) {
  TriangleMesh empty;
  EXPECT_EQ(validateMesh(empty).error().code, ErrorCode::kEmptyMesh);

  TriangleMesh nan = makeBox({1, 1, 1});
  nan.vertices[3].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validateMesh(nan).error().code, ErrorCode::kNonFinite);
  EXPECT_EQ(validateMesh(nan).error().message, "vertex 3 has a non-finite coordinate");

  TriangleMesh inf = makeBox({1, 1, 1});
  inf.vertices[0].x() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(validateMesh(inf).error().code, ErrorCode::kNonFinite);

  TriangleMesh range = makeBox({1, 1, 1});
  range.triangles[7][2] = 8;
  EXPECT_EQ(validateMesh(range).error().code, ErrorCode::kIndexOutOfRange);
  EXPECT_EQ(validateMesh(range).error().message, "face 7 refers to vertex 8, but the mesh has 8 vertices");

  TriangleMesh repeated = makeBox({1, 1, 1});
  repeated.triangles.push_back({1, 1, 2});
  EXPECT_EQ(validateMesh(repeated).error().code, ErrorCode::kDegenerateFace);
  EXPECT_EQ(validateMesh(repeated).error().message, "1 degenerate face (first: face 12, repeated vertex)");
  EXPECT_TRUE(validateMesh(repeated, {.allowDegenerateFaces = true}).ok());
  EXPECT_EQ(removeRepeatedVertexFaces(repeated), 1u);
  EXPECT_TRUE(validateMesh(repeated).ok());

  TriangleMesh collinear = makeBox({1, 1, 1});
  collinear.vertices.push_back(0.5 * (collinear.vertices[0] + collinear.vertices[7]));
  collinear.triangles.push_back({0, 8, 7});
  EXPECT_EQ(validateMesh(collinear).error().message, "1 degenerate face (first: face 12, zero area)");
  const MeshDefects d = findDefects(collinear);
  EXPECT_EQ(d.zeroAreaFaces, 1u);
  EXPECT_EQ(d.repeatedVertexFaces, 0u);
}

}  // namespace
}  // namespace shapedb::core

namespace shapedb::core {
namespace {

// Union-find against its oracle: the connected components of the same joins found by a breadth-first
// search over them, on random graphs from sparse to nearly connected.
TEST(DisjointSets, AgreeWithABreadthFirstSearchOnRandomJoins) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const std::uint32_t n = 1 + static_cast<std::uint32_t>(rng() % 300);
    const std::size_t joins = rng() % (2 * n);
    DisjointSets sets(n);
    std::vector<std::vector<std::uint32_t>> neighbours(n);
    for (std::size_t j = 0; j < joins; ++j) {
      const auto a = static_cast<std::uint32_t>(rng() % n), b = static_cast<std::uint32_t>(rng() % n);
      const bool wereApart = sets.find(a) != sets.find(b);
      EXPECT_EQ(sets.unite(a, b), wereApart);
      neighbours[a].push_back(b);
      neighbours[b].push_back(a);
    }
    std::vector<int> component(n, -1);
    int components = 0;
    for (std::uint32_t start = 0; start < n; ++start) {
      if (component[start] >= 0) continue;
      std::vector<std::uint32_t> queue{start};
      component[start] = components;
      for (std::size_t q = 0; q < queue.size(); ++q)
        for (std::uint32_t next : neighbours[queue[q]])
          if (component[next] < 0) {
            component[next] = components;
            queue.push_back(next);
          }
      ++components;
    }
    ASSERT_EQ(sets.sets(), static_cast<std::size_t>(components)) << "trial " << trial;
    for (std::uint32_t a = 0; a < n; ++a) {
      const std::uint32_t b = static_cast<std::uint32_t>(rng() % n);
      EXPECT_EQ(sets.find(a) == sets.find(b), component[a] == component[b]);
    }
  }
}

}  // namespace
}  // namespace shapedb::core
