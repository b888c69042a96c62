#pragma once

// FBX and COLLADA, the formats game engines and modelling tools exchange props in beside glTF, read
// through the Open Asset Import Library (assimp; Debian's libassimp5). assimp is a large parser of many
// formats, and a malformed file can crash it, so it never runs in this process: a child process loads
// it (dlopen, at run time) and reads the file, and sends the triangles back through a pipe. A crash, a
// hang or a mesh too large for the memory there is costs that one file, with an error that names it.
// Loaded in a child only, assimp's own copy of libdraco (which carries tinygltf's symbols) never meets
// the glTF reader of this process.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>

#include <shapedb/core/result.h>

#include "raw_polygons.h"

namespace shapedb::io::detail {

/// What an FBX or COLLADA file held besides the triangles read, for LoadedMesh's notes.
struct AssimpReport {
  std::size_t meshInstances = 0;      ///< meshes placed by the scene's nodes (one mesh may be placed twice)
  std::size_t primitivesSkipped = 0;  ///< point and line meshes, and faces of fewer than three corners
  /// FBX: the file's unit in metres (its UnitScaleFactor over 100: 0.01 for centimetres, FBX's default),
  /// applied to the coordinates; COLLADA: 1 (assimp applies its <unit> in the scene's root transform).
  double unit = 1.0;
};

/// How long a file may take to be read before its worker is stopped.
inline constexpr double kAssimpTimeoutSeconds = 600.0;

/// The triangles of an FBX (.fbx, binary or ASCII) or COLLADA (.dae) file's scene, in metres: every mesh
/// its nodes place, through the node hierarchy's transforms (a mirroring transform's triangles rewound
/// so that they keep their orientation), in single precision as assimp holds them. Polygons are
/// triangulated by assimp; point and line meshes are skipped and counted. Each placed mesh's vertices
/// are its own; loadMesh welds a surface split along its seams. The library is libassimp.so.5, or the
/// one the environment variable SHAPEDB_ASSIMP names. A mesh whose vertices and triangles would need
/// more than `memoryBudget` bytes (MeshFileSize::bytes; nothing: no check) is refused before it is read
/// into this process. Errors (naming the file): kParse (assimp's message; assimp crashed, or stopped
/// after kAssimpTimeoutSeconds), kIo (assimp is not installed, or the worker could not start), kNonFinite,
/// kEmptyMesh (no triangle in the scene, or no mesh: not the skeleton assimp makes up for it), kTooLarge.
Result<RawPolygons> readWithAssimp(const std::filesystem::path& path,
                                   const std::optional<std::uint64_t>& memoryBudget,
                                   AssimpReport* report = nullptr);

}  // namespace shapedb::io::detail
