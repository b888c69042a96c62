#pragma once

// Procedural fracture (the paper's main scenario, Figures 1, 8, 9): a closed surface broken into
// fragments with OpenVDB level sets. The solid becomes a narrow-band level set; random seed points inside
// it define Voronoi cells, each cell becomes a level-set cutter intersected with the solid (the CSG and
// segmentation of tools::LevelSetFracture, cell by cell and in parallel; pieces a cell splits in two, on a
// non-convex solid, become separate fragments). Each fragment is meshed back at its zero crossing and
// simplified to what physics needs. The work happens in a frame centred on the mesh (in double precision
// up to OpenVDB's floats), so a mesh far from the origin breaks as it would at the origin.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

struct FractureOptions {
  int pieces = 20;         ///< Voronoi seeds (1 to 1,000); the fragment count can differ (see below)
  std::uint64_t seed = 1;  ///< the same seed and mesh give the same fragments, to the bit
  /// Voxels along the mesh's longest side (16 to 1,024), or 0 for automaticResolution's choice.
  int resolution = 0;
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
  int resolution = 0;                         ///< voxels along the mesh's longest side (as given or chosen)
  double solidVolume = 0.0;                   ///< the mesh's enclosed volume (m³)
  double keptVolume = 0.0;                    ///< the fragments' total volume (m³)
  double droppedVolume = 0.0;                 ///< the dropped pieces' total volume (m³)
  /// Pieces under minVolumeFraction: fragments, and specks the level set closed apart from a fragment
  /// (a shell of their own beside it, where the solid is a voxel thin), which are dropped from it.
  std::size_t crumbsDropped = 0;
  /// Fragments whose zero crossing was not a closed manifold surface and that were meshed again a
  /// hundredth of a voxel (or a few) off the zero level, where it was.
  std::size_t remeshed = 0;
  /// Fragments with no closed surface near the zero level either (none seen on real meshes; reported,
  /// never passed on as solids).
  std::size_t openDropped = 0;

  /// keptVolume / solidVolume: below 1 by the crumbs and by the level sets' rounding of every cut edge
  /// (a voxel's fraction per edge, so it falls as the pieces grow and rises with the resolution).
  double keptFraction() const { return solidVolume > 0.0 ? keptVolume / solidVolume : 0.0; }
};

/// The default resolution: 128 voxels along the longest side, more where the solid or its pieces would
/// be thin in voxels (the level sets chamfer every cut edge and every sharp edge of the solid by about a
/// voxel's fraction, so the volume a fracture keeps falls as a fragment's voxels do): at least 6 voxels
/// across the solid's mean thickness 2V/A and 16 across a fragment's mean size (V/pieces)^(1/3), at most
/// 1,024. A 3 mm tray 356 mm wide gets 672; a bottle in 200 pieces 296; a pebble in 20 pieces 128.
int automaticResolution(const core::TriangleMesh& mesh, int pieces);

/// "fragment-000", "fragment-001", ...: the name of fracture's index-th fragment, wherever one is
/// written or shown (files, scenes, reports).
std::string fragmentName(std::size_t index);

/// Errors: kInvalidArgument for options out of range; validateMesh's; kNotClosed (and the other
/// topology errors) for a mesh that does not enclose a volume.
Result<FractureResult> fracture(const core::TriangleMesh& mesh, const FractureOptions& options = {});

}  // namespace shapedb::volume
