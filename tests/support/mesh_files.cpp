#include "support/mesh_files.h"

#include <sstream>

namespace shapedb::test {

core::TriangleMesh soupOf(const core::TriangleMesh& mesh) {
  core::TriangleMesh out;
  for (const auto& t : mesh.triangles) {
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    for (const std::uint32_t v : t)
      out.vertices.push_back(mesh.vertices[v]);
    out.triangles.push_back({base, base + 1, base + 2});
  }
  return out;
}

std::string objText(const core::TriangleMesh& mesh) {
  std::ostringstream out;
  out.precision(17);
  for (const core::Vec3& p : mesh.vertices)
    out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& t : mesh.triangles)
    out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  return out.str();
}

std::string offText(const core::TriangleMesh& mesh) {
  std::ostringstream out;
  out.precision(17);
  out << "OFF\n" << mesh.vertices.size() << " " << mesh.triangles.size() << " 0\n";
  for (const core::Vec3& p : mesh.vertices)
    out << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& t : mesh.triangles)
    out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return out.str();
}

std::string asciiStl(const core::TriangleMesh& mesh) {
  std::ostringstream out;
  out.precision(9);
  out << "solid test\n";
  for (const auto& t : mesh.triangles) {
    out << "facet normal 0 0 0\nouter loop\n";
    for (auto v : t)
      out << "vertex " << mesh.vertices[v].x() << " " << mesh.vertices[v].y() << " " << mesh.vertices[v].z()
          << "\n";
    out << "endloop\nendfacet\n";
  }
  out << "endsolid test\n";
  return out.str();
}

std::string binaryStl(const core::TriangleMesh& mesh, std::uint32_t claimedCount) {
  std::string out(80, ' ');
  out.append(reinterpret_cast<const char*>(&claimedCount), 4);
  for (const auto& t : mesh.triangles) {
    float record[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c)
        record[3 + 3 * k + c] = static_cast<float>(mesh.vertices[t[k]][c]);
    out.append(reinterpret_cast<const char*>(record), sizeof record);
    out.append(2, '\0');
  }
  return out;
}

std::string binaryStl(const core::TriangleMesh& mesh) {
  return binaryStl(mesh, static_cast<std::uint32_t>(mesh.triangles.size()));
}

}  // namespace shapedb::test
