#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include <shapedb/haptics/contact.h>

namespace shapedb::haptics {

using core::CollisionShape;
using core::Vec3;

namespace {

/// Distance to a solid made of the points within `radius` of `axisPoint`, the closest point of a core
/// (centre or segment) to p. `fallback`: the normal when p is on the core.
SurfaceDistance roundedDistance(const Vec3& p, const Vec3& axisPoint, double radius, const Vec3& fallback) {
  const Vec3 d = p - axisPoint;
  const double length = d.norm();
  SurfaceDistance out;
  out.normal = length > 0.0 ? Vec3(d / length) : fallback;
  out.distance = length - radius;
  out.point = axisPoint + radius * out.normal;
  return out;
}

SurfaceDistance boxDistance(const CollisionShape& box, const Vec3& p) {
  const Vec3 local = box.rotation.transpose() * (p - box.center);
  const Vec3 q = local.cwiseAbs() - box.halfExtents;
  SurfaceDistance out;
  if ((q.array() > 0.0).any()) {
    const Vec3 clamped = local.cwiseMax(-box.halfExtents).cwiseMin(box.halfExtents);
    const Vec3 away = local - clamped;
    out.distance = away.norm();
    out.normal = box.rotation * (away / out.distance);
    out.point = box.center + box.rotation * clamped;
    return out;
  }
  // Inside: the nearest face.
  int axis = 0;
  q.maxCoeff(&axis);
  Vec3 localNormal = Vec3::Zero();
  localNormal[axis] = local[axis] < 0.0 ? -1.0 : 1.0;
  Vec3 onFace = local;
  onFace[axis] = localNormal[axis] * box.halfExtents[axis];
  out.distance = q[axis];
  out.normal = box.rotation * localNormal;
  out.point = box.center + box.rotation * onFace;
  return out;
}

}  // namespace

SurfaceDistance signedDistance(const CollisionShape& shape, const Vec3& p) {
  switch (shape.type) {
    case CollisionShape::Type::kSphere:
      return roundedDistance(p, shape.center, shape.radius, Vec3::UnitZ());
    case CollisionShape::Type::kBox:
      return boxDistance(shape, p);
    case CollisionShape::Type::kCapsule: {
      const Vec3 axis = shape.rotation.col(2);
      const double t = std::clamp(axis.dot(p - shape.center), -shape.halfLength, shape.halfLength);
      // On the axis itself the normal is undetermined: take the capsule's local x.
      return roundedDistance(p, shape.center + t * axis, shape.radius, shape.rotation.col(0));
    }
  }
  return {};
}

SurfaceDistance signedDistance(std::span<const CollisionShape> shapes, const Vec3& p) {
  assert(!shapes.empty());
  SurfaceDistance best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const CollisionShape& shape : shapes) {
    const SurfaceDistance d = signedDistance(shape, p);
    if (d.distance < best.distance) best = d;
  }
  return best;
}

double boundingRadius(std::span<const CollisionShape> shapes, const Vec3& center) {
  double radius = 0.0;
  for (const CollisionShape& shape : shapes) {
    const double offset = (shape.center - center).norm();
    double extent = shape.radius;
    if (shape.type == CollisionShape::Type::kBox) extent = shape.halfExtents.norm();
    if (shape.type == CollisionShape::Type::kCapsule) extent = shape.halfLength + shape.radius;
    radius = std::max(radius, offset + extent);
  }
  return radius;
}

}  // namespace shapedb::haptics
