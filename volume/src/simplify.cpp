#include <cmath>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModAspectRatioT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/simplify.h>

namespace shapedb::volume {

namespace {

struct Traits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using Mesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;

}  // namespace

Result<core::TriangleMesh> simplify(const core::TriangleMesh& input, const SimplifyOptions& options) {
  if (!(options.maxError > 0.0) || options.maxTriangles < 4 || !(options.maxNormalDeviationDegrees > 0.0) ||
      !(options.maxAspectRatio > 1.0))
    return Error{ErrorCode::kInvalidArgument,
                 "simplify: the error bound must be positive, the triangle target at least 4, the normal "
                 "deviation positive and the aspect ratio above 1"};
  if (Status st = core::requireClosedOriented(core::analyzeTopology(input)); !st) return st.error();
  if (input.triangles.size() <= options.maxTriangles) return input;

  Mesh mesh;
  std::vector<Mesh::VertexHandle> handles;
  handles.reserve(input.vertices.size());
  for (const core::Vec3& p : input.vertices)
    handles.push_back(mesh.add_vertex(Mesh::Point(p.x(), p.y(), p.z())));
  for (const auto& t : input.triangles)
    if (!mesh.add_face(handles[t[0]], handles[t[1]], handles[t[2]]).is_valid())
      return Error{ErrorCode::kNonManifold,
                   "simplify: OpenMesh refused a face of the surface (non-manifold)"};
  mesh.update_face_normals();

  using Decimater = OpenMesh::Decimater::DecimaterT<Mesh>;
  Decimater decimater(mesh);
  OpenMesh::Decimater::ModQuadricT<Mesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle flipping;
  OpenMesh::Decimater::ModAspectRatioT<Mesh>::Handle aspect;
  decimater.add(quadric);
  decimater.add(flipping);
  decimater.add(aspect);
  decimater.module(quadric).set_max_err(options.maxError * options.maxError, /*binary=*/false);
  decimater.module(flipping).set_max_normal_deviation(options.maxNormalDeviationDegrees);
  decimater.module(aspect).set_aspect_ratio(static_cast<float>(options.maxAspectRatio));
  decimater.initialize();
  decimater.decimate_to_faces(0, options.maxTriangles);
  mesh.garbage_collection();

  core::TriangleMesh out;
  out.vertices.reserve(mesh.n_vertices());
  for (const Mesh::VertexHandle v : mesh.vertices()) {
    const Mesh::Point& p = mesh.point(v);
    out.vertices.emplace_back(p[0], p[1], p[2]);
  }
  out.triangles.reserve(mesh.n_faces());
  for (const Mesh::FaceHandle f : mesh.faces()) {
    core::TriangleMesh::Triangle t{};
    int k = 0;
    for (const Mesh::VertexHandle v : mesh.fv_range(f))
      t[k++] = static_cast<std::uint32_t>(v.idx());
    out.triangles.push_back(t);
  }
  if (Status st = core::requireClosedOriented(core::analyzeTopology(out)); !st)
    return withContext(st.error(), "simplify (a bug: the collapses broke the surface)");
  return out;
}

Result<std::optional<core::TriangleMesh>> surfaceForEntry(const core::TriangleMesh& mesh,
                                                          std::size_t maxTriangles) {
  if (maxTriangles == 0 || mesh.triangleCount() <= maxTriangles) return std::optional<core::TriangleMesh>();
  auto mass = core::computeMassProperties(mesh);
  if (!mass) return mass.error();
  SimplifyOptions options;
  options.maxTriangles = maxTriangles;
  options.maxError = 1e-3 * std::cbrt(mass->volume);
  auto simplified = simplify(mesh, options);
  if (!simplified) return withContext(simplified.error(), "simplifying its surface");
  return std::optional<core::TriangleMesh>(std::move(simplified).value());
}

}  // namespace shapedb::volume
