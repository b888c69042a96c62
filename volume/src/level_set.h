#pragma once

// Closed surfaces through OpenVDB level sets: a triangle mesh to a narrow-band signed distance grid, and a
// grid's zero crossing back to a closed, simplified triangle mesh. Shared by fracture and the families
// built by constructive solid geometry. Internal to volume (it names OpenVDB types).

#include <cstddef>
#include <utility>
#include <vector>

#include <openvdb/openvdb.h>

#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume::detail {

/// Narrow band half-width, voxels, of every level set made here.
inline constexpr float kLevelSetHalfWidth = 3.0f;

/// A triangle mesh as OpenVDB's mesh tools take it: single-precision points (the caller keeps them near
/// the origin of a local frame) and index triples.
struct OpenVdbMesh {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
};
OpenVdbMesh toOpenVdb(const core::TriangleMesh& mesh);

/// The level set of a closed, outward-wound surface in `transform`'s voxels (its points go through
/// single precision: the caller keeps them near the origin of a local frame). A surface of several
/// shells is the union of its solids less its cavities (shells wound inward), each made on its own.
openvdb::FloatGrid::Ptr levelSet(const core::TriangleMesh& mesh, const openvdb::math::Transform& transform);

/// How a surface came out of its level set.
enum class Meshing {
  kClosed,    ///< the zero crossing is a closed manifold
  kRemeshed,  ///< a crossing a hundredth to a tenth of a voxel off zero is
  kOpen       ///< none of them is (never seen; the zero crossing is returned)
};

/// What closedSurface simplifies to: at most maxTriangles (0 keeps the raw crossing), within
/// simplifyError voxels of it.
struct SurfaceOptions {
  std::size_t maxTriangles = 3000;
  double simplifyError = 0.25;
  /// Refuse a simplification that makes the surface pass through itself (two sheets of a thin wall folded
  /// together; a level set's crossing never does): the crossing then stands, unsimplified. The repair's
  /// (one surface); not fracture's, which meshes hundreds of fragments at once and would pay the
  /// self-intersection search for each.
  bool uncrossed = false;
};

/// The grid's zero crossing as an outward-wound triangle mesh, closed where it can be, then simplified.
/// Marching cubes can leave a non-manifold edge or vertex where two sheets of the level set touch within a
/// voxel (a thin wall, a cut grazing a surface); a crossing slightly inside or outside the zero level
/// separates them, so those are tried next. Empty when the grid holds no surface.
std::pair<core::TriangleMesh, Meshing> closedSurface(const openvdb::FloatGrid& grid, double voxelSize,
                                                     const SurfaceOptions& options);

/// Closed, manifold, consistently oriented, and free of the defects validateMesh refuses.
bool isClosedSolid(const core::TriangleMesh& mesh);

}  // namespace shapedb::volume::detail
