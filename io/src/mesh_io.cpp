#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <utility>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <shapedb/core/spatial.h>
#include <shapedb/core/topology.h>
#include <shapedb/core/weld.h>
#include <shapedb/io/mesh_io.h>

#include "assimp_reader.h"
#include "gltf_reader.h"
#include "mesh_format.h"
#include "obj_writer.h"
#include "openmesh_adapters.h"
#include "text_mesh_readers.h"

namespace shapedb::io {
namespace {

// OpenMesh's readers keep per-reader state and log through global streams: one call at a time, silenced.
std::mutex& openMeshMutex() {
  static std::mutex mutex;
  static std::once_flag silenced;
  std::call_once(silenced, [] {
    omlog().disable();
    omout().disable();
    omerr().disable();
  });
  return mutex;
}

Error fileError(const std::filesystem::path& path, ErrorCode code, const std::string& message) {
  return Error{code, path.string() + ": " + message};
}

// Binary STL is a header, a triangle count and 50 bytes per triangle. OpenMesh trusts the count, so a
// truncated file or a lying count is caught here first. ASCII STL starts with "solid"; so do the headers
// of many binary ones (SolidWorks writes "solid NAME" there), whose count and first triangle then hold bytes
// no text has.
Status checkStlFraming(const std::filesystem::path& path, std::uintmax_t fileSize) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 134> header{};  // the header, the count and the first triangle of a binary file
  in.read(header.data(), header.size());
  const auto got = static_cast<std::size_t>(in.gcount());
  std::string start(header.data(), std::min<std::size_t>(got, 80));
  start.erase(0, start.find_first_not_of(" \t\r\n"));
  const bool text =
      std::all_of(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(got), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return u >= 0x20 || u == '\t' || u == '\n' || u == '\r';
      });
  if (got >= 84) {
    std::uint32_t claimed = 0;
    std::memcpy(&claimed, header.data() + 80, sizeof claimed);  // little-endian on every target we build
    if (84 + 50 * std::uintmax_t{claimed} == fileSize) return Ok{};
    if (start.rfind("solid", 0) == 0 && text) return Ok{};
    return fileError(path, ErrorCode::kParse,
                     "truncated or corrupt binary STL (header says " + std::to_string(claimed) +
                         " triangles, file holds " + std::to_string((fileSize - 84) / 50) + ")");
  }
  if (start.rfind("solid", 0) == 0) return Ok{};
  return fileError(path, ErrorCode::kParse, "not an STL file (too short for binary, no 'solid' for ASCII)");
}

std::string formatBytes(std::uint64_t bytes) {
  char text[32];
  if (bytes >= (std::uint64_t{1} << 30))
    std::snprintf(text, sizeof text, "%.2f GiB", static_cast<double>(bytes) / (1u << 30));
  else
    std::snprintf(text, sizeof text, "%.0f MiB", static_cast<double>(bytes) / (1u << 20));
  return text;
}

// The file's mesh against the memory there is (LoadOptions::memoryBudget), before it is read. A file
// under 1 MiB holds at most about 260,000 faces (some 40 MB once loaded and queried): not checked, unless
// it is a glTF file, whose buffers may be other files and whose nodes may place a mesh many times.
Status checkFits(const std::filesystem::path& path, std::uintmax_t fileSize, const std::string& format,
                 const std::optional<std::uint64_t>& memoryBudget) {
  if ((fileSize < (1u << 20) && !detail::isGltf(format)) || memoryBudget == std::uint64_t{0}) return Ok{};
  const std::optional<std::uint64_t> budget = memoryBudget ? memoryBudget : availableMemory();
  if (!budget) return Ok{};
  const Result<MeshFileSize> size = estimateMeshFile(path);
  if (!size || size->bytes() <= *budget) return Ok{};  // unreadable: the reader will say why
  return fileError(
      path, ErrorCode::kTooLarge,
      "a mesh of " + std::to_string(size->triangles) + " faces and " + std::to_string(size->vertices) +
          " vertices needs about " + formatBytes(size->bytes()) + " to be loaded and queried, and " +
          formatBytes(*budget) +
          " is available: not read (a machine with more memory, or the mesh simplified, will do)");
}

// Polygons fan-triangulated; polygons with fewer than three corners counted.
struct Triangulated {
  core::TriangleMesh mesh;
  std::size_t polygons = 0;
  std::size_t tooFewCorners = 0;
  std::size_t firstTooFew = 0;
};

