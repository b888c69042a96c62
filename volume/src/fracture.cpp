#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Clip.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <shapedb/core/topology.h>
#include <shapedb/volume/fracture.h>
#include <shapedb/volume/openvdb_runtime.h>

#include "level_set.h"
#include "polyhedron.h"
#include "random_draws.h"

namespace shapedb::volume {

using core::TriangleMesh;
using core::Vec3;

namespace {

using detail::Meshing;

constexpr double kFrameMargin = 16.0;  ///< voxels between the local frame's origin and the mesh's bounds

/// A level set's crossing can close a speck apart from the fragment around it (where the solid is a
/// voxel thin): a shell of its own, a crumb by volume. Such shells are dropped and counted as the crumbs
/// they are, so that each fragment is its solid alone; a fragment whose every solid shell is a crumb is
/// left whole, to be counted as one crumb. Cavities stay.
void dropCrumbShells(TriangleMesh& piece, double crumbVolume, FractureResult& result) {
  const std::vector<core::Shell> shells = core::findShells(piece);
  if (shells.size() < 2) return;
  const auto isCrumb = [crumbVolume](const core::Shell& s) {
    return !s.cavity && std::abs(s.volume) < crumbVolume;
  };
  if (std::none_of(shells.begin(), shells.end(), isCrumb) ||
      std::all_of(shells.begin(), shells.end(), [&](const core::Shell& s) { return s.cavity || isCrumb(s); }))
    return;
  std::vector<bool> dropped(piece.triangles.size(), false);
  for (const core::Shell& s : shells) {
    if (!isCrumb(s)) continue;
    ++result.crumbsDropped;
    result.droppedVolume += std::abs(s.volume);
    for (const std::uint32_t t : s.triangles)
      dropped[t] = true;
  }
  core::removeTriangles(piece, dropped);
}

}  // namespace

std::string fragmentName(std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "fragment-%03zu", index);
  return name;
}

int automaticResolution(const TriangleMesh& mesh, int pieces) {
  constexpr double kBase = 128.0, kMax = 1024.0, kAcrossThickness = 6.0, kAcrossFragment = 16.0;
  const core::Bounds bounds = core::computeBounds(mesh);
  const double longest = (bounds.max - bounds.min).maxCoeff();
  const double volume = std::abs(core::computeSignedVolume(mesh));
  const double area = core::computeSurfaceArea(mesh);
  if (!(longest > 0.0 && volume > 0.0 && area > 0.0)) return static_cast<int>(kBase);
  const double thickness = 2.0 * volume / area;
  const double fragment = std::cbrt(volume / std::max(pieces, 1));
  const double voxel = std::min({longest / kBase, thickness / kAcrossThickness, fragment / kAcrossFragment});
  return static_cast<int>(std::min(kMax, std::ceil(longest / voxel)));
}

