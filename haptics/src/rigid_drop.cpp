#include <algorithm>
#include <btBulletDynamicsCommon.h>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Eigenvalues>

#include <shapedb/haptics/rigid_drop.h>

namespace shapedb::haptics {
namespace {

constexpr double kGravity = 9.81;

btVector3 toBt(const core::Vec3& v) {
  return {static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()), static_cast<btScalar>(v.z())};
}

btMatrix3x3 toBt(const core::Mat3& m) {
  return {static_cast<btScalar>(m(0, 0)), static_cast<btScalar>(m(0, 1)), static_cast<btScalar>(m(0, 2)),
          static_cast<btScalar>(m(1, 0)), static_cast<btScalar>(m(1, 1)), static_cast<btScalar>(m(1, 2)),
          static_cast<btScalar>(m(2, 0)), static_cast<btScalar>(m(2, 1)), static_cast<btScalar>(m(2, 2))};
}

core::Vec3 fromBt(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}

core::Mat4 fromBt(const btTransform& t) {
  core::Mat4 m = core::Mat4::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      m(r, c) = t.getBasis()[r][c];
    m(r, 3) = t.getOrigin()[r];
  }
  return m;
}

}  // namespace

double lowestPoint(const core::CollisionShape& s, const core::Mat4& pose) {
  const core::Mat3 r = pose.topLeftCorner<3, 3>();
  const core::Vec3 center = r * s.center + pose.topRightCorner<3, 1>();
  const core::Mat3 axes = r * s.rotation;
  switch (s.type) {
    case core::CollisionShape::Type::kSphere:
      return center.z() - s.radius;
    case core::CollisionShape::Type::kBox:
      return center.z() - (axes.row(2).cwiseAbs().transpose().cwiseProduct(s.halfExtents)).sum();
    case core::CollisionShape::Type::kCapsule:
      return center.z() - std::abs(axes(2, 2)) * s.halfLength - s.radius;
  }
  return center.z();
}

namespace {

/// A body's frame: its centre of mass and principal axes (right-handed), and the principal moments.
struct PrincipalFrame {
  core::Mat3 axes;
  core::Vec3 moments;
};

PrincipalFrame principalFrame(const core::Mat3& inertia) {
  const Eigen::SelfAdjointEigenSolver<core::Mat3> solver(inertia);
  PrincipalFrame f{solver.eigenvectors(), solver.eigenvalues()};
  if (f.axes.determinant() < 0.0) f.axes.col(2) *= -1.0;
  return f;
}

Status validate(std::span<const RigidBody> bodies, const DropOptions& o) {
  const bool optionsOk = std::isfinite(o.lift) && o.seconds > 0.0 && o.seconds <= 3600.0 &&
                         o.timeStep > 0.0 && o.timeStep <= 0.1 && o.friction >= 0.0 && o.restitution >= 0.0 &&
                         o.restitution <= 1.0 && o.restSpeed > 0.0 && o.restSpin > 0.0 && o.restHold >= 0.0;
  if (!optionsOk) return Error{ErrorCode::kInvalidArgument, "drop options out of range"};
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const RigidBody& b = bodies[i];
    const std::string which = "body " + std::to_string(i) + ": ";
    if (!(b.massProperties.mass > 0.0) || !std::isfinite(b.massProperties.mass))
      return Error{ErrorCode::kInvalidArgument, which + "mass must be positive"};
    if (!b.massProperties.inertia.allFinite() || !b.massProperties.centerOfMass.allFinite() ||
        !(principalFrame(b.massProperties.inertia).moments.minCoeff() > 0.0))
      return Error{ErrorCode::kInvalidArgument, which + "inertia must be finite and positive definite"};
    if (b.collision.shapes.empty()) return Error{ErrorCode::kInvalidArgument, which + "no collision shapes"};
    core::Mat4 lifted = core::Mat4::Identity();
    lifted(2, 3) = o.lift;
    for (const core::CollisionShape& shape : b.collision.shapes)
      if (const double z = lowestPoint(shape, lifted); z < -1e-9)
        return Error{ErrorCode::kInvalidArgument,
                     which + "starts below the floor (its lowest point at z = " + std::to_string(z) + " m)"};
  }
  return Ok{};
}