Triangulated triangulate(detail::RawPolygons&& raw) {
  Triangulated out;
  out.mesh.vertices = std::move(raw.vertices);
  out.mesh.triangles.reserve(raw.polygonCount());
  for (std::size_t f = 0; f < raw.polygonCount(); ++f) {
    const std::uint32_t* polygon = raw.corners.data() + raw.begin(f);
    const std::size_t corners = raw.ends[f] - raw.begin(f);
    if (corners < 3) {
      if (out.tooFewCorners++ == 0) out.firstTooFew = f;
      continue;
    }
    if (corners > 3) ++out.polygons;
    for (std::size_t i = 1; i + 1 < corners; ++i)
      out.mesh.triangles.push_back({polygon[0], polygon[i], polygon[i + 1]});
  }
  return out;
}

// Whether the triangles `part` of `mesh` are closed among themselves: every edge in two of them.
bool isClosedPart(const core::TriangleMesh& mesh, const std::vector<std::uint32_t>& part) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const std::uint32_t t : part)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.triangles[t][static_cast<std::size_t>(k)];
      const std::uint32_t b = mesh.triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      ++edges[std::minmax(a, b)];
    }
  return std::all_of(edges.begin(), edges.end(), [](const auto& edge) { return edge.second == 2; });
}

// LoadOptions::dropSpecks: the parts under kSpeckAreaShare of the largest's area are dropped, with the
// vertices only they used; the rest keep their order.
void dropSpecks(LoadedMesh& loaded) {
  core::TriangleMesh& mesh = loaded.mesh;
  const std::vector<core::Shell> parts = core::findShells(mesh);
  std::vector<double> areas(parts.size(), 0.0);
  for (std::size_t i = 0; i < parts.size(); ++i)
    for (const std::uint32_t t : parts[i].triangles) {
      const auto& [a, b, c] = mesh.triangles[t];
      areas[i] +=
          0.5 * (mesh.vertices[b] - mesh.vertices[a]).cross(mesh.vertices[c] - mesh.vertices[a]).norm();
    }
  const double largest = *std::max_element(areas.begin(), areas.end());
  double total = 0.0, droppedArea = 0.0, droppedVolume = 0.0, keptVolume = 0.0;
  std::vector<bool> dropped(mesh.triangles.size(), false);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    total += areas[i];
    if (areas[i] >= kSpeckAreaShare * largest) {
      keptVolume += parts[i].volume;
      continue;
    }
    ++loaded.specksDropped;
    droppedArea += areas[i];
    if (isClosedPart(mesh, parts[i].triangles)) droppedVolume += std::abs(parts[i].volume);
    for (const std::uint32_t t : parts[i].triangles)
      dropped[t] = true;
  }
  if (loaded.specksDropped == 0) return;

  core::removeTriangles(mesh, dropped);
  loaded.topology = core::analyzeTopology(mesh);
  loaded.specksAreaShare = droppedArea / total;
  // Of the volume, where what is kept bounds one (its shells' signed volumes sum to it).
  if (loaded.topology.isClosed() && droppedVolume > 0.0)
    loaded.specksVolumeShare = droppedVolume / (std::abs(keptVolume) + droppedVolume);
}

// STL through OpenMesh's reader, once checkStlFraming has checked the file's size against its count.
// (OBJ, OFF and PLY have shapedb's own readers: text_mesh_readers.h says why.)
Result<detail::RawPolygons> readStl(const std::filesystem::path& path) {
  // No OpenMesh exception crosses this function.
  detail::RawImporter importer;
  bool parsed = false;
  {
    std::lock_guard lock(openMeshMutex());
    try {
      OpenMesh::IO::Options readOptions;
      parsed = OpenMesh::IO::IOManager().read(path.string(), importer, readOptions);
    } catch (const std::exception& e) {
      return fileError(path, ErrorCode::kParse, std::string("parse error: ") + e.what());
    } catch (...) {
      return fileError(path, ErrorCode::kParse, "parse error");
    }
  }
  if (!parsed) return fileError(path, ErrorCode::kParse, "could not parse as STL");
  return std::move(importer.raw);
}

// shapedb's own writers, in double precision: OpenMesh's write every coordinate as a float (its OBJ
// writer converts the points, its PLY writer declares float properties), which moved a fragment's vertices
// by up to 6e-8 of their coordinates, more than a micrometre on a scan hundreds of metres from the origin.
// 17 significant digits round-trip a double.
void writeObj(const core::TriangleMesh& mesh, std::ostream& out) {
  char line[96];
  std::snprintf(line, sizeof line, "# %zu vertices, %zu faces\n", mesh.vertices.size(),
                mesh.triangles.size());
  out << line;
  detail::writeObjPart(out, mesh);
}

