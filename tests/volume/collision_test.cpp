// The collision compound (collision.h): boxes, spheres and capsules fitted to a solid's voxels.

#include <cstdio>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/volume/collision.h>

namespace shapedb::volume {
namespace {

TEST(Collision, ABoxIsOneBoxAndASphereIsCoveredWithLittleOvershoot) {
  auto box = fitCollisionCompound(core::makeBox(core::Vec3(2.0, 1.0, 0.5)));
  ASSERT_TRUE(box.ok()) << box.error().message;
  ASSERT_EQ(box->shapes.size(), 1u);
  EXPECT_EQ(box->shapes[0].type, core::CollisionShape::Type::kBox);
  EXPECT_GT(box->coverage, 0.99);
  EXPECT_LT(box->overshoot, 0.01);
  EXPECT_NEAR(box->shapes[0].volume(), 1.0, 0.1);

  auto sphere = fitCollisionCompound(core::makeIcosphere(1.0, 3));
  ASSERT_TRUE(sphere.ok());
  // A sphere, or a capsule so short it is one (voxel centres straddle the true centre).
  EXPECT_LT(sphere->shapes.front().halfLength, 0.1);
  EXPECT_GT(sphere->coverage, 0.9);
  EXPECT_LT(sphere->overshoot, 0.05);

  // A capsule along x: mostly covered, little overshoot. (Voxel centres sit half a voxel off its axis,
  // so the fitted capsules are thinner than the real one: a known weakness of fitting to voxel centres.)
  const core::TriangleMesh capsule = core::transformed(core::makeCapsule(0.3, 2.0, 24, 8), [] {
    core::Mat4 t = core::Mat4::Identity();
    t.topLeftCorner<3, 3>() << 0, 0, 1, 0, 1, 0, -1, 0, 0;
    return t;
  }());
  auto c = fitCollisionCompound(capsule);
  ASSERT_TRUE(c.ok());
  EXPECT_GT(c->coverage, 0.8);
  EXPECT_LT(c->overshoot, 0.05);
  std::printf("capsule: %zu shapes, coverage %.3f, overshoot %.3f\n", c->shapes.size(), c->coverage,
              c->overshoot);
}

}  // namespace
}  // namespace shapedb::volume