/// Bullet's world and everything it points to, torn down in the right order.
class World {
 public:
  World()
      : mDispatcher(&mConfiguration),
        mWorld(&mDispatcher, &mBroadphase, &mSolver, &mConfiguration),
        mFloorShape(btVector3(0, 0, 1), 0) {
    mWorld.setGravity(btVector3(0, 0, static_cast<btScalar>(-kGravity)));
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, &mFloorShape);
    mFloor = std::make_unique<btRigidBody>(info);
    mWorld.addRigidBody(mFloor.get());
  }
  ~World() {
    for (auto& body : mBodies)
      mWorld.removeRigidBody(body.get());
    mWorld.removeRigidBody(mFloor.get());
  }
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  void setFloorContact(double friction, double restitution) {
    mFloor->setFriction(static_cast<btScalar>(friction));
    mFloor->setRestitution(static_cast<btScalar>(restitution));
  }

  /// Adds one body: its compound built in its principal frame, placed at `start` (world from body).
  btRigidBody* add(const RigidBody& body, const PrincipalFrame& frame, const btTransform& start,
                   const DropOptions& o) {
    auto compound = std::make_unique<btCompoundShape>();
    const core::Vec3& com = body.massProperties.centerOfMass;
    for (const core::CollisionShape& s : body.collision.shapes) {
      std::unique_ptr<btCollisionShape> child;
      switch (s.type) {
        case core::CollisionShape::Type::kSphere:
          child = std::make_unique<btSphereShape>(static_cast<btScalar>(s.radius));
          break;
        case core::CollisionShape::Type::kBox: {
          auto box = std::make_unique<btBoxShape>(toBt(s.halfExtents));
          // Bullet rounds a box's edges by its margin (0.04 m by default): keep it small beside the box.
          box->setMargin(static_cast<btScalar>(std::min(0.004, 0.1 * s.halfExtents.minCoeff())));
          child = std::move(box);
          break;
        }
        case core::CollisionShape::Type::kCapsule:
          child = std::make_unique<btCapsuleShapeZ>(static_cast<btScalar>(s.radius),
                                                    static_cast<btScalar>(2.0 * s.halfLength));
          break;
      }
      const btTransform local(toBt(core::Mat3(frame.axes.transpose() * s.rotation)),
                              toBt(core::Vec3(frame.axes.transpose() * (s.center - com))));
      compound->addChildShape(local, child.get());
      mChildren.push_back(std::move(child));
    }
    const btVector3 inertia = toBt(frame.moments);
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(body.massProperties.mass), nullptr,
                                                  compound.get(), inertia);
    info.m_startWorldTransform = start;
    info.m_friction = static_cast<btScalar>(o.friction);
    info.m_restitution = static_cast<btScalar>(o.restitution);
    auto rigid = std::make_unique<btRigidBody>(info);
    mWorld.addRigidBody(rigid.get());
    mShapes.push_back(std::move(compound));
    mBodies.push_back(std::move(rigid));
    return mBodies.back().get();
  }

  void step(double dt) { mWorld.stepSimulation(static_cast<btScalar>(dt), 1, static_cast<btScalar>(dt)); }

 private:
  btDefaultCollisionConfiguration mConfiguration;
  btCollisionDispatcher mDispatcher;
  btDbvtBroadphase mBroadphase;
  btSequentialImpulseConstraintSolver mSolver;
  btDiscreteDynamicsWorld mWorld;
  btStaticPlaneShape mFloorShape;
  std::unique_ptr<btRigidBody> mFloor;
  std::vector<std::unique_ptr<btCollisionShape>> mChildren;
  std::vector<std::unique_ptr<btCompoundShape>> mShapes;
  std::vector<std::unique_ptr<btRigidBody>> mBodies;
};

}  // namespace