/// PLY with double coordinates and int indices; binary little-endian or ASCII.
void writePly(const core::TriangleMesh& mesh, bool binary, std::ostream& out) {
  static_assert(std::endian::native == std::endian::little, "the binary PLY writer writes native bytes");
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\ncomment shapedb\n"
      << "element vertex " << mesh.vertices.size()
      << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element face " << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  char line[96];
  for (const core::Vec3& p : mesh.vertices) {
    if (binary) {
      out.write(reinterpret_cast<const char*>(p.data()), 3 * sizeof(double));
    } else {
      std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
      out << line;
    }
  }
  for (const auto& t : mesh.triangles) {
    if (binary) {
      const unsigned char three = 3;
      const std::array<std::int32_t, 3> face{static_cast<std::int32_t>(t[0]), static_cast<std::int32_t>(t[1]),
                                             static_cast<std::int32_t>(t[2])};
      out.write(reinterpret_cast<const char*>(&three), 1);
      out.write(reinterpret_cast<const char*>(face.data()), sizeof face);
    } else {
      out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    }
  }
}

}  // namespace

Result<std::vector<std::filesystem::path>> listMeshFiles(const std::filesystem::path& directory) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(directory, ec))
    return Error{ErrorCode::kIo, directory.string() + ": not a directory"};
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(directory, ec)) {
    if (entry.is_regular_file() && detail::isMeshFormat(detail::lowercaseExtension(entry.path())))
      files.push_back(entry.path());
  }
  if (ec) return Error{ErrorCode::kIo, directory.string() + ": " + ec.message()};
  if (files.empty())
    return Error{ErrorCode::kIo,
                 directory.string() + ": no mesh files (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)"};
  std::sort(files.begin(), files.end());
  return files;
}

