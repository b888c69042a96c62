// Signed distances to compound solids, checked against containment and sampled surfaces; the trajectory
// device's playback and its errors.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <unistd.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <shapedb/haptics/contact.h>
#include <shapedb/haptics/device.h>

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

TEST(Device, CsvPlaybackInterpolatesAndHoldsTheEnds) {
  const auto path =
      std::filesystem::temp_directory_path() / ("shapedb-trajectory-" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream out(path);
    out << "t,x,y,z\n0,0,0,0\n\n1, 1, 2, 3\r\n3,1,2,-1\n";
  }
  Result<TrajectoryDevice> device = TrajectoryDevice::fromCsv(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(device.ok()) << device.error().message;
  EXPECT_EQ(device->keyframes().size(), 3u);
  EXPECT_LT((device->position(0.5) - Vec3(0.5, 1.0, 1.5)).norm(), 1e-15);
  EXPECT_LT((device->position(2.0) - Vec3(1.0, 2.0, 1.0)).norm(), 1e-15);
  EXPECT_LT((device->position(-1.0) - Vec3::Zero()).norm(), 1e-15);
  EXPECT_LT((device->position(10.0) - Vec3(1.0, 2.0, -1.0)).norm(), 1e-15);
  EXPECT_LT((device->position(0.25) - Vec3(0.25, 0.5, 0.75)).norm(), 1e-15);  // back in time
  device->applyForce(0.0, Vec3(1, 2, 3));
  EXPECT_EQ(device->lastForce(), Vec3(1, 2, 3));
}

TEST(Device, CsvErrorsNameTheFileAndLine) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto write = [&](const std::string& name, const std::string& text) {
    const auto path = dir / (name + std::to_string(::getpid()) + ".csv");
    std::ofstream(path) << text;
    return path;
  };
  const auto bad = write("shapedb-bad-", "t,x,y,z\n0,0,0,0\n1,2,x,3\n");
  Result<TrajectoryDevice> r = TrajectoryDevice::fromCsv(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kParse);
  EXPECT_NE(r.error().message.find(bad.string() + ":3:"), std::string::npos) << r.error().message;
  const auto back = write("shapedb-back-", "0,0,0,0\n1,0,0,0\n0.5,0,0,0\n");
  r = TrajectoryDevice::fromCsv(back);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("back in time"), std::string::npos) << r.error().message;
  const auto empty = write("shapedb-empty-", "t,x,y,z\n");
  r = TrajectoryDevice::fromCsv(empty);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(empty.string()), std::string::npos) << r.error().message;
  EXPECT_EQ(TrajectoryDevice::fromCsv(dir / "shapedb-no-such-file.csv").error().code, ErrorCode::kIo);
  for (const auto& p : {bad, back, empty})
    std::filesystem::remove(p);
}

TEST(Device, SweepRunsEveryLaneAcrossTheBoxAtItsSpeed) {
  // Lanes 4 m long, 1 m apart, at 2 m/s: 2 s a lane, 0.5 s between lanes.
  TrajectoryDevice sweep = TrajectoryDevice::sweep(Vec3(0, 0, 0), Vec3(4, 2, 1), 3, 2.0);
  EXPECT_LT((sweep.position(0.0) - Vec3(0, 0, 0.5)).norm(), 1e-15);
  EXPECT_LT((sweep.position(1.0) - Vec3(2, 0, 0.5)).norm(), 1e-15);
  EXPECT_LT((sweep.position(2.25) - Vec3(4, 0.5, 0.5)).norm(), 1e-15);  // moving to the next lane
  EXPECT_LT((sweep.position(3.5) - Vec3(2, 1, 0.5)).norm(), 1e-15);     // second lane, coming back
  EXPECT_LT((sweep.position(7.0) - Vec3(4, 2, 0.5)).norm(), 1e-15);
  EXPECT_LT((sweep.position(100.0) - Vec3(4, 2, 0.5)).norm(), 1e-15);
}

}  // namespace
}  // namespace shapedb::haptics
