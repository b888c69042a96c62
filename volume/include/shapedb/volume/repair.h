#pragma once
// Surfaces that are not closed solids made into closed ones: open (holes, a missing cap), non-manifold or
// self-intersecting surfaces, as scans and game assets come. The surface becomes an unsigned distance
// field; everything within the closing radius of it, or shut in by it, is solid; that solid's boundary
// moved back in by the closing radius (a morphological closing, so holes up to about twice the radius
// across are shut and the rest of the surface stays where it was) is meshed at its zero crossing and
// simplified. Implemented beside the other OpenVDB level sets, in src/level_set.cpp.

#include <cstddef>
#include <optional>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

struct RepairOptions {
  /// Voxels along the largest side of the mesh's bounding box, 16 to 1,024.
  int resolution = 128;
  /// Holes wider than this fraction of the largest side are refused: closing them would round off
  /// every concave part of the surface as much.
  double maxHoleFraction = 0.1;
  /// The repaired surface is simplified to at most this many triangles (within a quarter voxel), unless the
  /// simplification would make it pass through itself (two sheets of a thin wall folded together): then it
  /// is the level set's crossing, unsimplified.
  std::size_t maxTriangles = 20000;
};

/// What the repair did, in the mesh's units.
struct RepairReport {
  int resolution = 0;
  double voxelSize = 0.0;
  std::size_t holes = 0;       ///< boundary loops of the input (0 for a closed, if non-manifold, surface)
  double closingRadius = 0.0;  ///< 1.5 voxels, or half the widest hole and a voxel
  /// The input's enclosed volume where it is a closed, consistently oriented surface.
  std::optional<double> volumeBefore;
  double volumeAfter = 0.0;
  double areaBefore = 0.0, areaAfter = 0.0;
  std::size_t trianglesBefore = 0, trianglesAfter = 0;
};

struct RepairedSurface {
  core::TriangleMesh mesh;  ///< closed, manifold, wound outward, not passing through itself
  RepairReport report;
};

/// Repairs `mesh` as described above. Thread-safe. Errors: kEmptyMesh; kInvalidArgument (options; a
/// hole wider than maxHoleFraction of the mesh: the message says how wide); kNonFinite; kParse when no
/// closed surface came out (a surface with nothing to enclose: a single sheet much wider than its holes
/// are bounded).
Result<RepairedSurface> repairSurface(const core::TriangleMesh& mesh, const RepairOptions& options = {});

}  // namespace shapedb::volume
