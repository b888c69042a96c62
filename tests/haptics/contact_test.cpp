// Signed distances to compound solids (contact.h), checked against containment and sampled surfaces.

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <shapedb/haptics/contact.h>

namespace shapedb::haptics {
namespace {

using core::CollisionShape;
using core::Vec3;

core::Mat3 randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

CollisionShape randomShape(CollisionShape::Type type, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.2, 1.0);
  CollisionShape s;
  s.type = type;
  s.center = Vec3(u(rng), u(rng), u(rng));
  s.rotation = randomRotation(rng);
  s.halfExtents = Vec3(u(rng), u(rng), u(rng));
  s.radius = u(rng);
  s.halfLength = u(rng);
  return s;
}

/// Points spread over the solid's surface, densely (the oracle for the closest surface point).
std::vector<Vec3> surfaceSamples(const CollisionShape& s, std::mt19937_64& rng, int count) {
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> points;
  while (static_cast<int>(points.size()) < count) {
    Vec3 local;
    if (s.type == CollisionShape::Type::kBox) {
      local = Vec3(u(rng), u(rng), u(rng));
      const int face = static_cast<int>(rng() % 3);
      local[face] = local[face] < 0.0 ? -1.0 : 1.0;
      local = local.cwiseProduct(s.halfExtents);
    } else {
      Vec3 d(n(rng), n(rng), n(rng));
      if (s.type == CollisionShape::Type::kCapsule && rng() % 2) {
        d.z() = 0.0;  // the cylindrical side
        local = s.radius * d.normalized() + Vec3(0.0, 0.0, s.halfLength * u(rng));
      } else {
        local = s.radius * d.normalized();  // a sphere, or a capsule's cap
        if (s.type == CollisionShape::Type::kCapsule)
          local.z() += (local.z() >= 0.0 ? 1.0 : -1.0) * s.halfLength;
      }
    }
    points.push_back(s.center + s.rotation * local);
  }
  return points;
}

TEST(Contact, SignedDistanceAgreesWithContainmentAndTheSampledSurface) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 2.5);
  for (const auto type :
       {CollisionShape::Type::kSphere, CollisionShape::Type::kBox, CollisionShape::Type::kCapsule}) {
    for (int shapeIndex = 0; shapeIndex < 5; ++shapeIndex) {
      const CollisionShape shape = randomShape(type, rng);
      const std::vector<Vec3> samples = surfaceSamples(shape, rng, 20000);
      for (int i = 0; i < 200; ++i) {
        const Vec3 p(u(rng), u(rng), u(rng));
        const SurfaceDistance d = signedDistance(shape, p);
        SCOPED_TRACE(std::string(core::toString(type)) + " point " + std::to_string(i));
        EXPECT_EQ(d.distance < 0.0, shape.contains(p));
        EXPECT_NEAR(std::abs(d.distance), (p - d.point).norm(), 1e-12);
        EXPECT_NEAR(d.normal.norm(), 1.0, 1e-12);
        EXPECT_LT((p - d.distance * d.normal - d.point).norm(), 1e-12);
        EXPECT_NEAR(signedDistance(shape, d.point).distance, 0.0, 1e-12);  // the point is on the surface
        double nearest = 1e300;
        for (const Vec3& s : samples)
          nearest = std::min(nearest, (p - s).norm());
        EXPECT_LE(std::abs(d.distance), nearest + 1e-12);  // no surface sample is closer
        EXPECT_GE(std::abs(d.distance), nearest - 0.05);   // and the samples come close to it
      }
    }
  }
}

TEST(Contact, UnionTakesTheDeepestSolidAndBoundsEveryShape) {
  std::mt19937_64 rng(3);
  std::vector<CollisionShape> shapes = {randomShape(CollisionShape::Type::kBox, rng),
                                        randomShape(CollisionShape::Type::kCapsule, rng),
                                        randomShape(CollisionShape::Type::kSphere, rng)};
  std::uniform_real_distribution<double> u(-2.0, 3.0);
  const Vec3 center(0.5, 0.5, 0.5);
  const double radius = boundingRadius(shapes, center);
  for (int i = 0; i < 500; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    double smallest = 1e300;
    bool inside = false;
    for (const CollisionShape& s : shapes) {
      smallest = std::min(smallest, signedDistance(s, p).distance);
      inside = inside || s.contains(p);
    }
    EXPECT_EQ(signedDistance(shapes, p).distance, smallest);
    EXPECT_EQ(smallest < 0.0, inside);
    if (inside) {
      EXPECT_LE((p - center).norm(), radius + 1e-12);
    }
  }
}

}  // namespace
}  // namespace shapedb::haptics
