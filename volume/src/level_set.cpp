#include "level_set.h"

#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <shapedb/core/spatial.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/simplify.h>

namespace shapedb::volume::detail {

using core::TriangleMesh;
using core::Vec3;

namespace {

/// The crossing of a level set at `isovalue` (m), as an outward-wound triangle mesh (quads split).
TriangleMesh crossing(const openvdb::FloatGrid& grid, double isovalue) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, isovalue, 0.0);
  TriangleMesh mesh;
  mesh.vertices.reserve(points.size());
  for (const openvdb::Vec3s& p : points)
    mesh.vertices.emplace_back(p.x(), p.y(), p.z());
  for (const openvdb::Vec3I& t : triangles)
    mesh.triangles.push_back({t[0], t[1], t[2]});
  for (const openvdb::Vec4I& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  if (core::computeSignedVolume(mesh) < 0.0)
    for (auto& t : mesh.triangles)
      std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace

OpenVdbMesh toOpenVdb(const TriangleMesh& mesh) {
  OpenVdbMesh out;
  out.points.reserve(mesh.vertices.size());
  for (const Vec3& p : mesh.vertices)
    out.points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    out.triangles.emplace_back(t[0], t[1], t[2]);
  return out;
}

openvdb::FloatGrid::Ptr levelSet(const TriangleMesh& mesh, const openvdb::math::Transform& transform) {
  const OpenVdbMesh vdb = toOpenVdb(mesh);
  return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(transform, vdb.points, vdb.triangles,
                                                            kLevelSetHalfWidth);
}

bool isClosedSolid(const TriangleMesh& mesh) {
  return !mesh.triangles.empty() && core::validateMesh(mesh).ok() &&
         core::requireClosedOriented(core::analyzeTopology(mesh)).ok();
}

std::pair<TriangleMesh, Meshing> closedSurface(const openvdb::FloatGrid& grid, double voxelSize,
                                               const SurfaceOptions& options) {
  // The zero crossing first, then a hundredth of a voxel at a time off it (the surface moves by that
  // much, far under the simplification's own error).
  static constexpr double kIsovalues[] = {0.0, -0.01, 0.01, -0.03, 0.03, -0.1, 0.1};
  TriangleMesh raw;
  Meshing meshing = Meshing::kOpen;
  for (const double isovalue : kIsovalues) {
    raw = crossing(grid, isovalue * voxelSize);
    if (raw.triangles.empty() || isClosedSolid(raw)) {
      meshing = isovalue == 0.0 ? Meshing::kClosed : Meshing::kRemeshed;
      break;
    }
  }
  if (meshing == Meshing::kOpen) return {crossing(grid, 0.0), meshing};
  if (options.maxTriangles == 0 || raw.triangles.size() <= options.maxTriangles)
    return {std::move(raw), meshing};
  // Simplified about the surface's own centre (the decimater's quadrics are computed in coordinates).
  // Its quadric bound holds each collapse near the planes it has merged, not the faces it leaves: on thin
  // plates whole strips of a fragment's rim came out bevelled several times the bound deep, and a few per
  // cent of its volume gone. So every simplified face is checked at its centroid against the raw surface;
  // one farther than twice the bound has the simplification done again with half the error, and at the
  // end the raw surface stands.
  const Vec3 centre = core::computeBounds(raw).center();
  TriangleMesh centred = raw;
  for (Vec3& p : centred.vertices)
    p -= centre;
  const core::ClosestPointTree rawSurface(centred);
  const auto faithful = [&](const TriangleMesh& simpler, double maxError) {
    const double limitSq = 4.0 * maxError * maxError;
    for (const auto& t : simpler.triangles) {
      const Vec3 c = (simpler.vertices[t[0]] + simpler.vertices[t[1]] + simpler.vertices[t[2]]) / 3.0;
      if (rawSurface.closest(c).closest.squaredDistance > limitSq) return false;
    }
    return true;
  };
  SimplifyOptions simplifyOptions;
  simplifyOptions.maxTriangles = options.maxTriangles;
  for (double error = options.simplifyError; error >= options.simplifyError / 4.0; error /= 2.0) {
    simplifyOptions.maxError = error * voxelSize;
    Result<TriangleMesh> simpler = simplify(centred, simplifyOptions);
    if (!simpler.ok() || !isClosedSolid(*simpler)) break;
    if (!faithful(*simpler, simplifyOptions.maxError)) continue;
    for (Vec3& p : simpler->vertices)
      p += centre;
    return {std::move(simpler).value(), meshing};
  }
  return {std::move(raw), meshing};
}

}  // namespace shapedb::volume::detail
