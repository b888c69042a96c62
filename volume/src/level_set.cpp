#include "level_set.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <shapedb/core/disjoint_sets.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/repair.h>
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
  const auto one = [&transform](const TriangleMesh& surface) {
    const OpenVdbMesh vdb = toOpenVdb(surface);
    return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(transform, vdb.points, vdb.triangles,
                                                              kLevelSetHalfWidth);
  };
  // meshToLevelSet signs a voxel inside where the outside cannot reach it, so it fills a cavity (an inner
  // shell wound inward: a hollow ball came apart into fragments of twice its volume). A closed surface of
  // several shells is made of each shell's own solid: the solids joined, the cavities cut out of them.
  if (!isClosedSolid(mesh)) return one(mesh);
  const std::vector<core::Shell> shells = core::findShells(mesh);
  if (shells.size() < 2) return one(mesh);
  openvdb::FloatGrid::Ptr solid;
  std::vector<openvdb::FloatGrid::Ptr> cavities;
  for (const core::Shell& shell : shells) {
    TriangleMesh part;
    std::unordered_map<std::uint32_t, std::uint32_t> renumbered;
    for (std::uint32_t t : shell.triangles) {
      TriangleMesh::Triangle tri = mesh.triangles[t];
      for (std::uint32_t& v : tri) {
        const auto [at, added] = renumbered.emplace(v, static_cast<std::uint32_t>(part.vertices.size()));
        if (added) part.vertices.push_back(mesh.vertices[v]);
        v = at->second;
      }
      if (shell.volume < 0.0) std::swap(tri[1], tri[2]);  // wound outward round its own solid
      part.triangles.push_back(tri);
    }
    openvdb::FloatGrid::Ptr grid = one(part);
    if (shell.cavity)
      cavities.push_back(std::move(grid));
    else if (!solid)
      solid = std::move(grid);
    else
      openvdb::tools::csgUnion(*solid, *grid);
  }
  if (!solid) return one(mesh);
  for (const openvdb::FloatGrid::Ptr& cavity : cavities)
    openvdb::tools::csgDifference(*solid, *cavity);
  return solid;
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
    if (options.uncrossed && !core::findSelfIntersections(*simpler).empty()) break;
    for (Vec3& p : simpler->vertices)
      p += centre;
    return {std::move(simpler).value(), meshing};
  }
  return {std::move(raw), meshing};
}

}  // namespace shapedb::volume::detail

namespace shapedb::volume {
namespace {

using core::TriangleMesh;
using core::Vec3;

/// The open boundary's loops: edges of one triangle, grouped by the vertices they share. For each, the
/// largest distance of its vertices from their centroid: about half the hole's width.
std::vector<double> holeRadii(const TriangleMesh& mesh) {
  std::unordered_map<std::uint64_t, int> edgeUses;
  const auto key = [](std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
  };
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      ++edgeUses[key(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)])];
  core::DisjointSets loopOf(mesh.vertices.size());
  std::vector<bool> onBoundary(mesh.vertices.size(), false);
  for (const auto& [edge, uses] : edgeUses) {
    if (uses != 1) continue;
    const auto a = static_cast<std::uint32_t>(edge >> 32), b = static_cast<std::uint32_t>(edge & 0xffffffffu);
    onBoundary[a] = onBoundary[b] = true;
    loopOf.unite(a, b);
  }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> loops;
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (onBoundary[v]) loops[loopOf.find(v)].push_back(v);
  std::vector<double> radii;
  for (const auto& [root, vertices] : loops) {
    Vec3 centre = Vec3::Zero();
    for (std::uint32_t v : vertices)
      centre += mesh.vertices[v];
    centre /= static_cast<double>(vertices.size());
    double radius = 0.0;
    for (std::uint32_t v : vertices)
      radius = std::max(radius, (mesh.vertices[v] - centre).norm());
    radii.push_back(radius);
  }
  std::sort(radii.begin(), radii.end());
  return radii;
}

}  // namespace

