#include "support/mesh_files.h"

#include <algorithm>
#include <cstring>
#include <limits>
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

std::string colladaText(const core::TriangleMesh& mesh) {
  std::ostringstream out;
  out.precision(9);
  out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      << "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
      << "<asset><unit name=\"meter\" meter=\"1\"/><up_axis>Y_UP</up_axis></asset>\n"
      << "<library_geometries><geometry id=\"mesh\"><mesh>\n<source id=\"positions\">"
      << "<float_array id=\"xyz\" count=\"" << 3 * mesh.vertices.size() << "\">";
  for (const core::Vec3& p : mesh.vertices)
    out << p.x() << " " << p.y() << " " << p.z() << " ";
  out << "</float_array>\n<technique_common><accessor source=\"#xyz\" count=\"" << mesh.vertices.size()
      << "\" stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
      << "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
      << "<vertices id=\"vertices\"><input semantic=\"POSITION\" source=\"#positions\"/></vertices>\n"
      << "<triangles count=\"" << mesh.triangles.size()
      << "\"><input semantic=\"VERTEX\" source=\"#vertices\" offset=\"0\"/><p>";
  for (const auto& t : mesh.triangles)
    out << t[0] << " " << t[1] << " " << t[2] << " ";
  out << "</p></triangles>\n</mesh></geometry></library_geometries>\n"
      << "<library_visual_scenes><visual_scene id=\"scene\"><node id=\"node\">"
      << "<instance_geometry url=\"#mesh\"/></node></visual_scene></library_visual_scenes>\n"
      << "<scene><instance_visual_scene url=\"#scene\"/></scene>\n</COLLADA>\n";
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

tinygltf::Model gltfOf(const core::TriangleMesh& mesh) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "shapedb tests";
  tinygltf::Buffer buffer;
  tinygltf::Accessor positions;
  positions.bufferView = 0;
  positions.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  positions.type = TINYGLTF_TYPE_VEC3;
  positions.count = mesh.vertices.size();
  positions.minValues.assign(3, std::numeric_limits<double>::infinity());
  positions.maxValues.assign(3, -std::numeric_limits<double>::infinity());
  for (const core::Vec3& p : mesh.vertices)
    for (int c = 0; c < 3; ++c) {
      const float x = static_cast<float>(p[c]);
      const auto* bytes = reinterpret_cast<const unsigned char*>(&x);
      buffer.data.insert(buffer.data.end(), bytes, bytes + 4);
      positions.minValues[static_cast<std::size_t>(c)] =
          std::min<double>(positions.minValues[static_cast<std::size_t>(c)], x);
      positions.maxValues[static_cast<std::size_t>(c)] =
          std::max<double>(positions.maxValues[static_cast<std::size_t>(c)], x);
    }
  const std::size_t positionBytes = buffer.data.size();
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t v : t) {
      const auto* bytes = reinterpret_cast<const unsigned char*>(&v);
      buffer.data.insert(buffer.data.end(), bytes, bytes + 4);
    }
  tinygltf::BufferView positionView;
  positionView.buffer = 0;
  positionView.byteLength = positionBytes;
  positionView.target = TINYGLTF_TARGET_ARRAY_BUFFER;
  tinygltf::BufferView indexView;
  indexView.buffer = 0;
  indexView.byteOffset = positionBytes;
  indexView.byteLength = buffer.data.size() - positionBytes;
  indexView.target = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
  tinygltf::Accessor indices;
  indices.bufferView = 1;
  indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  indices.type = TINYGLTF_TYPE_SCALAR;
  indices.count = 3 * mesh.triangles.size();
  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = 0;
  primitive.indices = 1;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh gltfMesh;
  gltfMesh.primitives.push_back(primitive);
  tinygltf::Node node;
  node.mesh = 0;
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.buffers.push_back(std::move(buffer));
  model.bufferViews = {positionView, indexView};
  model.accessors = {positions, indices};
  model.meshes.push_back(gltfMesh);
  model.nodes.push_back(node);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  return model;
}

bool writeGltf(const tinygltf::Model& model, const std::filesystem::path& path, bool embedBuffers) {
  tinygltf::TinyGLTF writer;
  const bool binary = path.extension() == ".glb";
  return writer.WriteGltfSceneToFile(&model, path.string(), false, embedBuffers || binary, true, binary);
}

}  // namespace shapedb::test
