#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>

namespace shapedb::core {
namespace {

void expectClosedOutward(const TriangleMesh& mesh) {
  ASSERT_TRUE(validateMesh(mesh).ok()) << validateMesh(mesh).error().message;
  const TopologyReport t = analyzeTopology(mesh);
  EXPECT_TRUE(t.isClosed());
  EXPECT_TRUE(t.isConsistentlyOriented());
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.eulerCharacteristic(), 2);
  const Result<MassProperties> mp = computeMassProperties(mesh);
  ASSERT_TRUE(mp.ok()) << mp.error().message;
  EXPECT_FALSE(mp->wasFlipped);
}

TEST(Primitives, AreClosedAndWoundOutward) {
  expectClosedOutward(makeTetrahedron({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}));
  expectClosedOutward(makeTetrahedron({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}));
  expectClosedOutward(makeBox({1, 2, 3}));
  expectClosedOutward(makeUvEllipsoid({1, 2, 3}, 12, 7));
  expectClosedOutward(makeIcosphere(2.0, 3));
  expectClosedOutward(makeCylinder(1.0, 3.0, 17));
  expectClosedOutward(subdivideMidpoint(makeBox({1, 1, 1})));
}

TEST(Primitives, SubdivisionKeepsTheSurface) {
  const TriangleMesh box = makeBox({1, 2, 3});
  const TriangleMesh fine = subdivideMidpoint(subdivideMidpoint(box));
  EXPECT_EQ(fine.triangleCount(), 16 * box.triangleCount());
  EXPECT_NEAR(computeSurfaceArea(fine), computeSurfaceArea(box), 1e-12);
}

}  // namespace
}  // namespace shapedb::core
