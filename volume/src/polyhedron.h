#pragma once

// Convex polyhedra as lists of polygons, cut by half-spaces: the shard family and the cells of fracture.
// Internal to volume.

#include <span>
#include <vector>

#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::volume::detail {

/// A convex polygon face of a polyhedron, counter-clockwise seen from outside.
using Polygon = std::vector<core::Vec3>;

/// The six faces of the box [lo, hi], as quads.
std::vector<Polygon> boxFaces(const core::Vec3& lo, const core::Vec3& hi);

/// Cuts a convex polyhedron by the half-space n·x ≤ d, closing the cut with a new face.
std::vector<Polygon> clip(const std::vector<Polygon>& faces, const core::Vec3& n, double d);

/// The Voronoi cell of seeds[i] within the convex polyhedron `solid`: `solid` cut by the bisector plane
/// to every other seed. A repeated seed's cell goes to its first occurrence (the others are empty).
/// Empty when the cell misses the solid.
std::vector<Polygon> voronoiCell(std::vector<Polygon> solid, std::span<const core::Vec3> seeds,
                                 std::size_t i);

/// Polygons → triangle mesh with shared vertices (welded on a 2⁻³⁰ lattice) and fan triangles.
core::TriangleMesh triangulate(const std::vector<Polygon>& faces);

}  // namespace shapedb::volume::detail
