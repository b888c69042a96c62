#include <cstdint>
#include <unordered_map>

#include <shapedb/core/triangle_mesh.h>

namespace shapedb::core {

Bounds computeBounds(const TriangleMesh& mesh) {
  Bounds bounds;
  if (mesh.vertices.empty()) return bounds;
  bounds.min = bounds.max = mesh.vertices.front();
  for (const Vec3& p : mesh.vertices) {
    bounds.min = bounds.min.cwiseMin(p);
    bounds.max = bounds.max.cwiseMax(p);
  }
  return bounds;
}

double computeSurfaceArea(const TriangleMesh& mesh) {
  double twiceArea = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    twiceArea += (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
  }
  return 0.5 * twiceArea;
}

double computeSignedVolume(const TriangleMesh& mesh) {
  if (mesh.vertices.empty()) return 0.0;
  const Vec3 o = mesh.vertices.front();
  double six = 0.0;
  for (const auto& t : mesh.triangles)
    six += (mesh.vertices[t[0]] - o).dot((mesh.vertices[t[1]] - o).cross(mesh.vertices[t[2]] - o));
  return six / 6.0;
}

void append(TriangleMesh& into, const TriangleMesh& part) {
  const auto offset = static_cast<std::uint32_t>(into.vertices.size());
  into.vertices.insert(into.vertices.end(), part.vertices.begin(), part.vertices.end());
  into.triangles.reserve(into.triangles.size() + part.triangles.size());
  for (const auto& t : part.triangles)
    into.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

std::size_t removeUnusedVertices(TriangleMesh& mesh) {
  constexpr std::uint32_t kUnused = 0xffffffffu;
  std::vector<std::uint32_t> index(mesh.vertices.size(), kUnused);
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t v : t)
      index[v] = 0;
  std::uint32_t kept = 0;
  for (std::size_t v = 0; v < index.size(); ++v)
    if (index[v] != kUnused) {
      mesh.vertices[kept] = mesh.vertices[v];
      index[v] = kept++;
    }
  const std::size_t dropped = mesh.vertices.size() - kept;
  mesh.vertices.resize(kept);
  for (auto& t : mesh.triangles)
    for (std::uint32_t& v : t)
      v = index[v];
  return dropped;
}

void removeTriangles(TriangleMesh& mesh, const std::vector<bool>& dropped) {
  std::size_t kept = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (!dropped[t]) mesh.triangles[kept++] = mesh.triangles[t];
  mesh.triangles.resize(kept);
  removeUnusedVertices(mesh);
}

TriangleMesh transformed(const TriangleMesh& mesh, const Mat4& dstFromSrc) {
  TriangleMesh out;
  out.vertices.reserve(mesh.vertices.size());
  for (const Vec3& p : mesh.vertices)
    out.vertices.push_back(transformPoint(dstFromSrc, p));
  const bool mirrors = dstFromSrc.topLeftCorner<3, 3>().determinant() < 0.0;
  out.triangles = mirrors ? flipped(mesh).triangles : mesh.triangles;
  return out;
}

TriangleMesh flipped(const TriangleMesh& mesh) {
  TriangleMesh out = mesh;
  for (auto& t : out.triangles)
    std::swap(t[1], t[2]);
  return out;
}

TriangleMesh subdivideMidpoint(const TriangleMesh& mesh) {
  TriangleMesh out;
  out.vertices = mesh.vertices;
  out.triangles.reserve(4 * mesh.triangles.size());
  // One midpoint per undirected edge, shared by the two triangles beside it.
  std::unordered_map<std::uint64_t, std::uint32_t> midpointOfEdge;
  midpointOfEdge.reserve(3 * mesh.triangles.size());
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
    auto [it, inserted] = midpointOfEdge.try_emplace(key, static_cast<std::uint32_t>(out.vertices.size()));
    if (inserted) out.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
    return it->second;
  };
  for (const auto& t : mesh.triangles) {
    const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

}  // namespace shapedb::core
