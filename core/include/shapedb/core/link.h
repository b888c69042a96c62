#pragma once
// The link stage, the last of a query (paper eq. 7): every vertex of the query's surface tied to a tet
// of the adapted entry's tet mesh, so that the entry's mode shapes (node displacements) move the
// query's own surface. Tets are found through a TetLocator (spatial.h) built once per entry, in its
// canonical frame; a Placement (adapt.h) carries the query's vertices there.

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/adapt.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// Linking (paper eq. 7): per surface vertex, the adapted tet that holds it and its four barycentric
/// weights (≥ 0, summing to 1). A vertex outside every tet is tied to the closest point of the tet
/// mesh's boundary, in the tet that owns it.
struct SurfaceLink {
  std::vector<TetLocation> locations;  ///< per vertex
  std::size_t outsideCount = 0;
  double maxOutsideDistance = 0.0;  ///< metres
};

/// Links `vertices` (the query's, in its frame) to the entry's tets through `locator`, built on the
/// entry's canonical tet mesh: the vertices are carried to the entry's frame by `placement`, so one
/// locator serves every query that matches the entry. Distances are reported in the query's units.
/// Parallel (TBB) from 1,024 vertices.
SurfaceLink linkSurface(const TetLocator& locator, const Placement& placement,
                        std::span<const Vec3> vertices);

/// Deformed positions of linked vertices: x = rest + Σ wᵢ u(nodeᵢ), with u the node displacements
/// (3 per node, query frame). Inside vertices thus move with the tet's linear interpolation; outside
/// vertices with their closest point. `out` is resized to rest.size().
void deformSurface(const SurfaceLink& link, const TetMesh& tetMesh,
                   const Eigen::Ref<const Eigen::VectorXd>& u, std::span<const Vec3> rest,
                   std::vector<Vec3>& out);

}  // namespace shapedb::core
