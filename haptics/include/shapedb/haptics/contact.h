#pragma once

// The proxy against a collision compound: signed distances to spheres, boxes and capsules. Allocation-free,
// for the haptic tick.

#include <span>

#include <shapedb/core/physics.h>
#include <shapedb/core/types.h>

namespace shapedb::haptics {

/// The signed distance from a point to a solid's surface (negative inside), the surface point closest to
/// it, and the outward normal there: point = p − distance · normal.
struct SurfaceDistance {
  double distance = 0.0;
  core::Vec3 point = core::Vec3::Zero();
  core::Vec3 normal = core::Vec3::UnitZ();
};

/// Exact for each solid. A point at a sphere's centre or on a capsule's axis has no unique closest
/// point; the normal is then world +z (sphere) or the capsule's local x.
SurfaceDistance signedDistance(const core::CollisionShape& shape, const core::Vec3& p);

/// The union of the shapes: the smallest of their signed distances (exact outside the union; inside it,
/// the distance to the surface of the solid that holds the point most deeply). Precondition: not empty.
SurfaceDistance signedDistance(std::span<const core::CollisionShape> shapes, const core::Vec3& p);

/// The radius of a sphere about `center` that holds every shape.
double boundingRadius(std::span<const core::CollisionShape> shapes, const core::Vec3& center);

}  // namespace shapedb::haptics
