#pragma once

// Writers of mesh file contents for the formats shapedb only reads (OFF, STL) and for plain OBJ text,
// so that tests can make real files of every format, well-formed or deliberately not.

#include <cstdint>
#include <string>

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

}  // namespace shapedb::test
