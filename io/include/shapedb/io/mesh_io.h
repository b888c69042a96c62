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
  /// exporters write) is flipped, and LoadedMesh::flippedInsideOut says so; so is each of its shells that
  /// is wound inward with no material around it (LoadedMesh::shellsTurnedOutward). An inconsistently
  /// oriented one is left as it is: no flip can fix it, and the stages that need a solid refuse it.
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
  /// A surface of several parts (edge-connected components) loses those whose area is under
  /// kSpeckAreaShare of the largest's: the floating specks a scan picks up, open or closed, which would
  /// otherwise leave the surface open or make it several solids. LoadedMesh::specksDropped says so.
  bool dropSpecks = true;
  /// Bytes the mesh may need. Before a file is read whole, its size is read from its header (OBJ and
  /// ASCII STL: its lines counted in one streamed pass, when the file is over 16 MiB) and the memory a
  /// query on it needs is estimated (estimateMeshMemory); a file whose estimate exceeds this is refused
  /// (kTooLarge), the estimate in the message. Nothing: the memory this process can still have
  /// (availableMemory(), read at the call); 0: no check.
  std::optional<std::uint64_t> memoryBudget{};
};

/// What a mesh file holds, as its header says (or its lines, counted), before it is read whole.
struct MeshFileSize {
  std::uint64_t triangles = 0;  ///< faces (polygons count once: a lower bound of the triangles)
  std::uint64_t vertices = 0;
  /// The peak memory of loading the file and querying a database with it, fidelity report included
  /// (the largest step: a closest-point tree of the mesh), from measurements: 120 bytes a triangle and
  /// 48 a vertex (a 10-million-triangle closed scan peaked at 1.46 GB).
  std::uint64_t bytes() const { return 120 * triangles + 48 * vertices; }
};

/// The size of the mesh in `path`, from its header: PLY's and OFF's element counts (capped by what the
/// file's bytes can hold, so a corrupt count does not pass for a huge mesh), binary STL's triangle count;
/// OBJ's `v` and `f` lines and ASCII STL's facets counted in one streamed pass, for files over 16 MiB
/// (smaller ones: zero, not worth a pass); glTF's accessor counts, over the meshes its nodes place (a
/// mesh placed twice counts twice); FBX and COLLADA: zero (assimp alone parses them, in a worker whose
/// count loadMesh checks before the mesh is read in). Errors: kIo, kUnknownFormat.
Result<MeshFileSize> estimateMeshFile(const std::filesystem::path& path);

/// The memory this process can still allocate: the least of the system's available memory
/// (/proc/meminfo's MemAvailable), its control group's limit less its use, and its address-space limit
/// less its size. Nothing where none of these can be read.
std::optional<std::uint64_t> availableMemory();

/// Metres per unit for "mm", "cm", "m", "in" and "ft"; nothing for any other name.
std::optional<double> unitScale(std::string_view unit);

/// loadMesh tells a cavity from an inside-out solid for surfaces of up to this many shells wound inward
/// (each is a pass over the rest of the surface: a scan of thousands of specks is read as it is).
inline constexpr std::size_t kMaxShellsChecked = 64;

/// LoadOptions::dropSpecks: a part of a surface under this share of its largest part's area is a speck.
/// A closed speck at this share of the area holds about 3e-5 of the volume (the share to the power 3/2,
/// for shapes alike), well within what a mesh's tessellation moves.
inline constexpr double kSpeckAreaShare = 1e-3;

