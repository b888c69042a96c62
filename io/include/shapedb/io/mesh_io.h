#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/topology.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::io {

/// What loadMesh tolerates.
struct LoadOptions {
  /// Keep degenerate faces instead of failing: faces with a repeated vertex are dropped (and counted),
  /// zero-area faces with distinct vertices are kept (they contribute nothing to areas or volumes).
  bool allowDegenerateFaces = false;
  /// A closed, consistently oriented surface that encloses a negative volume (wound inward, as some
  /// exporters write) is flipped, and LoadedMesh::flippedInsideOut says so. An inconsistently oriented
  /// one is left as it is: no flip can fix it, and the stages that need a solid refuse it.
  bool orientOutward = true;
  /// Coordinates are multiplied by this as they are read (the file's unit in metres: unitScale("mm") is
  /// 0.001). Positive and finite.
  double scale = 1.0;
  /// A surface that is open as read has its coincident vertices welded (core::weldVertices), and the
  /// weld is kept if it closes edges: a triangle soup, or a mesh split along texture seams, becomes the
  /// surface it describes. A closed surface is never welded (two solids touching along an edge would
  /// become non-manifold).
  bool weld = true;
  /// Vertices closer than this fraction of the bounding box's diagonal are coincident; 0: exactly equal
  /// positions only.
  double weldTolerance = 0.0;
};

/// Metres per unit for "mm", "cm", "m", "in" and "ft"; nothing for any other name.
std::optional<double> unitScale(std::string_view unit);

/// A mesh read from a file, with what was learnt about it on the way in. Plain value type.
struct LoadedMesh {
  core::TriangleMesh mesh;
  core::TopologyReport topology;         ///< of `mesh` as returned
  core::MeshDefects defects;             ///< as read, before any face was dropped
  std::string format;                    ///< "obj", "ply", "off" or "stl"
  std::size_t polygonsTriangulated = 0;  ///< faces with more than three vertices, fan-triangulated
  std::size_t facesDropped = 0;          ///< repeated-vertex faces dropped under allowDegenerateFaces
  bool flippedInsideOut = false;         ///< wound inward as read, flipped (LoadOptions::orientOutward)
  std::size_t verticesWelded = 0;        ///< coincident vertices merged (LoadOptions::weld)
  std::size_t facesCollapsedByWeld = 0;  ///< triangles the weld left with a repeated corner, removed
  double scale = 1.0;                    ///< LoadOptions::scale, applied
  double signedVolumeAsRead = 0.0;       ///< of a closed, consistent surface as read (m³), else 0

  /// What a user should hear about the file's mesh ("the surface was wound inward ... flipped"), one
  /// sentence each; empty when it was read as it is.
  std::vector<std::string> notes() const;
};

/// Reads an OBJ, PLY (ASCII or binary), OFF or STL (ASCII or binary) file, chosen by extension
/// (case-insensitive): OBJ by shapedb's own reader (double precision; only `v` and `f` statements are
/// read, no other file is opened), the others through OpenMesh (single precision, as its readers parse).
/// Polygons are fan-triangulated; vertices are kept as the file has them
/// (STL's duplicated corners are merged by OpenMesh's reader). Every error names the file:
/// "part.stl: truncated binary STL (header says 12 triangles, file holds 3)". Errors: kIo, kUnknownFormat,
/// kParse, kEmptyMesh, kNonFinite, kIndexOutOfRange, kDegenerateFace. Thread-safe.
Result<LoadedMesh> loadMesh(const std::filesystem::path& path, const LoadOptions& options = {});

/// The mesh files (.obj, .ply, .off, .stl, any case) in `directory` and its subdirectories, sorted by
/// path.
/// Errors: kIo (not a directory, unreadable, or no mesh file in it), naming the directory.
Result<std::vector<std::filesystem::path>> listMeshFiles(const std::filesystem::path& directory);

/// What saveMesh writes.
struct SaveOptions {
  bool binary = true;  ///< PLY only: binary little-endian (exact doubles) rather than ASCII
};

/// Writes an OBJ or PLY file through OpenMesh, chosen by extension. OpenMesh's readers parse single
/// precision, so a mesh read back matches to float precision (~6e-8 relative). Errors: kUnknownFormat,
/// kIo, kInvalidArgument (a mesh that fails validateMesh, or a non-manifold one, which OpenMesh's
/// kernel cannot hold). Thread-safe.
Status saveMesh(const core::TriangleMesh& mesh, const std::filesystem::path& path,
                const SaveOptions& options = {});

}  // namespace shapedb::io
