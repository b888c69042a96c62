#pragma once

// Welding: coincident vertices merged into one, so that a triangle soup (every triangle with its own
// three corners, as many STL and game exports are) or a mesh split along texture seams becomes the
// connected surface it describes.

#include <cstddef>

#include <shapedb/core/triangle_mesh.h>

namespace shapedb::core {

struct WeldReport {
  std::size_t verticesMerged = 0;  ///< vertices that became another one
  std::size_t facesCollapsed = 0;  ///< triangles left with a repeated corner, removed
};

/// Merges every vertex into the first earlier kept vertex within `tolerance` (m; 0 merges only exactly
/// equal positions), in vertex order, so the result does not depend on hashing; removes the triangles
/// that this leaves with a repeated corner, and the vertices no triangle uses. Kept vertices keep their
/// order and positions. Expected O(V + F) (a hash grid of cell `tolerance`), for tolerances under the
/// mesh's edge lengths. Precondition: indices in range and coordinates finite (validateMesh); a tolerance
/// that is not finite and positive welds exact equals only.
WeldReport weldVertices(TriangleMesh& mesh, double tolerance = 0.0);

/// The same by the plain method, every vertex against every kept one: O(V²). The oracle of weldVertices.
WeldReport weldVerticesBruteForce(TriangleMesh& mesh, double tolerance = 0.0);

}  // namespace shapedb::core
