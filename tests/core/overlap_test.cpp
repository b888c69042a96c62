// Volume overlap by sampling, compound bounds, and the inertia-equivalent primitives of the baselines.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <shapedb/core/fidelity.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>

namespace shapedb::core {
namespace {

SampledSolid ball(const Vec3& center, double r) {
  return {[=](const Vec3& p) { return (p - center).squaredNorm() <= r * r; },
          Bounds{center - Vec3::Constant(r), center + Vec3::Constant(r)}};
}

TEST(VolumeOverlap, TwoUnitBallsOneRadiusApartMatchTheLensVolume) {
  // Lens of two balls of radius r at distance d: π (4r + d)(2r − d)² / 12.
  const double r = 1.0, d = 1.0;
  const double ballVolume = 4.0 / 3.0 * std::numbers::pi;
  const double lens = std::numbers::pi * (4 * r + d) * (2 * r - d) * (2 * r - d) / 12.0;
  const VolumeOverlap o = sampleOverlap(ball(Vec3::Zero(), r), ball(Vec3(d, 0, 0), r), 160);
  EXPECT_NEAR(o.volumeA / ballVolume, 1.0, 0.01);
  EXPECT_NEAR(o.iou, lens / (2 * ballVolume - lens), 0.01);
  EXPECT_NEAR(o.coverage, lens / ballVolume, 0.01);
  EXPECT_NEAR(o.overshoot, 1.0 - lens / ballVolume, 0.01);
}

TEST(VolumeOverlap, ASolidWithItselfIsOneAndApartIsZero) {
  const VolumeOverlap same = sampleOverlap(ball(Vec3::Zero(), 0.3), ball(Vec3::Zero(), 0.3), 32);
  EXPECT_DOUBLE_EQ(same.iou, 1.0);
  EXPECT_DOUBLE_EQ(same.coverage, 1.0);
  EXPECT_DOUBLE_EQ(same.overshoot, 0.0);
  const VolumeOverlap apart = sampleOverlap(ball(Vec3::Zero(), 0.3), ball(Vec3(2, 0, 0), 0.3), 64);
  EXPECT_EQ(apart.iou, 0.0);
  EXPECT_EQ(apart.coverage, 0.0);
  EXPECT_NEAR(apart.overshoot, 1.0, 0.1);  // B is as big as A, all of it outside
}

TEST(VolumeOverlap, CompoundBoundsHoldEveryShapeTightly) {
  CollisionCompound compound;
  CollisionShape box;
  box.type = CollisionShape::Type::kBox;
  box.center = Vec3(1, 2, 3);
  box.rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  box.halfExtents = Vec3(0.5, 0.2, 0.1);
  CollisionShape capsule;
  capsule.type = CollisionShape::Type::kCapsule;
  capsule.center = Vec3(-1, 0, 0);
  capsule.rotation = Eigen::AngleAxisd(0.4, Vec3::UnitY()).toRotationMatrix();
  capsule.radius = 0.2;
  capsule.halfLength = 0.6;
  CollisionShape sphere;
  sphere.center = Vec3(0.3, -1.5, 1.0);
  sphere.radius = 0.3;
  compound.shapes = {box, capsule, sphere};
  const Bounds b = compoundBounds(compound);
  // Every point inside lies within the bounds, and the bounds are reached within a sampling step.
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  const SampledSolid solid = sampledSolid(compound);
  const int n = 120;
  const Vec3 step = (b.max - b.min + Vec3::Constant(0.2)) / n;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        const Vec3 p = b.min - Vec3::Constant(0.1) + step.cwiseProduct(Vec3(i, j, k));
        if (!solid.contains(p)) continue;
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
  EXPECT_TRUE(((lo - b.min).array() >= 0.0).all());
  EXPECT_TRUE(((b.max - hi).array() >= 0.0).all());
  EXPECT_LT((lo - b.min).maxCoeff(), 2 * step.maxCoeff());
  EXPECT_LT((b.max - hi).maxCoeff(), 2 * step.maxCoeff());
}

TEST(InertiaEquivalent, ABoxAndAnEllipsoidGiveBackTheirOwnSize) {
  const TriangleMesh box = makeBox({0.2, 0.4, 0.6});
  const auto mp = computeMassProperties(box);
  ASSERT_TRUE(mp.ok());
  Eigen::SelfAdjointEigenSolver<Mat3> eig(mp->inertia);
  const Vec3 half = inertiaEquivalentBox(eig.eigenvalues(), mp->mass);  // ascending moments: longest first
  EXPECT_NEAR(half.x(), 0.3, 1e-9);
  EXPECT_NEAR(half.y(), 0.2, 1e-9);
  EXPECT_NEAR(half.z(), 0.1, 1e-9);
  // A solid ellipsoid of semi-axes (3, 2, 1), mass m: I = m (b² + c²) / 5 ...
  const double m = 2.5;
  const Vec3 moments(m * (4 + 1) / 5.0, m * (9 + 1) / 5.0, m * (9 + 4) / 5.0);
  const Vec3 axes = inertiaEquivalentEllipsoid(moments, m);
  EXPECT_NEAR(axes.x(), 3.0, 1e-12);
  EXPECT_NEAR(axes.y(), 2.0, 1e-12);
  EXPECT_NEAR(axes.z(), 1.0, 1e-12);
  // A flat body: I₃ = I₁ + I₂ exactly, and round-off below, gives a zero axis, not NaN.
  const Vec3 flat = inertiaEquivalentBox(Vec3(1.0, 2.0, 3.0 + 1e-15), 1.0);
  EXPECT_EQ(flat.z(), 0.0);
}

}  // namespace
}  // namespace shapedb::core