Result<DropReport> simulateDrop(std::span<const RigidBody> bodies, const DropOptions& options) {
  if (Status valid = validate(bodies, options); !valid) return valid.error();
  World world;
  world.setFloorContact(options.friction, options.restitution);
  std::vector<btRigidBody*> rigid;
  std::vector<PrincipalFrame> frames;
  std::vector<core::Mat4> startInverse;  // body from world at the start, lift included
  for (const RigidBody& b : bodies) {
    const PrincipalFrame frame = principalFrame(b.massProperties.inertia);
    const core::Vec3 origin = b.massProperties.centerOfMass + core::Vec3(0.0, 0.0, options.lift);
    rigid.push_back(world.add(b, frame, btTransform(toBt(frame.axes), toBt(origin)), options));
    core::Mat4 bodyFromWorld = core::Mat4::Identity();
    bodyFromWorld.topLeftCorner<3, 3>() = frame.axes.transpose();
    bodyFromWorld.topRightCorner<3, 1>() = -frame.axes.transpose() * b.massProperties.centerOfMass;
    startInverse.push_back(bodyFromWorld);
    frames.push_back(frame);
  }

  DropReport report;
  report.bodies.resize(bodies.size());
  std::vector<double> calmSince(bodies.size(), -1.0);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    report.bodies[i].lowestPoint = std::numeric_limits<double>::infinity();
  }
  const auto steps = static_cast<std::size_t>(std::ceil(options.seconds / options.timeStep));
  for (std::size_t step = 1; step <= steps; ++step) {
    world.step(options.timeStep);
    const double t = static_cast<double>(step) * options.timeStep;
    double kinetic = 0.0, potential = 0.0;
    const bool record = options.recordEvery > 0 && (step % options.recordEvery == 0 || step == steps);
    if (record) report.frames.emplace_back();
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const btTransform& transform = rigid[i]->getWorldTransform();
      const core::Mat4 pose = fromBt(transform) * startInverse[i];
      BodyOutcome& outcome = report.bodies[i];
      outcome.finalPose = pose;
      outcome.finalLowestPoint = std::numeric_limits<double>::infinity();
      for (const core::CollisionShape& s : bodies[i].collision.shapes)
        outcome.finalLowestPoint = std::min(outcome.finalLowestPoint, lowestPoint(s, pose));
      outcome.lowestPoint = std::min(outcome.lowestPoint, outcome.finalLowestPoint);
      const core::Vec3 v = fromBt(rigid[i]->getLinearVelocity());
      const core::Vec3 w = fromBt(rigid[i]->getAngularVelocity());
      const double mass = bodies[i].massProperties.mass;
      const core::Mat3 axes = pose.topLeftCorner<3, 3>() * frames[i].axes;
      const core::Vec3 wBody = axes.transpose() * w;
      kinetic += 0.5 * mass * v.squaredNorm() + 0.5 * wBody.dot(frames[i].moments.cwiseProduct(wBody));
      potential += mass * kGravity * transform.getOrigin().z();
      const bool calm = v.norm() < options.restSpeed && w.norm() < options.restSpin;
      if (!calm) {
        calmSince[i] = -1.0;
        outcome.restTime = -1.0;
      } else if (calmSince[i] < 0.0) {
        calmSince[i] = t;
      }
      if (calm && outcome.restTime < 0.0 && t - calmSince[i] >= options.restHold)
        outcome.restTime = calmSince[i];
      if (record) report.frames.back().push_back(pose);
    }
    report.times.push_back(t);
    report.kineticEnergy.push_back(kinetic);
    report.potentialEnergy.push_back(potential);
  }
  report.atRest = static_cast<std::size_t>(std::count_if(
      report.bodies.begin(), report.bodies.end(), [](const BodyOutcome& b) { return b.restTime >= 0.0; }));
  return report;
}

}  // namespace shapedb::haptics
