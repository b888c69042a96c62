#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::core {

/// What a mesh's connectivity says about it, computed by analyzeTopology. Plain value type.
struct TopologyReport {
  std::size_t vertexCount = 0;  ///< vertices referenced by at least one triangle
  std::size_t unreferencedVertices = 0;
  std::size_t triangleCount = 0;
  std::size_t edgeCount = 0;          ///< undirected edges
  std::size_t boundaryEdges = 0;      ///< edges with exactly one triangle
  std::size_t nonManifoldEdges = 0;   ///< edges with three or more triangles
  std::size_t inconsistentEdges = 0;  ///< two-triangle edges traversed twice in the same direction
  std::size_t components = 0;         ///< connected components (triangles sharing a vertex)

  /// Every edge has exactly two triangles: the surface can enclose a volume.
  bool isClosed() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
  /// Every two-triangle edge is traversed once in each direction.
  bool isConsistentlyOriented() const { return inconsistentEdges == 0; }
  /// V - E + F over referenced vertices (2 per sphere-like closed component).
  long eulerCharacteristic() const {
    return static_cast<long>(vertexCount) - static_cast<long>(edgeCount) + static_cast<long>(triangleCount);
  }
};

/// Counts boundary, non-manifold and inconsistently oriented edges and connected components.
/// Precondition: every index is in range (validateMesh). O(F + V) for meshes whose vertices have
/// bounded degree (half-edges bucketed by vertex); thread-safe (pure function).
TopologyReport analyzeTopology(const TriangleMesh& mesh);

/// The same report by the plain method, one global sort of all half-edges: O(F log F). The oracle
/// that analyzeTopology is tested against.
TopologyReport analyzeTopologyBySorting(const TriangleMesh& mesh);

/// The error a mass-property computation should report for this topology, or Ok when the surface is
/// closed and consistently oriented: "mesh is not closed (14 boundary edges)".
Status requireClosedOriented(const TopologyReport& topology);

/// One closed shell of a surface (a connected component: triangles sharing a vertex) and the volume it
/// encloses, signed by its winding: positive where its triangles face outward (it bounds a solid of its
/// own), negative where they face inward (a cavity: a void inside the solid around it, as in a hollow
/// ball or a sealed tank modelled with its wall's two sides).
struct Shell {
  std::vector<std::uint32_t> triangles;  ///< indices into the mesh's triangles, ascending
  double volume = 0.0;                   ///< signed, in the mesh's units cubed
  /// Wound against the whole surface (the sign of all its shells' volumes summed): a cavity of the solid
  /// around it; else it bounds a solid.
  bool cavity = false;
};

/// The shells of `mesh`, in the order of their first triangle. Precondition: indices in range
/// (validateMesh); the volumes and roles mean what they say only for a closed, consistently oriented
/// surface.
std::vector<Shell> findShells(const TriangleMesh& mesh);

/// How many solids and cavities shells bound (Shell::cavity).
struct ShellCount {
  std::size_t solids = 0;
  std::size_t cavities = 0;
  double largestSolidShare = 1.0;  ///< the largest solid's share of the solids' volume
};
ShellCount countShells(const std::vector<Shell>& shells);

/// What validateMesh tolerates.
struct ValidationOptions {
  /// Keep going past degenerate faces (repeated vertex or zero area); they are still counted.
  bool allowDegenerateFaces = false;
};

/// Per-mesh counts of the defects validateMesh looks for.
/// Each count comes with its first offender, so that an error can point at it.
struct MeshDefects {
  std::size_t vertexCount = 0;
  std::size_t triangleCount = 0;
  std::size_t nonFiniteVertices = 0;
  std::size_t outOfRangeIndices = 0;    ///< faces with at least one index ≥ vertexCount
  std::size_t repeatedVertexFaces = 0;  ///< faces such as (a, a, b)
  std::size_t zeroAreaFaces = 0;        ///< distinct vertices, but collinear or coincident
  std::size_t firstNonFiniteVertex = 0;
  std::size_t firstOutOfRangeFace = 0;
  std::uint32_t firstOutOfRangeIndex = 0;  ///< the offending index in that face
  std::size_t firstDegenerateFace = 0;     ///< first repeated-vertex or zero-area face
  bool firstDegenerateIsRepeated = false;
};

/// Counts the defects of a mesh in one pass over its vertices and faces. Never fails; out-of-range
/// faces are skipped by the degeneracy tests.
MeshDefects findDefects(const TriangleMesh& mesh);

/// The error validateMesh reports for these defects, or Ok.
Status checkDefects(const MeshDefects& defects, const ValidationOptions& options = {});

/// Checks that a mesh can be processed: vertices and faces present, all coordinates finite, all
/// indices in range, no degenerate face (unless allowed). The error names the first offender:
/// "face 7 refers to vertex 120, but the mesh has 100 vertices". Same as checkDefects(findDefects(mesh)).
Status validateMesh(const TriangleMesh& mesh, const ValidationOptions& options = {});

/// Removes zero-area faces whose corners are distinct and on one line (CAD tessellations and STL exports
/// leave them where a vertex lies on a neighbour's edge: the filler of a T-junction) by flipping the edge
/// each lies along: with m its middle corner and x the far corner of the triangle across its long edge
/// ab, the two become (m, a, x) and (x, b, m). The surface is the same point set, closed and wound as
/// before; only how it is cut into triangles changes. A face is left as it is where the flip would make a
/// zero-area face or an edge the surface has already (a fan of such faces along one edge is flipped away
/// one by one). Returns how many were flipped away. Precondition: closed and consistently oriented
/// (analyzeTopology), indices in range.
std::size_t flipZeroAreaFaces(TriangleMesh& mesh);

/// flipZeroAreaFaces for faces that are only nearly flat: a face whose corner m lies within
/// `relativeHeight` × |ab| of the line of its longest edge ab (a cap: CAD tessellations leave them where a
/// vertex sits just off a neighbour's edge) is flipped as there, under the same conditions, with "zero
/// area" read as "this thin". The vertices stay where they are; the surface moves by at most m's height
/// over ab, and the volume by at most a third of that height times the area of the face across ab, per
/// flip. flipZeroAreaFaces is flipThinFaces with a relative height of 1e-12. Precondition: as there;
/// relativeHeight ≥ 0.
std::size_t flipThinFaces(TriangleMesh& mesh, double relativeHeight);

/// Removes faces with a repeated vertex index (they have no area and no proper edges) and returns how
/// many were removed. Zero-area faces with distinct vertices stay: they may close a T-junction.
std::size_t removeRepeatedVertexFaces(TriangleMesh& mesh);

}  // namespace shapedb::core