/// A mesh read from a file, with what was learnt about it on the way in. Plain value type.
struct LoadedMesh {
  core::TriangleMesh mesh;
  core::TopologyReport topology;         ///< of `mesh` as returned
  core::MeshDefects defects;             ///< as read, before any face was dropped
  std::string format;                    ///< "obj", "ply", "off", "stl", "gltf", "glb", "fbx" or "dae"
  std::size_t polygonsTriangulated = 0;  ///< faces with more than three vertices, fan-triangulated
  std::size_t meshInstances = 0;         ///< glTF, FBX, COLLADA: meshes the scene's nodes place (else 0)
  std::size_t primitivesSkipped = 0;     ///< glTF, FBX, COLLADA: point and line primitives, skipped
  /// FBX: the file's unit in metres (its UnitScaleFactor over 100; FBX's default unit is the
  /// centimetre), applied as it was read, before `scale`; 1 for other formats.
  double fileUnit = 1.0;
  std::size_t skinnedInstances = 0;  ///< glTF: skinned meshes, read in their bind pose
  std::size_t facesDropped = 0;      ///< repeated-vertex faces dropped under allowDegenerateFaces
  bool flippedInsideOut = false;     ///< wound inward as read, flipped (LoadOptions::orientOutward)
  /// Shells wound inward with no material around them (not cavities: inside-out solids of their own),
  /// turned outward (LoadOptions::orientOutward; surfaces of up to kMaxShellsChecked such shells).
  std::size_t shellsTurnedOutward = 0;
  std::size_t verticesWelded = 0;        ///< coincident vertices merged (LoadOptions::weld)
  std::size_t facesCollapsedByWeld = 0;  ///< triangles the weld left with a repeated corner, removed
  /// Zero-area faces of a closed surface flipped away (core::flipZeroAreaFaces), unless
  /// allowDegenerateFaces keeps them: a surface with any left is refused as before.
  std::size_t zeroAreaFacesFlipped = 0;
  std::size_t specksDropped = 0;    ///< parts under kSpeckAreaShare of the largest's area, dropped
  double specksAreaShare = 0.0;     ///< their share of the surface's area as read
  double specksVolumeShare = 0.0;   ///< the share of the volume their closed ones held (0: none closed)
  double scale = 1.0;               ///< LoadOptions::scale, applied
  double signedVolumeAsRead = 0.0;  ///< of a closed, consistent surface as read (m³), else 0

  /// What a user should hear about the file's mesh ("the surface was wound inward ... flipped"), one
  /// sentence each; empty when it was read as it is.
  std::vector<std::string> notes() const;
};

/// Reads an OBJ, PLY (ASCII or binary), OFF, STL (ASCII or binary), glTF 2.0 (.gltf with its buffers,
/// or .glb), FBX (binary or ASCII) or COLLADA (.dae) file, chosen by extension (case-insensitive): OBJ,
/// PLY and OFF by shapedb's own readers (double precision; of OBJ, only `v` and `f` statements are read,
/// no other file is opened), STL through OpenMesh's (single precision), glTF through tinygltf: the
/// default scene's meshes placed by their nodes, in metres, as one surface (see
/// LoadedMesh::meshInstances; a surface split into primitives is welded along its seams). FBX and
/// COLLADA likewise, through assimp in a worker process that a malformed file cannot take this one down
/// with (single precision; FBX's unit applied, LoadedMesh::fileUnit; assimp turns a COLLADA scene
/// whose up axis is Z to Y up).
/// Polygons are fan-triangulated; vertices are kept as the file has them (STL's duplicated corners are
/// merged by OpenMesh's reader). A file too large for the memory there is, by its header, is refused
/// before it is read (LoadOptions::memoryBudget). Every error names the file:
/// "part.stl: truncated binary STL (header says 12 triangles, file holds 3)". Errors: kIo, kUnknownFormat,
/// kParse, kEmptyMesh, kNonFinite, kIndexOutOfRange, kDegenerateFace, kTooLarge (LoadOptions::memoryBudget).
/// Thread-safe.
Result<LoadedMesh> loadMesh(const std::filesystem::path& path, const LoadOptions& options = {});

/// The mesh files (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae, any case) in `directory` and its
/// subdirectories, sorted by path. Errors: kIo (not a directory, unreadable, or no mesh file in it), naming
/// the directory.
Result<std::vector<std::filesystem::path>> listMeshFiles(const std::filesystem::path& directory);

/// What saveMesh writes.
struct SaveOptions {
  bool binary = true;  ///< PLY only: binary little-endian rather than ASCII (both exact)
};

/// Writes an OBJ or PLY file, chosen by extension, in double precision (OBJ: 17 significant digits; PLY:
/// double properties), so that loadMesh reads back exactly the vertices written; or a glTF file (.glb,
/// or .gltf with its buffer embedded) for game engines, in glTF's single precision about the mesh's
/// centre (loadMesh reads back the vertices within about 6e-8 of the mesh's size, wherever it lies).
/// Errors: kUnknownFormat, kIo, kInvalidArgument (a mesh that fails validateMesh). Thread-safe.
Status saveMesh(const core::TriangleMesh& mesh, const std::filesystem::path& path,
                const SaveOptions& options = {});

}  // namespace shapedb::io