Result<RepairedSurface> repairSurface(const TriangleMesh& mesh, const RepairOptions& options) {
  if (options.resolution < 16 || options.resolution > 1024)
    return Error{ErrorCode::kInvalidArgument, "the repair's resolution must be 16 to 1024 voxels"};
  if (!(options.maxHoleFraction > 0.0 && options.maxHoleFraction <= 0.5))
    return Error{ErrorCode::kInvalidArgument, "the largest hole to close must be a fraction in (0, 0.5]"};
  if (mesh.triangles.empty() || mesh.vertices.empty())
    return Error{ErrorCode::kEmptyMesh, "the mesh has no triangles"};
  for (const Vec3& p : mesh.vertices)
    if (!p.allFinite()) return Error{ErrorCode::kNonFinite, "the mesh has a vertex that is not finite"};
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t)
      if (v >= mesh.vertices.size())
        return Error{ErrorCode::kIndexOutOfRange, "a triangle refers to a vertex that does not exist"};

  RepairReport report;
  report.resolution = options.resolution;
  report.trianglesBefore = mesh.triangles.size();
  report.areaBefore = core::computeSurfaceArea(mesh);
  if (detail::isClosedSolid(mesh)) report.volumeBefore = core::computeSignedVolume(mesh);
  const core::Bounds bounds = core::computeBounds(mesh);
  const double extent = (bounds.max - bounds.min).maxCoeff();
  if (!(extent > 0.0)) return Error{ErrorCode::kEmptyMesh, "the mesh has no extent"};
  const double voxel = extent / options.resolution;
  report.voxelSize = voxel;

  // The closing radius: wide enough to shut the widest hole.
  const std::vector<double> holes = holeRadii(mesh);
  report.holes = holes.size();
  const double widest = holes.empty() ? 0.0 : holes.back();
  if (2.0 * widest > options.maxHoleFraction * extent) {
    char message[200];
    std::snprintf(message, sizeof message,
                  "a hole %.3g across (%.0f %% of the mesh's largest side) is wider than the repair closes "
                  "(%.0f %%)",
                  2.0 * widest, 100.0 * 2.0 * widest / extent, 100.0 * options.maxHoleFraction);
    return Error{ErrorCode::kInvalidArgument, message};
  }
  const double radius = std::max(1.5 * voxel, widest + voxel);
  report.closingRadius = radius;

  // A local frame: float points near the origin, bounds away from the tree's top-level seams, and the
  // largest side 1 (OpenVDB refuses very small voxels: a 10 cm part read with --units mm, 0.1 mm across,
  // threw "Non-zero scale values required"), with a band reaching past the closing radius on both sides.
  // h and rr are the voxel and the radius there.
  const double h = voxel / extent, rr = radius / extent;
  const double bandVoxels = radius / voxel + 4.0;
  const Vec3 origin = bounds.min - Vec3::Constant((bandVoxels + 16.0) * voxel);
  TriangleMesh local = mesh;
  for (Vec3& p : local.vertices)
    p = (p - origin) / extent;
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(h);
  const detail::OpenVdbMesh vdb = detail::toOpenVdb(local);
  const openvdb::FloatGrid::Ptr distance = openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(
      *transform, vdb.points, vdb.triangles, std::vector<openvdb::Vec4I>{}, static_cast<float>(bandVoxels));

  // Outside: every voxel at least the radius from the surface that can be reached from the box's faces
  // through such voxels. The rest (the surface's neighbourhood and what it shuts in) is the closed solid
  // grown by the radius.
  const openvdb::Coord lo = transform->worldToIndexCellCentered(openvdb::Vec3d(0.0, 0.0, 0.0));
  const Vec3 top = (bounds.max - origin) / extent + Vec3::Constant((bandVoxels + 16.0) * h);
  const openvdb::Coord hi = transform->worldToIndexCellCentered(openvdb::Vec3d(top.x(), top.y(), top.z()));
  const openvdb::Coord dims = hi - lo + openvdb::Coord(1, 1, 1);
  const auto nx = static_cast<std::size_t>(dims.x()), ny = static_cast<std::size_t>(dims.y()),
             nz = static_cast<std::size_t>(dims.z());
  const auto index = [&](std::size_t x, std::size_t y, std::size_t z) { return (x * ny + y) * nz + z; };
  const float r = static_cast<float>(rr);
  std::vector<std::uint8_t> outside(nx * ny * nz, 0);
  {
    openvdb::FloatGrid::ConstAccessor d = distance->getConstAccessor();
    const auto open = [&](std::size_t x, std::size_t y, std::size_t z) {
      return d.getValue(lo + openvdb::Coord(static_cast<int>(x), static_cast<int>(y), static_cast<int>(z))) >=
             r;
    };
    std::vector<std::size_t> queue;
    const auto visit = [&](std::size_t x, std::size_t y, std::size_t z) {
      const std::size_t i = index(x, y, z);
      if (outside[i] || !open(x, y, z)) return;
      outside[i] = 1;
      queue.push_back(i);
    };
    for (std::size_t x = 0; x < nx; ++x)
      for (std::size_t y = 0; y < ny; ++y) {
        visit(x, y, 0);
        visit(x, y, nz - 1);
      }
    for (std::size_t x = 0; x < nx; ++x)
      for (std::size_t z = 0; z < nz; ++z) {
        visit(x, 0, z);
        visit(x, ny - 1, z);
      }
    for (std::size_t y = 0; y < ny; ++y)
      for (std::size_t z = 0; z < nz; ++z) {
        visit(0, y, z);
        visit(nx - 1, y, z);
      }
    while (!queue.empty()) {
      const std::size_t i = queue.back();
      queue.pop_back();
      const std::size_t z = i % nz, y = (i / nz) % ny, x = i / (ny * nz);
      if (x > 0) visit(x - 1, y, z);
      if (x + 1 < nx) visit(x + 1, y, z);
      if (y > 0) visit(x, y - 1, z);
      if (y + 1 < ny) visit(x, y + 1, z);
      if (z > 0) visit(x, y, z - 1);
      if (z + 1 < nz) visit(x, y, z + 1);
    }
  }

  // On the band, a field whose zero crossing is the grown solid's boundary, to sub-voxel accuracy: r − d
  // (positive within the radius, negative outside it), and positive wherever the surface shuts a voxel
  // in. Between an outside voxel and its inside neighbour d crosses r, so the crossing is where the
  // distance is the radius. Then the signed distance to that boundary, and the boundary moved back in by
  // the radius: the crossing of (distance + r).
  const openvdb::FloatGrid::Ptr grown = distance->deepCopy();
  for (openvdb::FloatGrid::ValueOnIter it = grown->beginValueOn(); it; ++it) {
    const openvdb::Coord c = it.getCoord() - lo;
    const bool out = c.x() >= 0 && c.y() >= 0 && c.z() >= 0 && static_cast<std::size_t>(c.x()) < nx &&
                     static_cast<std::size_t>(c.y()) < ny && static_cast<std::size_t>(c.z()) < nz &&
                     outside[index(static_cast<std::size_t>(c.x()), static_cast<std::size_t>(c.y()),
                                   static_cast<std::size_t>(c.z()))];
    const float inside = r - *it;
    it.setValue(out ? std::min(inside, 0.0f) : std::max(inside, 0.5f * static_cast<float>(h)));
  }
  outside = {};
  openvdb::FloatGrid::Ptr solid = openvdb::tools::fogToSdf(*grown, 0.0f);
  if (!solid) return Error{ErrorCode::kParse, "the repair's level set could not be built"};
  for (openvdb::FloatGrid::ValueOnIter it = solid->beginValueOn(); it; ++it)
    if (std::isfinite(*it)) it.setValue(*it + r);
  // Beyond the band, the sign of its nearest values: outside or inside at the band's distance.
  openvdb::tools::signedFloodFillWithValues(solid->tree(), static_cast<float>(bandVoxels * h),
                                            -static_cast<float>(bandVoxels * h));
  solid->setTransform(transform);

  // Unsimplified where the simplification would make it pass through itself: a repaired surface that
  // still did would need repairing again.
  auto [surface, meshing] = detail::closedSurface(
      *solid, h,
      detail::SurfaceOptions{.maxTriangles = options.maxTriangles, .simplifyError = 0.25, .uncrossed = true});
  if (surface.triangles.empty() || meshing == detail::Meshing::kOpen)
    return Error{ErrorCode::kParse,
                 "no closed surface came out of the repair: the mesh encloses nothing that its holes "
                 "leave shut (a single sheet, or holes wider than " +
                     std::to_string(2.0 * radius) + " across)"};
  for (Vec3& p : surface.vertices)
    p = origin + extent * p;
  report.volumeAfter = core::computeSignedVolume(surface);
  report.areaAfter = core::computeSurfaceArea(surface);
  report.trianglesAfter = surface.triangles.size();
  return RepairedSurface{std::move(surface), report};
}

}  // namespace shapedb::volume
