#pragma once

// Procedural fracture (the paper's main scenario, Figures 1, 8, 9): a closed surface broken into
// fragments with OpenVDB level sets. The solid becomes a narrow-band level set; random seed points inside
// it define Voronoi cells, each cell becomes a level-set cutter intersected with the solid (the CSG and
// segmentation of tools::LevelSetFracture, cell by cell and in parallel; pieces a cell splits in two, on a
// non-convex solid, become separate fragments). Each fragment is meshed back at its zero crossing and
// simplified to what physics needs.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

struct FractureOptions {
  int pieces = 20;         ///< Voronoi seeds (1 to 1,000); the fragment count can differ (see below)
  std::uint64_t seed = 1;  ///< the same seed and mesh give the same fragments, to the bit
  int resolution = 128;    ///< voxels along the mesh's longest side (16 to 1,024)
  /// Fragments smaller than this fraction of the solid's volume (voxel-scale crumbs) are dropped.
  double minVolumeFraction = 1e-4;
  /// Each fragment's mesh is simplified to at most this many triangles (volume::simplify), moving its
  /// surface by at most simplifyError voxels; 0 keeps the raw level-set mesh, which holds tens of
  /// thousands of triangles and edges a thousandth of a voxel long (TetGen refines such a mesh into
  /// hundreds of thousands of tets, or fails on it).
  std::size_t maxTriangles = 3000;
  double simplifyError = 0.25;
};

struct FractureResult {
  std::vector<core::TriangleMesh> fragments;  ///< closed, outward-oriented, in the mesh's frame; by size
  double voxelSize = 0.0;                     ///< the level sets' resolution (m): the fragments' detail
  std::size_t crumbsDropped = 0;              ///< fragments under minVolumeFraction
  std::size_t openDropped = 0;                ///< fragments whose meshing did not close (should be none)
};

/// Errors: kInvalidArgument for options out of range; validateMesh's; kNotClosed (and the other
/// topology errors) for a mesh that does not enclose a volume.
Result<FractureResult> fracture(const core::TriangleMesh& mesh, const FractureOptions& options = {});

}  // namespace shapedb::volume