Result<LoadedMesh> loadMesh(const std::filesystem::path& path, const LoadOptions& options) {
  // Format by extension, then the file itself.
  const std::string format = detail::lowercaseExtension(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    return fileError(path, ErrorCode::kIo, "is a directory, not a mesh file");
  if (!detail::isMeshFormat(format))
    return fileError(path, ErrorCode::kUnknownFormat,
                     "unknown mesh format '" + path.extension().string() +
                         "' (expected .obj, .ply, .off, .stl, .gltf, .glb, .fbx or .dae)");
  if (!std::filesystem::is_regular_file(path, ec))
    return fileError(path, ErrorCode::kIo,
                     std::filesystem::exists(path, ec) ? "not a regular file" : "no such file");
  const std::uintmax_t fileSize = std::filesystem::file_size(path, ec);
  if (ec || !std::ifstream(path, std::ios::binary))
    return fileError(path, ErrorCode::kIo, "cannot read file");
  if (fileSize == 0) return fileError(path, ErrorCode::kParse, "file is empty");
  if (format == "stl") {
    if (Status framing = checkStlFraming(path, fileSize); !framing) return framing.error();
  }
  if (Status fits = checkFits(path, fileSize, format, options.memoryBudget); !fits) return fits.error();
  detail::GltfReport gltf;
  detail::AssimpReport assimp;
  const auto assimpBudget = [&]() -> std::optional<std::uint64_t> {
    if (options.memoryBudget == std::uint64_t{0}) return std::nullopt;
    return options.memoryBudget ? options.memoryBudget : availableMemory();
  };
  Result<detail::RawPolygons> raw = format == "obj"          ? detail::readObj(path)
                                    : format == "off"        ? detail::readOff(path)
                                    : format == "ply"        ? detail::readPly(path)
                                    : detail::isGltf(format) ? detail::readGltf(path, &gltf)
                                    : detail::isAssimpFormat(format)
                                        ? detail::readWithAssimp(path, assimpBudget(), &assimp)
                                        : readStl(path);
  if (!raw) return raw.error();

  if (!(options.scale > 0.0 && std::isfinite(options.scale)))
    return fileError(path, ErrorCode::kInvalidArgument, "the scale must be positive and finite");
  if (!(options.weldTolerance >= 0.0 && options.weldTolerance < 1.0))
    return fileError(path, ErrorCode::kInvalidArgument, "the weld tolerance must be a fraction in [0, 1)");
  if (options.scale != 1.0)
    for (core::Vec3& p : raw->vertices)
      p *= options.scale;

  // Triangulate, then validate what was read.
  Triangulated tri = triangulate(std::move(raw).value());
  if (tri.tooFewCorners > 0 && !options.allowDegenerateFaces)
    return fileError(path, ErrorCode::kDegenerateFace,
                     std::to_string(tri.tooFewCorners) + (tri.tooFewCorners == 1 ? " face" : " faces") +
                         " with fewer than 3 vertices (first: face " + std::to_string(tri.firstTooFew) + ")");
  LoadedMesh out;
  out.mesh = std::move(tri.mesh);
  out.format = format;
  out.polygonsTriangulated = tri.polygons;
  out.meshInstances = gltf.meshInstances + assimp.meshInstances;
  out.primitivesSkipped = gltf.primitivesSkipped + assimp.primitivesSkipped;
  out.fileUnit = assimp.unit;
  out.skinnedInstances = gltf.skinnedInstances;
  out.facesDropped = tri.tooFewCorners;
  out.defects = core::findDefects(out.mesh);
  // Zero-area faces with distinct corners alone (a T-junction's filler) are flipped away below once the
  // surface is known to be closed, and checked after that.
  const bool zeroAreaOnly =
      !options.allowDegenerateFaces && out.defects.zeroAreaFaces > 0 && out.defects.repeatedVertexFaces == 0;
  core::MeshDefects checked = out.defects;
  if (zeroAreaOnly) checked.zeroAreaFaces = 0;
  if (Status valid = core::checkDefects(checked, {.allowDegenerateFaces = options.allowDegenerateFaces});
      !valid)
    return withContext(valid.error(), path.string());
  if (options.allowDegenerateFaces) {
    out.facesDropped += core::removeRepeatedVertexFaces(out.mesh);
    if (out.mesh.triangles.empty())
      return fileError(path, ErrorCode::kEmptyMesh, "mesh has no faces once degenerate faces are dropped");
  }
  out.scale = options.scale;
  out.topology = core::analyzeTopology(out.mesh);
  if (options.weld && !out.topology.isClosed()) {
    const core::Bounds bounds = core::computeBounds(out.mesh);
    core::TriangleMesh welded = out.mesh;
    const core::WeldReport weld = core::weldVertices(
        welded,
        options.weldTolerance == 0.0 ? 0.0 : options.weldTolerance * (bounds.max - bounds.min).stableNorm());
    const core::TopologyReport after = core::analyzeTopology(welded);
    if (!welded.triangles.empty() && after.boundaryEdges + after.nonManifoldEdges <
                                         out.topology.boundaryEdges + out.topology.nonManifoldEdges) {
      out.mesh = std::move(welded);
      out.topology = after;
      out.verticesWelded = weld.verticesMerged;
      out.facesCollapsedByWeld = weld.facesCollapsed;
    }
  }
  if (options.dropSpecks && out.topology.components > 1) dropSpecks(out);
  if (zeroAreaOnly) {
    if (out.topology.isClosed() && out.topology.isConsistentlyOriented()) {
      out.zeroAreaFacesFlipped = core::flipZeroAreaFaces(out.mesh);
      out.topology = core::analyzeTopology(out.mesh);
    }
    if (Status valid = core::validateMesh(out.mesh); !valid) return withContext(valid.error(), path.string());
  }
  if (out.topology.isClosed() && out.topology.isConsistentlyOriented()) {
    out.signedVolumeAsRead = core::computeSignedVolume(out.mesh);
    if (options.orientOutward && out.signedVolumeAsRead < 0.0) {
      for (auto& t : out.mesh.triangles)
        std::swap(t[1], t[2]);
      out.flippedInsideOut = true;
    }
    // A shell wound inward is a cavity where the rest of the surface has material around it (winding
    // number 1 there) and an inside-out solid where it has none (0: apart from every solid, or loose in
    // another's cavity): such a shell is turned outward as well. A shell wound outward inside another solid
    // is left as it is (a cavity wound the wrong way, or an insert of another material: no telling).
    if (options.orientOutward && out.topology.components > 1) {
      const std::vector<core::Shell> shells = core::findShells(out.mesh);
      if (core::countShells(shells).cavities <= kMaxShellsChecked) {
        std::vector<std::uint32_t> turn;
        for (std::size_t i = 0; i < shells.size(); ++i) {
          if (!shells[i].cavity) continue;  // wound inward: the surface is outward now
          core::TriangleMesh others;
          others.vertices = out.mesh.vertices;
          for (std::size_t j = 0; j < shells.size(); ++j)
            if (j != i)
              for (std::uint32_t t : shells[j].triangles)
                others.triangles.push_back(out.mesh.triangles[t]);
          const core::Vec3& p = out.mesh.vertices[out.mesh.triangles[shells[i].triangles.front()][0]];
          if (core::windingNumber(others, p) >= 0.5) continue;  // a cavity
          turn.insert(turn.end(), shells[i].triangles.begin(), shells[i].triangles.end());
          ++out.shellsTurnedOutward;
        }
        for (std::uint32_t t : turn)
          std::swap(out.mesh.triangles[t][1], out.mesh.triangles[t][2]);
      }
    }
  }
  return out;
}

std::optional<double> unitScale(std::string_view unit) {
  if (unit == "mm") return 0.001;
  if (unit == "cm") return 0.01;
  if (unit == "m") return 1.0;
  if (unit == "in") return 0.0254;
  if (unit == "ft") return 0.3048;
  return std::nullopt;
}

std::vector<std::string> LoadedMesh::notes() const {
  std::vector<std::string> out;
  if (meshInstances > 1)
    out.push_back("the scene places " + std::to_string(meshInstances) +
                  " meshes, read as one surface in the scene's frame");
  if (primitivesSkipped > 0)
    out.push_back(std::to_string(primitivesSkipped) +
                  (primitivesSkipped == 1 ? " point or line primitive" : " point or line primitives") +
                  " skipped (no surface)");
  if (fileUnit != 1.0) {
    char unit[64];
    std::snprintf(unit, sizeof unit, "%g", fileUnit);
    out.push_back(std::string("the file's unit is ") + unit + " m" +
                  (fileUnit == 0.01    ? " (centimetres, FBX's default)"
                   : fileUnit == 0.001 ? " (millimetres)"
                                       : "") +
                  ": read in metres");
  }
  if (skinnedInstances > 0)
    out.push_back(std::to_string(skinnedInstances) +
                  (skinnedInstances == 1 ? " skinned mesh" : " skinned meshes") +
                  " read in the bind pose, placed by the node that holds it");
  if (verticesWelded > 0)
    out.push_back(std::to_string(verticesWelded) + " coincident vertices welded" +
                  (facesCollapsedByWeld > 0 ? " (" + std::to_string(facesCollapsedByWeld) +
                                                  " triangles collapsed to slivers removed)"
                                            : std::string()) +
                  (topology.boundaryEdges == 0
                       ? ", which closed the surface"
                       : ", leaving " + std::to_string(topology.boundaryEdges) + " boundary edges"));
  if (specksDropped > 0) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "%zu detached %s under %g of the largest part's area dropped (specks: %.3g %% of the area",
                  specksDropped, specksDropped == 1 ? "part" : "parts", kSpeckAreaShare,
                  100.0 * specksAreaShare);
    std::string note = text;
    if (specksVolumeShare > 0.0) {
      std::snprintf(text, sizeof text, ", %.3g %% of the volume", 100.0 * specksVolumeShare);
      note += text;
    }
    out.push_back(note + ")");
  }
  if (zeroAreaFacesFlipped > 0)
    out.push_back(
        std::to_string(zeroAreaFacesFlipped) +
        (zeroAreaFacesFlipped == 1 ? " zero-area face" : " zero-area faces") +
        " (corners on one line, where a vertex lies on a neighbour's edge) flipped away: the surface is "
        "the same, cut into other triangles");
  if (shellsTurnedOutward > 0)
    out.push_back(std::to_string(shellsTurnedOutward) +
                  (shellsTurnedOutward == 1 ? " closed shell was" : " closed shells were") +
                  " wound inward with no material around (inside out, not a cavity) and " +
                  (shellsTurnedOutward == 1 ? "has" : "have") + " been turned outward");
  if (flippedInsideOut) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the surface is wound inward (signed volume %.6g m³) and has been flipped",
                  signedVolumeAsRead);
    out.emplace_back(text);
  }
  return out;
}

Status saveMesh(const core::TriangleMesh& mesh, const std::filesystem::path& path,
                const SaveOptions& options) {
  const std::string format = detail::lowercaseExtension(path);
  if (format != "obj" && format != "ply" && !detail::isGltf(format))
    return fileError(
        path, ErrorCode::kUnknownFormat,
        "cannot write format '" + path.extension().string() + "' (expected .obj, .ply, .gltf or .glb)");
  if (Status valid = core::validateMesh(mesh, {.allowDegenerateFaces = true}); !valid)
    return fileError(path, ErrorCode::kInvalidArgument, "refusing to write: " + valid.error().message);
  if (detail::isGltf(format)) return detail::writeGltf(mesh, path);

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return fileError(path, ErrorCode::kIo, "cannot open for writing");
  if (format == "obj")
    writeObj(mesh, out);
  else
    writePly(mesh, options.binary, out);
  out.flush();
  const bool written = static_cast<bool>(out);
  if (!written) return fileError(path, ErrorCode::kIo, "cannot write file");
  return Ok{};
}

}  // namespace shapedb::io