Result<FractureResult> fracture(const TriangleMesh& mesh, const FractureOptions& options) {
  if (options.pieces < 1 || options.pieces > 1000)
    return Error{ErrorCode::kInvalidArgument,
                 "pieces must be 1 to 1,000, not " + std::to_string(options.pieces)};
  if (options.resolution != 0 && (options.resolution < 16 || options.resolution > 1024))
    return Error{
        ErrorCode::kInvalidArgument,
        "resolution must be 16 to 1,024 voxels (or 0: automatic), not " + std::to_string(options.resolution)};
  if (options.maxTriangles != 0 && (options.maxTriangles < 100 || !(options.simplifyError > 0.0)))
    return Error{ErrorCode::kInvalidArgument,
                 "fragments simplified to fewer than 100 triangles, or with no error allowed, would not "
                 "be fragments (0 keeps the raw meshes)"};
  if (!(options.minVolumeFraction >= 0.0 && options.minVolumeFraction < 1.0))
    return Error{ErrorCode::kInvalidArgument, "the crumb threshold must be a fraction in [0, 1)"};
  if (Status st = core::validateMesh(mesh); !st) return st.error();
  if (Status st = core::requireClosedOriented(core::analyzeTopology(mesh)); !st) return st.error();
  const double volume = core::computeSignedVolume(mesh);
  if (!(volume > 0.0))
    return Error{ErrorCode::kInsideOut,
                 "the surface encloses a negative or zero volume (faces wound inward?)"};

  // Everything below happens in a local frame in double precision until OpenVDB's single-precision
  // points: scans and CAD exports often sit hundreds of metres from the origin, where a float cannot
  // resolve a voxel's hundredth and the level sets' surfaces tear. The frame puts the mesh's bounds a few
  // voxels into the positive octant, so that the solid also lies within one of the grid tree's top-level
  // nodes (a solid straddling the origin, where all of them meet, came out of the CSG with a hole along
  // the coordinate planes). Its unit is the mesh's largest side, so that the voxels are never too small
  // for OpenVDB (it refuses a transform's scale under about 1e-8: a part read in the wrong unit, microns
  // across, threw "Non-zero scale values required"); lengths and volumes go back to the mesh's units with
  // the fragments.
  initializeOpenVdb();
  const core::Bounds worldBounds = core::computeBounds(mesh);
  const double side = (worldBounds.max - worldBounds.min).maxCoeff();
  FractureResult result;
  result.solidVolume = volume;
  result.resolution =
      options.resolution != 0 ? options.resolution : automaticResolution(mesh, options.pieces);
  result.voxelSize = side / result.resolution;
  const double voxel = 1.0 / result.resolution;  // in the local frame
  const Vec3 origin = worldBounds.min - Vec3::Constant(kFrameMargin * result.voxelSize);
  TriangleMesh local = mesh;
  for (Vec3& p : local.vertices)
    p = (p - origin) / side;
  const double localVolume = volume / (side * side * side);
  const core::Bounds bounds = core::computeBounds(local);
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
  openvdb::FloatGrid::Ptr solid = detail::levelSet(local, *transform);

  // Seeds: uniform in the bounding box, kept where the level set says the point is inside.
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> seeds;
  const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> inside(*solid);
  const long attempts = 1000L * options.pieces + 100000L;
  for (long a = 0; a < attempts && static_cast<int>(seeds.size()) < options.pieces; ++a) {
    const Vec3 p =
        bounds.min + (bounds.max - bounds.min).cwiseProduct(detail::drawVector([&] { return unit(rng); }));
    if (inside.wsSample(openvdb::Vec3R(p.x(), p.y(), p.z())) < 0.0) seeds.push_back(p);
  }
  if (seeds.empty())
    return Error{ErrorCode::kZeroVolume,
                 "the solid is too thin for its resolution: no seed fell inside it "
                 "(raise the resolution)"};

  // One cutter per Voronoi cell (the box around the solid, cut by the bisector planes to every other
  // seed). The cells tile space, so each fragment is its cell's level set intersected with the solid, and
  // the cells are independent: each is cut from the part of the solid under its own bounding box, in
  // parallel, then split into its connected pieces (a cell can cut a non-convex solid in two). This is
  // what tools::LevelSetFracture does cutter by cutter, without its cost: it re-segments every fragment
  // made so far at each cut, quadratic in the pieces (200 pieces took minutes), and it drops a fragment
  // whose cutter leaves no residual (a cell that holds the whole solid).
  const Vec3 margin = Vec3::Constant((detail::kLevelSetHalfWidth + 2.0) * voxel);
  std::vector<std::vector<openvdb::FloatGrid::Ptr>> cellGrids(seeds.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seeds.size(), 1), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const std::vector<detail::Polygon> cell =
          detail::voronoiCell(detail::boxFaces(bounds.min - margin, bounds.max + margin), seeds, i);
      if (cell.size() < 4) continue;
      const TriangleMesh cutterMesh = detail::triangulate(cell);
      const core::Bounds cellBounds = core::computeBounds(cutterMesh);
      const Vec3 lo = cellBounds.min - margin, hi = cellBounds.max + margin;
      const openvdb::FloatGrid::Ptr clipped =
          openvdb::tools::clip(*solid, openvdb::BBoxd({lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}));
      const openvdb::FloatGrid::Ptr cutter = detail::levelSet(cutterMesh, *transform);
      const openvdb::FloatGrid::Ptr piece = openvdb::tools::csgIntersectionCopy(*clipped, *cutter);
      if (piece->tree().empty()) continue;
      openvdb::tools::segmentSDF(*piece, cellGrids[i]);
    }
  });
  std::vector<openvdb::FloatGrid::Ptr> grids;
  for (auto& g : cellGrids)
    grids.insert(grids.end(), g.begin(), g.end());

  std::vector<std::pair<TriangleMesh, Meshing>> surfaces(grids.size());
  tbb::parallel_for(std::size_t{0}, grids.size(), [&](std::size_t i) {
    surfaces[i] = detail::closedSurface(
        *grids[i], voxel, {.maxTriangles = options.maxTriangles, .simplifyError = options.simplifyError});
  });

  // Volumes in the local frame's unit until the end.
  std::vector<std::pair<double, TriangleMesh>> pieces;
  for (auto& [piece, meshing] : surfaces) {
    if (piece.triangles.empty()) continue;
    dropCrumbShells(piece, options.minVolumeFraction * localVolume, result);
    const double v = core::computeSignedVolume(piece);
    if (meshing == Meshing::kOpen) {
      // No crossing near the zero level closed: never seen, and not passed on as a solid.
      ++result.openDropped;
      result.droppedVolume += std::max(v, 0.0);
      continue;
    }
    if (v < options.minVolumeFraction * localVolume) {
      ++result.crumbsDropped;
      result.droppedVolume += std::max(v, 0.0);
      continue;
    }
    if (meshing == Meshing::kRemeshed) ++result.remeshed;
    result.keptVolume += v;
    for (Vec3& p : piece.vertices)
      p = origin + side * p;
    pieces.emplace_back(v, std::move(piece));
  }
  result.keptVolume *= side * side * side;
  result.droppedVolume *= side * side * side;
  // Largest first; ties (never in practice) by the first vertex, so the order is the mesh's own.
  std::sort(pieces.begin(), pieces.end(), [](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first > b.first;
    const Vec3& pa = a.second.vertices.front();
    const Vec3& pb = b.second.vertices.front();
    return std::lexicographical_compare(pa.data(), pa.data() + 3, pb.data(), pb.data() + 3);
  });
  for (auto& piece : pieces)
    result.fragments.push_back(std::move(piece.second));
  return result;
}

}  // namespace shapedb::volume
