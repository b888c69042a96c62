#pragma once

// Writing OBJ text, in double precision: one writer for the mesh files (io_mesh) and the exported tets and
// collision parts (io_media), which link no library in common but core.

#include <cstddef>
#include <cstdio>
#include <ostream>
#include <string>

#include <shapedb/core/triangle_mesh.h>

namespace shapedb::io::detail {

/// Writes `mesh` as OBJ vertices and faces, its vertex indices offset by `base` (the vertices written
/// before it in the same file), under `o name` if a name is given. 17 significant digits round-trip a
/// double: a vertex reads back exactly as it was.
inline void writeObjPart(std::ostream& out, const core::TriangleMesh& mesh, std::size_t base = 0,
                         const std::string& name = {}) {
  if (!name.empty()) out << "o " << name << '\n';
  char line[96];
  for (const core::Vec3& p : mesh.vertices) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    out << line;
  }
  for (const auto& t : mesh.triangles)
    out << "f " << t[0] + base + 1 << ' ' << t[1] + base + 1 << ' ' << t[2] + base + 1 << '\n';
}

}  // namespace shapedb::io::detail
