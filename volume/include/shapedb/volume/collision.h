#pragma once

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

/// How a collision compound is fitted.
struct CollisionOptions {
  int maxShapes = 8;             ///< at most this many spheres, boxes and capsules, ≥ 1
  double targetCoverage = 0.95;  ///< stop adding shapes once this fraction of the volume is covered
  int resolution = 32;           ///< voxels along the largest extent of the sampling grid, 8–128
  /// A voxel the compound covers outside the solid costs this many covered voxels inside it: the larger,
  /// the more the fit stays inside the surface (a collision shape that overshoots makes objects float).
  double overshootPenalty = 2.0;
};

/// Fits a compound of spheres, boxes and capsules to the solid bounded by `surface` (closed, outward
/// oriented), greedily: the solid is sampled on a voxel grid with its signed distance (OpenVDB); each
/// round grows candidates from the deepest voxel not yet covered (the inscribed sphere there; the box
/// grown face by face while each new layer stays inside; capsules along x, y and z extended while their
/// end spheres stay inside) and keeps the one that covers the most new volume net of its overshoot.
/// Boxes and capsules are aligned with the mesh's axes: fit in the canonical frame, where those are the
/// principal axes. Reports coverage and overshoot measured on the same grid. Deterministic.
/// Errors: kInvalidArgument (options), kEmptyMesh / kZeroVolume (nothing inside at this resolution).
Result<core::CollisionCompound> fitCollisionCompound(const core::TriangleMesh& surface,
                                                     const CollisionOptions& options = {});

}  // namespace shapedb::volume
