// Where an impact strikes (sound.h): the vertex and the direction of the blow.

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/core/sound.h>

namespace shapedb::core {
namespace {

TEST(Sound, AnImpactStrikesTheFarthestVertexOrTheOneNearestAPointInwardAlongItsNormal) {
  // A 4 × 2 × 1 box about the origin: every corner is as far from the centre, so the farthest is the
  // first of them in the vertex order; its normal is the sum of its three faces' area-weighted normals.
  const TriangleMesh box = makeBox({4.0, 2.0, 1.0});
  Result<ImpactPoint> far = chooseImpact(box, Vec3::Zero());
  ASSERT_TRUE(far.ok()) << far.error().message;
  const Vec3 corner = box.vertices[far->vertex];
  EXPECT_NEAR(corner.cwiseAbs().maxCoeff(), 2.0, 1e-12);
  EXPECT_NEAR(corner.squaredNorm(), 4.0 + 1.0 + 0.25, 1e-12);
  EXPECT_NEAR(far->direction.norm(), 1.0, 1e-12);
  // Inward: against the corner's own position, on every axis.
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(far->direction[a] * corner[a], 0.0) << a;

  // Nearest a point beside one corner: that corner, whatever the centre.
  const Vec3 beside(-2.1, 1.2, 0.6);
  Result<ImpactPoint> near = chooseImpact(box, Vec3(100, 100, 100), beside);
  ASSERT_TRUE(near.ok());
  EXPECT_LT((box.vertices[near->vertex] - Vec3(-2.0, 1.0, 0.5)).norm(), 1e-12);
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(near->direction[a] * beside[a], 0.0) << a;

  EXPECT_EQ(chooseImpact(TriangleMesh{}, Vec3::Zero()).error().code, ErrorCode::kEmptyMesh);
}

}  // namespace
}  // namespace shapedb::core
