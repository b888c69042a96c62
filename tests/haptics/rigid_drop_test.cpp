// The rigid-body scenario in Bullet: known resting poses, the compound placed where Bullet sees it, and
// determinism.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/haptics/rigid_drop.h>

#include "support/test_support.h"

namespace shapedb::haptics {
namespace {

using core::CollisionShape;
using core::Mat3;
using core::Vec3;

/// A solid box of steel as a body: exact mass properties, its compound the box itself.
RigidBody box(const Vec3& size, const Mat3& rotation = Mat3::Identity(), const Vec3& center = Vec3::Zero()) {
  core::TriangleMesh mesh = core::makeBox(size);
  core::Mat4 pose = core::Mat4::Identity();
  pose.topLeftCorner<3, 3>() = rotation;
  pose.topRightCorner<3, 1>() = center;
  mesh = core::transformed(mesh, pose);
  RigidBody body;
  body.massProperties = *core::computeMassProperties(mesh, {.density = 7850.0});
  CollisionShape shape;
  shape.type = CollisionShape::Type::kBox;
  shape.center = center;
  shape.rotation = rotation;
  shape.halfExtents = 0.5 * size;
  body.collision.shapes.push_back(shape);
  return body;
}

TEST(RigidDrop, ABoxComesToRestOnItsLargestFace) {
  const RigidBody body = box({0.3, 0.2, 0.1});
  const Result<DropReport> report = simulateDrop(std::span(&body, 1));
  ASSERT_TRUE(report.ok()) << report.error().message;
  const BodyOutcome& outcome = report->bodies[0];
  EXPECT_GE(outcome.restTime, 0.0);
  EXPECT_EQ(report->atRest, 1u);
  const Vec3 com = outcome.finalPose.topRightCorner<3, 1>();  // the centre of mass started at the origin
  EXPECT_NEAR(com.z(), 0.05, 2e-3);
  EXPECT_NEAR(outcome.finalLowestPoint, 0.0, 2e-3);
  // Dissipated: from m g (0.3 + 0.05) at the start to m g 0.05 at rest.
  const double mass = body.massProperties.mass;
  EXPECT_NEAR(report->potentialEnergy.back(), mass * 9.81 * 0.05, mass * 9.81 * 2e-3);
  EXPECT_LT(report->kineticEnergy.back(), 1e-3);
}

TEST(RigidDrop, ASphereWithoutRestitutionRestsOnTheFloor) {
  RigidBody body;
  const core::TriangleMesh mesh = core::makeIcosphere(0.05, 4);
  body.massProperties = *core::computeMassProperties(mesh, {.density = 1000.0});
  CollisionShape sphere;
  sphere.radius = 0.05;
  body.collision.shapes.push_back(sphere);
  DropOptions options;
  options.restitution = 0.0;
  const Result<DropReport> report = simulateDrop(std::span(&body, 1), options);
  ASSERT_TRUE(report.ok()) << report.error().message;
  EXPECT_NEAR(report->bodies[0].finalPose(2, 3), 0.05, 1e-3);
  EXPECT_GE(report->bodies[0].restTime, 0.0);
}

TEST(RigidDrop, TurnedAndOffCentreCompoundsRestWhereBulletSeesThem) {
  // Bodies whose principal frames differ from the world's and whose shapes sit off their centre of
  // mass (an L of two boxes): once at rest, the exact lowest point of the shapes, moved by the reported
  // pose, touches the floor. A compound placed wrongly in the body frame would float or sink.
  std::mt19937_64 rng(7);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 4; ++i) {
    const Mat3 r = test::randomRotation(rng);
    const Vec3 at(0.5 * i, 0.0, 0.2);
    RigidBody a = box({0.2, 0.05, 0.05}, r, at);
    const RigidBody b = box({0.05, 0.15, 0.05}, r, at + r * Vec3(0.075, 0.1, 0.0));
    // The union's mass properties: both boxes, exact.
    core::MassProperties& m = a.massProperties;
    const core::MassProperties& n = b.massProperties;
    const double mass = m.mass + n.mass;
    const Vec3 com = (m.mass * m.centerOfMass + n.mass * n.centerOfMass) / mass;
    auto shifted = [&](const core::MassProperties& p) {
      const Vec3 d = p.centerOfMass - com;
      return core::Mat3(p.inertia + p.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
    };
    m.inertia = shifted(m) + shifted(n);
    m.centerOfMass = com;
    m.mass = mass;
    a.collision.shapes.push_back(b.collision.shapes[0]);
    bodies.push_back(a);
  }
  DropOptions options;
  options.seconds = 4.0;
  const Result<DropReport> report = simulateDrop(bodies, options);
  ASSERT_TRUE(report.ok()) << report.error().message;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_GE(report->bodies[i].restTime, 0.0);
    EXPECT_NEAR(report->bodies[i].finalLowestPoint, 0.0, 2e-3);
    std::printf("body %zu: at rest from %.2f s, lowest point %.2f mm, %.1f mm at worst\n", i,
                report->bodies[i].restTime, 1e3 * report->bodies[i].finalLowestPoint,
                1e3 * report->bodies[i].lowestPoint);
  }
}

TEST(RigidDrop, TheSameDropGivesTheSameReport) {
  const std::vector<RigidBody> bodies = {box({0.2, 0.1, 0.05}),
                                         box({0.1, 0.1, 0.1}, Mat3::Identity(), {0.05, 0.02, 0.3})};
  const Result<DropReport> a = simulateDrop(bodies), b = simulateDrop(bodies);
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t i = 0; i < bodies.size(); ++i)
    EXPECT_EQ(a->bodies[i].finalPose, b->bodies[i].finalPose);
  EXPECT_EQ(a->kineticEnergy, b->kineticEnergy);
}

TEST(RigidDrop, BadBodiesAndOptionsAreErrors) {
  RigidBody body = box({0.1, 0.1, 0.1});
  body.massProperties.mass = 0.0;
  EXPECT_EQ(simulateDrop(std::span(&body, 1)).error().code, ErrorCode::kInvalidArgument);
  body = box({0.1, 0.1, 0.1});
  body.collision.shapes.clear();
  EXPECT_EQ(simulateDrop(std::span(&body, 1)).error().code, ErrorCode::kInvalidArgument);
  body = box({0.1, 0.1, 0.1});
  DropOptions options;
  options.timeStep = 0.0;
  EXPECT_EQ(simulateDrop(std::span(&body, 1), options).error().code, ErrorCode::kInvalidArgument);

  // A box centred at the origin reaches z = -0.05: lowered, it would start in the floor; raised by
  // exactly that, it rests on it.
  options = DropOptions{};
  options.seconds = 0.1;
  options.lift = 0.04;
  const Result<DropReport> below = simulateDrop(std::span(&body, 1), options);
  ASSERT_FALSE(below.ok());
  EXPECT_NE(below.error().message.find("below the floor"), std::string::npos) << below.error().message;
  options.lift = 0.05;
  EXPECT_TRUE(simulateDrop(std::span(&body, 1), options).ok());
  body = box({0.1, 0.1, 0.1}, Mat3::Identity(), Vec3(0, 0, 1.0));
  options.lift = -0.9;  // lowered: what the start's height asks for
  EXPECT_TRUE(simulateDrop(std::span(&body, 1), options).ok());
}

}  // namespace
}  // namespace shapedb::haptics
