#pragma once
// Where a closed surface passes through itself: two triangles that cross, as a scan's folded sheet or an
// export of parts that overlap have. Such a surface bounds no solid, and TetGen cannot mesh it (it
// refuses it or crashes on it); this names the triangles, so that the error can.

#include <cstdint>
#include <vector>

#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// Two triangles of one surface that cross: an edge of one passes through the inside of the other.
struct TriangleCrossing {
  std::uint32_t first = 0, second = 0;  ///< triangle indices, first < second
  Vec3 point = Vec3::Zero();            ///< where an edge of one crosses the other
};

/// Every pair of triangles of `surface` that cross, sorted by (first, second). Triangles that share an
/// edge are never a pair; triangles that share a corner are one if the edge opposite it, in one of them,
/// crosses the other. Only clear crossings count: an edge whose ends lie on the two sides of the other
/// triangle's plane by more than a billionth of the surface's size, through the triangle's inside by a
/// billionth of its barycentric range. Touching, grazing and coplanar overlaps are not reported. A
/// ClosestPointTree finds the candidate pairs (their boxes meet); parallel (TBB).
std::vector<TriangleCrossing> findSelfIntersections(const TriangleMesh& surface);

/// The oracle of findSelfIntersections: every pair of triangles tried.
std::vector<TriangleCrossing> findSelfIntersectionsBruteForce(const TriangleMesh& surface);

}  // namespace shapedb::core
