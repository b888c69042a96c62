#include <algorithm>
#include <cmath>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>

#include <shapedb/core/topology.h>
#include <shapedb/volume/openvdb_runtime.h>
#include <shapedb/volume/simplify.h>

#include "family_shapes.h"
#include "level_set.h"

namespace shapedb::volume::detail {

using core::TriangleMesh;
using core::Vec3;

Result<TriangleMesh> meshCsg(std::span<const CsgTerm> terms, double thinnest, std::size_t maxTriangles) {
  if (terms.empty()) return Error{ErrorCode::kInvalidArgument, "a constructive solid needs a term"};
  constexpr double kAcrossThinnest = 3.0, kMinAcross = 48.0, kMaxAcross = 240.0;
  constexpr double kRawTriangles = 20000.0;  ///< about the most marching cubes may make: simplifying costs
  constexpr double kFrameMargin = 16.0;      ///< voxels, as fracture: the solid inside one top-level node

  // The voxel: three across the thinnest part, unless the surface would then be more than ~20,000 raw
  // triangles (two per voxel of its area, the terms' areas summed being an upper bound), within 48 to
  // 240 across the whole.
  core::Bounds bounds = core::computeBounds(terms.front().solid);
  double area = 0.0;
  for (const CsgTerm& term : terms) {
    const core::Bounds b = core::computeBounds(term.solid);
    bounds.min = bounds.min.cwiseMin(b.min);
    bounds.max = bounds.max.cwiseMax(b.max);
    area += core::computeSurfaceArea(term.solid);
  }
  const double longest = bounds.extent().maxCoeff();
  const double voxel = std::clamp(std::max(thinnest / kAcrossThinnest, std::sqrt(2.0 * area / kRawTriangles)),
                                  longest / kMaxAcross, longest / kMinAcross);

  // A local frame with every term a margin into the positive octant (fracture's reasons: single
  // precision, and the grid tree's top-level nodes meeting at the origin), back to the shape's at the end.
  initializeOpenVdb();
  const Vec3 origin = bounds.min - Vec3::Constant(kFrameMargin * voxel);
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
  const auto localLevelSet = [&](const TriangleMesh& mesh) {
    TriangleMesh local = mesh;
    for (Vec3& p : local.vertices)
      p -= origin;
    return levelSet(local, *transform);
  };
  openvdb::FloatGrid::Ptr solid = localLevelSet(terms.front().solid);
  for (const CsgTerm& term : terms.subspan(1)) {
    openvdb::FloatGrid::Ptr other = localLevelSet(term.solid);
    if (term.subtract)
      openvdb::tools::csgDifference(*solid, *other);
    else
      openvdb::tools::csgUnion(*solid, *other);
  }

  // The zero crossing, simplified to triangles TetGen can keep without refining much around them (an
  // entry's tets, not its surface, are what it costs): as far as a voxel from the crossing, which is
  // itself within a fraction of a voxel of the terms' surfaces.
  auto [raw, meshing] = closedSurface(*solid, voxel, {.maxTriangles = 0});
  if (meshing == Meshing::kOpen || raw.triangles.empty())
    return Error{ErrorCode::kNotClosed, "the constructive solid's surface does not close"};
  const Vec3 centre = core::computeBounds(raw).center();
  for (Vec3& p : raw.vertices)
    p -= centre;
  Result<TriangleMesh> simpler =
      simplify(raw, {.maxTriangles = maxTriangles, .maxError = voxel, .maxAspectRatio = 6.0});
  if (!simpler || !isClosedSolid(*simpler))
    return Error{ErrorCode::kNotClosed,
                 "the constructive solid's surface did not stay closed when simplified"};
  TriangleMesh mesh = std::move(simpler).value();
  for (Vec3& p : mesh.vertices)
    p += centre;
  const core::TopologyReport topology = core::analyzeTopology(mesh);
  if (topology.components != 1)
    return Error{ErrorCode::kNotClosed,
                 "the constructive solid is in " + std::to_string(topology.components) + " pieces"};
  for (Vec3& p : mesh.vertices)
    p += origin;
  return mesh;
}

}  // namespace shapedb::volume::detail
