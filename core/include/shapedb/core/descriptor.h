#pragma once
// Shape descriptors (paper §4) and their similarities (eq. 4-6): what a descriptor holds and how two
// compare. They are computed from a mesh by volume::Describer (volume/describe.h, on OpenVDB grids);
// core::Index (index.h) searches many of them.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// The three shape descriptors of the paper (§4).
enum class DescriptorKind {
  kMoment,         ///< §4.1: the three principal moments of the normalized shape, ascending
  kVoxel,          ///< §4.2: binary occupancy of an N³ grid
  kCentroidVoxel,  ///< §4.3, the "improved voxel": occupancy plus the centroid of the surface per filled cell
};

/// How the surface is binned into the grid of a voxel descriptor.
enum class Sampling {
  kArea,      ///< the surface itself, clipped exactly to the cells: occupancy and centroids by area
  kVertices,  ///< the mesh's vertices, as the paper does: depends on the tessellation
};

/// Parameters of a descriptor. Plain value type.
struct DescriptorOptions {
  DescriptorKind kind = DescriptorKind::kCentroidVoxel;
  Sampling sampling = Sampling::kArea;
  int gridSize = 10;  ///< N, cells per axis; 2 ≤ N ≤ kMaxGridSize
  /// Area sampling: a cell is filled when the surface inside it covers at least this fraction of one
  /// cell face. Keeps cells that the surface only grazes, by round-off or by a sliver, empty.
  double minCellArea = 1e-4;
};

/// Linear index i + N (j + N k) of cell (i, j, k) in an N³ grid, x fastest.
inline std::uint32_t linearCell(int i, int j, int k, int gridSize) {
  return static_cast<std::uint32_t>(i + gridSize * (j + gridSize * k));
}

/// The (i, j, k) of linear cell index `cell` in an N³ grid: the inverse of linearCell.
inline std::array<int, 3> cellCoordinates(std::uint32_t cell, int gridSize) {
  const int c = static_cast<int>(cell);
  return {c % gridSize, c / gridSize % gridSize, c / (gridSize * gridSize)};
}

/// Largest supported grid size: N³ cell indices fit comfortably in 32 bits and a query's dense
/// scratch in cache.
inline constexpr int kMaxGridSize = 64;

/// The descriptor of one normalized shape. Plain value type.
///
/// Grid layout: a cube of side `gridSize · cellSize` centred at the origin of the canonical frame,
/// side = the largest extent of the normalized mesh (§4.2); cell (i, j, k) has linear index
/// i + N (j + N k), x fastest. Surface outside the cube (the cube is centred on the centre of mass, not
/// on the bounding box) is counted in the border cells.
struct Descriptor {
  DescriptorKind kind = DescriptorKind::kCentroidVoxel;
  Sampling sampling = Sampling::kArea;
  Vec3 moments = Vec3::Zero();       ///< principal moments of the unit-volume, unit-density shape, ascending
  int gridSize = 0;                  ///< N; 0 for a moment descriptor
  double cellSize = 0.0;             ///< canonical units (the shape has volume 1)
  std::vector<std::uint32_t> cells;  ///< filled cells, ascending linear index
  /// Per filled cell: the centroid of the surface (or of the vertices) inside it, in the cell's own
  /// unit cube, each coordinate in [0, 1]. Filled for voxel descriptors too (cheap, useful to look at).
  std::vector<Vec3> centroids;
  std::vector<double> weights;  ///< per filled cell: area (canonical units²) or vertex count
  /// The rotation applied to the canonical frame before binning (orientation candidates):
  /// candidateFromCanonical. Identity unless the search tried another orientation.
  Mat3 orientation = Mat3::Identity();

  std::size_t filledCount() const { return cells.size(); }
  /// The centroid of filled cell `index` (position in `cells`) in the canonical frame.
  Vec3 canonicalCentroid(std::size_t index) const;
};

/// Checks that `d` is a well-formed descriptor of the kind, sampling and grid size `options` name:
/// finite moments; for the voxel kinds, a grid of 2 to kMaxGridSize cells across, cells strictly
/// ascending and below N³, one centroid per cell (centroid-voxel), each coordinate in [0, 1]. What the
/// index checks before it trusts a descriptor (a query's, or an entry's read back from a file).
/// Errors: kInvalidArgument naming the first problem.
Status validateDescriptor(const Descriptor& d, const DescriptorOptions& options);

/// Paper eq. (4): ‖m₁ − m₂‖², squared distance of the sorted moments.
double momentDistance(const Vec3& a, const Vec3& b);

/// Paper eq. (5): the number of cells filled in exactly one of the two, over n_filled, which we read
/// as the cells filled in at least one (the union). That is the Jaccard distance: in [0, 1], 1 for
/// disjoint grids, and a metric. (Reading n_filled as the intersection would let v exceed 1, against
/// the paper's own claim 0 ≤ v ≤ 1.) Two empty grids are at distance 0.
/// Precondition: same grid size.
double voxelDistance(const Descriptor& a, const Descriptor& b);

/// Paper eq. (6): (cells filled in exactly one + Σ over cells filled in both ‖c₁ − c₂‖ / l_diag) over
/// (n_filled + n_eq), n_filled the union as in eq. (5) and n_eq the cells filled in both; so the
/// denominator is n₁ + n₂. Centroids are compared in their cell's unit cube (l_diag = √3), so grids of
/// different physical size compare cell for cell, and each term is at most 1. In [0, 1].
/// Precondition: same grid size.
double centroidVoxelDistance(const Descriptor& a, const Descriptor& b);

/// The similarity of the descriptors' kind (a's kind; b must be of the same kind and grid size).
double descriptorDistance(const Descriptor& a, const Descriptor& b);

/// The descriptor of the same shape in the frame `rotation` · (d's frame), when `rotation` only
/// permutes and reverses axes (every entry within 1e-12 of 0 or ±1), without describing the surface
/// again: the grid is centred on the origin and its side is the largest extent, so such a rotation
/// maps whole cells to cells and each centroid's coordinates to themselves or 1 − themselves.
/// Equals Describer::describe in the rotated frame up to round-off for area sampling. (With vertex
/// sampling a vertex lying on a cell plane belongs to the cell above it, which a reversal changes.)
/// nullopt when `rotation` is not such a matrix. Moment descriptors come back unchanged.
std::optional<Descriptor> reorientDescriptor(const Descriptor& d, const Mat3& rotation);

/// "moment", "voxel", "centroid-voxel"; "area", "vertices".
const char* toString(DescriptorKind kind);
const char* toString(Sampling sampling);
std::optional<DescriptorKind> parseDescriptorKind(std::string_view name);
std::optional<Sampling> parseSampling(std::string_view name);

}  // namespace shapedb::core
