#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <shapedb/core/types.h>

namespace shapedb::core {

/// An indexed triangle mesh: the surface every stage of shapedb starts from.
/// Plain value type (copyable, movable); no invariant is enforced on construction, so loaders and
/// generators validate it (validateMesh, analyzeTopology) before later stages rely on it.
struct TriangleMesh {
  using Triangle = std::array<std::uint32_t, 3>;

  std::vector<Vec3> vertices;       ///< m, in the mesh's own frame
  std::vector<Triangle> triangles;  ///< indices into vertices, counter-clockwise seen from outside

  std::size_t vertexCount() const { return vertices.size(); }
  std::size_t triangleCount() const { return triangles.size(); }
};

/// Axis-aligned bounding box of a set of points.
struct Bounds {
  Vec3 min = Vec3::Constant(0.0);  ///< m
  Vec3 max = Vec3::Constant(0.0);  ///< m
  Vec3 extent() const { return max - min; }
  Vec3 center() const { return 0.5 * (min + max); }
};

/// Bounding box of the mesh's vertices; all zero for a mesh without vertices.
Bounds computeBounds(const TriangleMesh& mesh);

/// Total surface area, m². Degenerate triangles contribute zero.
double computeSurfaceArea(const TriangleMesh& mesh);

/// Signed volume enclosed by a closed surface (divergence theorem), m³: positive when it is wound outward.
/// Summed about the first vertex, so that a mesh far from the origin loses no digits (about the origin, a
/// mesh 10⁶ m away has none left). Meaningless for an open surface; 0 for a mesh without vertices.
double computeSignedVolume(const TriangleMesh& mesh);

/// The mesh with every vertex mapped through dstFromSrc (a 4x4 affine transform). When the
/// transform's linear part has a negative determinant, every triangle is reversed so the surface
/// keeps facing outward.
TriangleMesh transformed(const TriangleMesh& mesh, const Mat4& dstFromSrc);

/// `part`'s vertices and triangles added to `into` (its indices shifted past into's vertices): one mesh
/// of several surfaces, nothing welded.
void append(TriangleMesh& into, const TriangleMesh& part);

/// Drops the vertices no triangle uses; the others keep their order and positions, and the triangles
/// are renumbered to match. Returns how many were dropped. Precondition: indices in range.
std::size_t removeUnusedVertices(TriangleMesh& mesh);

/// Drops the triangles whose flag in `dropped` (one per triangle) is set, and then the vertices only they
/// used (removeUnusedVertices); the rest keep their order. A surface's shells taken out (specks, crumbs).
void removeTriangles(TriangleMesh& mesh, const std::vector<bool>& dropped);

/// The mesh with every triangle's winding reversed (an inside-out mesh turned right side out).
TriangleMesh flipped(const TriangleMesh& mesh);

/// Each triangle split into four at its edge midpoints (midpoints shared between neighbours), so a
/// closed mesh stays closed. Positions are not moved: the surface is the same, only finer.
TriangleMesh subdivideMidpoint(const TriangleMesh& mesh);

}  // namespace shapedb::core
