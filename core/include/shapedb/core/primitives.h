#pragma once

#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// Closed, outward-oriented triangle meshes of simple solids, centred at the origin unless stated.
/// The building blocks of the shape families and of analytic tests. Sizes in metres.

/// The tetrahedron (a, b, c, d), wound outward whatever the order of the points.
/// Precondition: the points are not coplanar.
TriangleMesh makeTetrahedron(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Box of side lengths size.x() × size.y() × size.z(), 12 triangles.
TriangleMesh makeBox(const Vec3& size);

/// Ellipsoid with semi-axes `radii` as a latitude-longitude mesh: `slices` ≥ 3 around z, `stacks` ≥ 2
/// from pole to pole. radii = (r, r, r) gives a sphere.
TriangleMesh makeUvEllipsoid(const Vec3& radii, int slices, int stacks);

/// Sphere of the given radius from an icosahedron subdivided `subdivisions` times, vertices projected
/// to the sphere: 20·4^subdivisions near-uniform triangles.
TriangleMesh makeIcosphere(double radius, int subdivisions);

/// Circular cylinder along z, `segments` ≥ 3 around, capped by triangle fans about the cap centres.
TriangleMesh makeCylinder(double radius, double height, int segments);

/// Circular cone along z, `segments` ≥ 3 around: base of the given radius at z = −height/2, apex at
/// z = +height/2 (the bounding box is centred, the centre of mass is not).
TriangleMesh makeCone(double radius, double height, int segments);

/// Capsule along z: a cylinder of the given radius whose axis segment has length `length` ≥ 0, closed
/// by two hemispheres of `capStacks` ≥ 1 rings each; `segments` ≥ 3 around.
TriangleMesh makeCapsule(double radius, double length, int segments, int capStacks);

/// Right prism along z of length `length` over the isosceles triangle of base `base` (along x) and
/// height `height` (along y), the triangle's bounding box centred on the axis. 8 triangles.
TriangleMesh makeTriangularPrism(double base, double height, double length);

}  // namespace shapedb::core
