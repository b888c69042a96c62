#pragma once

// glTF 2.0 (.gltf with its buffers, or one .glb), the format game engines and DCC tools exchange props
// in, read (and written) through tinygltf (Debian's libtinygltf). tinygltf parses the JSON and loads the
// buffers; the geometry is read here, every accessor checked against the bytes of its buffer before it is
// read.

#include <cstddef>
#include <filesystem>

#include <shapedb/core/result.h>

#include "raw_polygons.h"

namespace shapedb::io::detail {

/// What a glTF file held besides the triangles read, for LoadedMesh's notes.
struct GltfReport {
  std::size_t meshInstances = 0;      ///< meshes placed by the scene's nodes (one mesh may be placed twice)
  std::size_t primitivesSkipped = 0;  ///< point and line primitives: no surface
  std::size_t skinnedInstances = 0;   ///< skinned meshes, read in their bind pose
};

/// The triangles of a glTF file's scene in metres, glTF's unit: every mesh its nodes place, through the
/// node hierarchy's transforms (a mirroring transform's triangles rewound so that they keep their
/// orientation), the default scene (else the first; else every root node; else every mesh as it is).
/// Triangles, strips and fans are read (a strip's or fan's triangles with a repeated vertex, its joins,
/// are left out); points and lines are skipped and counted. Each primitive's vertices are its own, once a
/// node, except that primitives sharing one POSITION accessor share its vertices; loadMesh welds a
/// surface split into primitives (by material, say) along its seams. Positions of any component type
/// (KHR_mesh_quantization), sparse accessors and an accessor without a buffer view (zeros) are read as
/// glTF defines them. External buffers are read only as regular files; images are never decoded.
/// Errors (naming the file): kParse (tinygltf's message; a compressed mesh, KHR_draco_mesh_compression or
/// EXT_meshopt_compression, or GPU instancing, which are not decoded; an accessor that does not fit its
/// buffer; a node cycle), kIndexOutOfRange, kNonFinite, kEmptyMesh (no triangle in the scene).
Result<RawPolygons> readGltf(const std::filesystem::path& path, GltfReport* report = nullptr);

/// Writes `mesh` as glTF 2.0 through tinygltf's writer: a .glb, or a .gltf with its buffer embedded (one
/// self-contained file either way). One mesh of one primitive (float positions, unsigned int indices)
/// placed by one node whose translation, in double precision, is the mesh's bounding-box centre: the
/// positions are stored about it, so that a fragment far from the origin keeps single precision's
/// resolution at its own size (about 6e-8 of it), not at its distance. Errors: kIo.
Status writeGltf(const core::TriangleMesh& mesh, const std::filesystem::path& path);

}  // namespace shapedb::io::detail
