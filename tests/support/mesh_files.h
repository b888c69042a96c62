#pragma once

// Writers of mesh file contents for the formats shapedb only reads (OFF, STL, glTF) and for plain OBJ
// text, so that tests can make real files of every format, well-formed or deliberately not.

#include <cstdint>
#include <filesystem>
#include <string>
#include <tiny_gltf.h>

#include <shapedb/core/triangle_mesh.h>

namespace shapedb::test {

/// OBJ text: "v x y z" lines (17 digits), then "f a b c" lines (1-based).
std::string objText(const core::TriangleMesh& mesh);

/// The mesh as a triangle soup: every triangle with its own three corners, as STL files hold surfaces.
core::TriangleMesh soupOf(const core::TriangleMesh& mesh);
/// OFF text (17 digits).
std::string offText(const core::TriangleMesh& mesh);
/// ASCII STL (9 digits: single precision, as STL stores).
std::string asciiStl(const core::TriangleMesh& mesh);
/// Binary STL whose header claims `claimedCount` triangles (a lie when it differs from the mesh's).
std::string binaryStl(const core::TriangleMesh& mesh, std::uint32_t claimedCount);
std::string binaryStl(const core::TriangleMesh& mesh);

/// COLLADA text (.dae, 9 digits): the mesh as one geometry of triangles placed by one node, in metres,
/// Y up (as assimp reads it, unturned).
std::string colladaText(const core::TriangleMesh& mesh);

/// A glTF model of the mesh: one buffer (positions as floats, then indices as unsigned ints), one mesh of
/// one triangle primitive (accessor 0 its positions, 1 its indices), placed by one node in scene 0. Tests
/// change it (transforms, more nodes, broken accessors) before writing it. Made here, not by io's glTF
/// writer (saveMesh), so that the reader is tested on files that the code under test did not make.
tinygltf::Model gltfOf(const core::TriangleMesh& mesh);
/// Writes `model` with tinygltf's own writer: a .glb (binary, its first buffer inside), or a .gltf whose
/// buffers are embedded as data URIs or written beside it as .bin files. False where tinygltf fails.
bool writeGltf(const tinygltf::Model& model, const std::filesystem::path& path, bool embedBuffers = true);

}  // namespace shapedb::test
