#pragma once

// The rigid-body scenario (paper Figure 1): bodies given their mass properties and collision compounds
// (from a database query, say) dropped on a floor in Bullet, stepped at a fixed rate, and summarized:
// where each came to rest and when, the energy over time, how deep anything went into the floor.
// Built only when Bullet (libbullet-dev) is found: SHAPEDB_HAVE_BULLET.

#include <cstddef>
#include <span>
#include <vector>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>

namespace shapedb::haptics {

/// One body as it is at the start, world frame (z up, metres, kilograms).
struct RigidBody {
  core::MassProperties massProperties;  ///< mass, centre of mass, inertia about it (world axes)
  core::CollisionCompound collision;    ///< shapes in the world frame
};

struct DropOptions {
  double lift = 0.3;            ///< every body raised (or, < 0, lowered) by this much (m); the floor is z = 0
  double seconds = 3.0;         ///< simulated time
  double timeStep = 1.0 / 240;  ///< fixed step (s)
  double friction = 0.6;
  double restitution = 0.2;
  /// A body is at rest once its speed stays under restSpeed and its angular speed under restSpin for
  /// restHold seconds; its rest time is when that began.
  double restSpeed = 0.02, restSpin = 0.2, restHold = 0.25;
  std::size_t recordEvery = 0;  ///< > 0: keep every body's pose every this many steps (for frames)
};

struct BodyOutcome {
  core::Mat4 finalPose = core::Mat4::Identity();  ///< world from start: p(t) = pose · p(0)
  double restTime = -1.0;                         ///< s; -1: never at rest
  double lowestPoint = 0.0;       ///< lowest z any of its collision shapes reached (m); < 0: into the floor
  double finalLowestPoint = 0.0;  ///< the same at the end: ~0 for a body resting on the floor
};

struct DropReport {
  std::vector<BodyOutcome> bodies;
  std::vector<double> times;                    ///< s, one per step
  std::vector<double> kineticEnergy;            ///< J, all bodies, per step
  std::vector<double> potentialEnergy;          ///< J, m g z of the centres of mass, per step
  std::vector<std::vector<core::Mat4>> frames;  ///< with recordEvery: poses of every body per record
  std::size_t atRest = 0;                       ///< bodies at rest at the end
};

/// The lowest z of a collision shape moved by `pose` (world from start): exact for each solid.
double lowestPoint(const core::CollisionShape& shape, const core::Mat4& pose = core::Mat4::Identity());

/// Steps the bodies in Bullet's discrete dynamics world with a static floor plane. Each body's frame is
/// its centre of mass and principal axes; its compound's spheres, boxes and capsules are placed in it.
/// Deterministic: the same bodies and options give the same report. Errors: kInvalidArgument for a
/// body without positive mass, finite inertia or shapes, a body below the floor once lifted, or options
/// out of range.
Result<DropReport> simulateDrop(std::span<const RigidBody> bodies, const DropOptions& options = {});

}  // namespace shapedb::haptics
