#pragma once

// Surface simplification for meshes that come out of voxels (fracture fragments): marching-cubes-like
// meshes hold tens of thousands of triangles, some edges a thousandth of a voxel long, which TetGen
// refines into hundreds of thousands of tets or fails on. Quadric edge collapses (OpenMesh's decimater)
// bring them down to what physics needs, within a stated distance of the input.

#include <cstddef>
#include <optional>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

struct SimplifyOptions {
  std::size_t maxTriangles = 4000;  ///< stop at this many triangles (or when no collapse is allowed)
  /// No collapse may leave a vertex further than about this from the planes of the triangles it
  /// replaced (the square root of the quadric error), metres. > 0.
  double maxError = 1e-3;
  double maxNormalDeviationDegrees = 45.0;  ///< no collapse turns a triangle's normal more than this
  double maxAspectRatio = 10.0;  ///< no collapse makes a triangle thinner than this (edge / height)
};

/// Collapses edges of a closed, manifold, consistently oriented surface, cheapest quadric error first,
/// under the constraints above; the result stays closed, manifold and oriented (OpenMesh refuses
/// collapses that break the link condition, and the result is checked). A mesh already at or under
/// maxTriangles comes back unchanged. Errors: kInvalidArgument (options), the topology errors of
/// requireClosedOriented (input, or output, which would be a bug). Thread-safe.
Result<core::TriangleMesh> simplify(const core::TriangleMesh& mesh, const SimplifyOptions& options = {});

/// The surface an object from outside (`add`, `enrich`) is computed on: simplified to maxTriangles, no
/// vertex further than 1e-3 of the object's size ∛V from its surface, when it has more (0: never).
/// TetGen keeps every input triangle, so a fine scan would only multiply the tets, and the seconds of
/// their modes, without changing what they give. None when `mesh` is to be meshed as given (no copy of it
/// is made). Errors: those of the mass properties and of simplify.
Result<std::optional<core::TriangleMesh>> surfaceForEntry(const core::TriangleMesh& mesh,
                                                          std::size_t maxTriangles);

}  // namespace shapedb::volume
