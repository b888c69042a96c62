#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Clip.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <shapedb/core/topology.h>
#include <shapedb/volume/fracture.h>
#include <shapedb/volume/openvdb_runtime.h>
#include <shapedb/volume/simplify.h>

#include "polyhedron.h"

namespace shapedb::volume {

using core::TriangleMesh;
using core::Vec3;

namespace {

constexpr float kHalfWidth = 3.0f;  ///< narrow band, voxels, for the solid and every cutter alike

openvdb::FloatGrid::Ptr levelSet(const TriangleMesh& mesh, const openvdb::math::Transform& transform) {
  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.vertices.size());
  for (const Vec3& p : mesh.vertices)
    points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    triangles.emplace_back(t[0], t[1], t[2]);
  return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(transform, points, triangles, kHalfWidth);
}

/// Signed volume of a closed surface (divergence theorem).
double signedVolume(const TriangleMesh& mesh) {
  double six = 0.0;
  for (const auto& t : mesh.triangles)
    six += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  return six / 6.0;
}

/// The zero crossing of a fragment's level set, as an outward-wound triangle mesh (quads split).
TriangleMesh meshOf(const openvdb::FloatGrid& grid) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, 0.0, 0.0);
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
  if (signedVolume(mesh) < 0.0)
    for (auto& t : mesh.triangles)
      std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace

Result<FractureResult> fracture(const TriangleMesh& mesh, const FractureOptions& options) {
  if (options.pieces < 1 || options.pieces > 1000)
    return Error{ErrorCode::kInvalidArgument,
                 "pieces must be 1 to 1,000, not " + std::to_string(options.pieces)};
  if (options.resolution < 16 || options.resolution > 1024)
    return Error{ErrorCode::kInvalidArgument,
                 "resolution must be 16 to 1,024 voxels, not " + std::to_string(options.resolution)};
  if (options.maxTriangles != 0 && (options.maxTriangles < 100 || !(options.simplifyError > 0.0)))
    return Error{ErrorCode::kInvalidArgument,
                 "fragments simplified to fewer than 100 triangles, or with no error allowed, would not "
                 "be fragments (0 keeps the raw meshes)"};
  if (!(options.minVolumeFraction >= 0.0 && options.minVolumeFraction < 1.0))
    return Error{ErrorCode::kInvalidArgument, "the crumb threshold must be a fraction in [0, 1)"};
  if (Status st = core::validateMesh(mesh); !st) return st.error();
  if (Status st = core::requireClosedOriented(core::analyzeTopology(mesh)); !st) return st.error();
  const double volume = signedVolume(mesh);
  if (!(volume > 0.0))
    return Error{ErrorCode::kInsideOut,
                 "the surface encloses a negative or zero volume (faces wound inward?)"};

  initializeOpenVdb();
  const core::Bounds bounds = core::computeBounds(mesh);
  FractureResult result;
  result.voxelSize = (bounds.max - bounds.min).maxCoeff() / options.resolution;
  const openvdb::math::Transform::Ptr transform =
      openvdb::math::Transform::createLinearTransform(result.voxelSize);
  openvdb::FloatGrid::Ptr solid = levelSet(mesh, *transform);

  // Seeds: uniform in the bounding box, kept where the level set says the point is inside.
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> seeds;
  const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> inside(*solid);
  const long attempts = 1000L * options.pieces + 100000L;
  for (long a = 0; a < attempts && static_cast<int>(seeds.size()) < options.pieces; ++a) {
    const Vec3 p = bounds.min + (bounds.max - bounds.min).cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng)));
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
  const Vec3 margin = Vec3::Constant((kHalfWidth + 2.0) * result.voxelSize);
  std::vector<std::vector<openvdb::FloatGrid::Ptr>> cellGrids(seeds.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seeds.size(), 1), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const std::vector<detail::Polygon> cell =
          detail::voronoiCell(detail::boxFaces(bounds.min - margin, bounds.max + margin), seeds, i);
      if (cell.size() < 4) continue;
      const TriangleMesh cutterMesh = detail::triangulate(cell);
      const core::Bounds cellBounds = core::computeBounds(cutterMesh);
      const Vec3 lo = cellBounds.min - margin, hi = cellBounds.max + margin;
      const openvdb::FloatGrid::Ptr local =
          openvdb::tools::clip(*solid, openvdb::BBoxd({lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}));
      const openvdb::FloatGrid::Ptr cutter = levelSet(cutterMesh, *transform);
      const openvdb::FloatGrid::Ptr piece = openvdb::tools::csgIntersectionCopy(*local, *cutter);
      if (piece->tree().empty()) continue;
      openvdb::tools::segmentSDF(*piece, cellGrids[i]);
    }
  });
  std::vector<openvdb::FloatGrid::Ptr> grids;
  for (auto& g : cellGrids)
    grids.insert(grids.end(), g.begin(), g.end());

  // Meshed, and simplified where the raw mesh is closed (an open one is dropped below either way).
  std::vector<TriangleMesh> meshes(grids.size());
  tbb::parallel_for(std::size_t{0}, grids.size(), [&](std::size_t i) {
    meshes[i] = meshOf(*grids[i]);
    if (options.maxTriangles == 0 || meshes[i].triangles.size() <= options.maxTriangles) return;
    SimplifyOptions simplifyOptions;
    simplifyOptions.maxTriangles = options.maxTriangles;
    simplifyOptions.maxError = options.simplifyError * result.voxelSize;
    if (Result<TriangleMesh> simpler = simplify(meshes[i], simplifyOptions); simpler.ok())
      meshes[i] = std::move(simpler).value();
  });

  std::vector<std::pair<double, TriangleMesh>> pieces;
  for (TriangleMesh& piece : meshes) {
    if (piece.triangles.empty()) continue;
    const double v = signedVolume(piece);
    if (v < options.minVolumeFraction * volume) {
      ++result.crumbsDropped;
      continue;
    }
    if (!core::validateMesh(piece).ok() || !core::requireClosedOriented(core::analyzeTopology(piece)).ok()) {
      ++result.openDropped;
      continue;
    }
    pieces.emplace_back(v, std::move(piece));
  }
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
