// How large a mesh file's mesh is before it is read whole, and how much memory this process can have:
// together they let loadMesh refuse a file that would not fit, with the figures, instead of failing
// half way through (or being killed).

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/resource.h>
#include <unistd.h>
#include <vector>

#include <nlohmann/json.hpp>

#include <shapedb/io/mesh_io.h>

#include "mesh_format.h"

namespace shapedb::io {
namespace {

constexpr std::uint64_t kCountedAbove = 16u << 20;  // text files smaller than this are not counted

// The file's first 64 KiB as lines: where a header's counts are, without reading a line of unbounded
// length (a binary file may hold no newline at all).
std::istringstream headerLines(std::ifstream& in) {
  std::string head(64u << 10, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return std::istringstream(head);
}

// PLY's header: "element vertex N" and "element face N", up to end_header.
MeshFileSize plyHeader(std::ifstream& in) {
  MeshFileSize size;
  std::istringstream lines = headerLines(in);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string keyword, element;
    std::uint64_t count = 0;
    if (!(words >> keyword)) continue;
    if (keyword == "end_header") break;
    if (keyword == "element" && words >> element >> count) {
      if (element == "vertex") size.vertices = count;
      if (element == "face") size.triangles = count;
    }
  }
  return size;
}

// OFF's counts: the first line that starts with two numbers (comments, blank lines and the keyword's line
// skipped).
MeshFileSize offHeader(std::ifstream& in) {
  MeshFileSize size;
  std::istringstream lines = headerLines(in);
  std::string line;
  while (std::getline(lines, line)) {
    const std::size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    std::istringstream words(line.substr(start));
    std::uint64_t vertices = 0, faces = 0;
    if (words >> vertices >> faces) {
      size.vertices = vertices;
      size.triangles = faces;
      break;
    }
  }
  return size;
}

// OBJ's `v` and `f` lines, or ASCII STL's facets, counted by each line's first word, a megabyte at a
// time.
MeshFileSize countLines(std::ifstream& in, bool stl) {
  MeshFileSize size;
  std::vector<char> buffer(1u << 20);
  std::string word;  // the line's first word so far (its first eight characters: enough to tell)
  enum class At { kLeadingBlanks, kFirstWord, kRest } at = At::kLeadingBlanks;
  const auto countWord = [&] {
    if (stl && word == "facet") ++size.triangles;
    if (!stl && word == "v") ++size.vertices;
    if (!stl && word == "f") ++size.triangles;
    word.clear();
  };
  while (in.read(buffer.data(), static_cast<std::streamsize>(buffer.size())) || in.gcount() > 0) {
    const auto got = static_cast<std::size_t>(in.gcount());
    for (std::size_t i = 0; i < got; ++i) {
      const char c = buffer[i];
      if (c == '\n') {
        if (at == At::kFirstWord) countWord();
        word.clear();
        at = At::kLeadingBlanks;
        continue;
      }
      const bool blank = c == ' ' || c == '\t' || c == '\r';
      if (at == At::kLeadingBlanks && !blank) at = At::kFirstWord;
      if (at != At::kFirstWord) continue;
      if (blank) {
        countWord();
        at = At::kRest;
      } else if (word.size() < 8) {
        word.push_back(c);
      }
    }
  }
  if (at == At::kFirstWord) countWord();
  if (stl) size.vertices = size.triangles / 2;  // a closed surface's, once its corners are merged
  return size;
}

// glTF's JSON: the .gltf file itself, or a .glb's first chunk (after a 12-byte header and the chunk's
// length and type). Nothing for JSON over 64 MiB (buffers embedded as text: the reader will read them) or
// a file that is not glTF.
constexpr std::uint64_t kGltfJsonLimit = 64u << 20;

std::optional<nlohmann::json> gltfJson(std::ifstream& in, bool binary, std::uintmax_t fileSize) {
  std::uint64_t offset = 0, length = fileSize;
  if (binary) {
    std::array<std::uint32_t, 5> header{};  // magic, version, length; chunk length, chunk type
    in.read(reinterpret_cast<char*>(header.data()), sizeof header);
    if (in.gcount() != sizeof header || header[0] != 0x46546C67u || header[4] != 0x4E4F534Au)
      return std::nullopt;
    offset = sizeof header;
    length = std::min<std::uint64_t>(header[3], fileSize - offset);
  }
  if (length > kGltfJsonLimit) return std::nullopt;
  std::string text(static_cast<std::size_t>(length), '\0');
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(text.data(), static_cast<std::streamsize>(length));
  nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) return std::nullopt;
  return json;
}

// An object's field as an unsigned integer: `fallback` where it is missing, and 0 where it is anything but
// an unsigned integer (a float such as 1e98 would not convert).
std::uint64_t unsignedField(const nlohmann::json& object, const char* key, std::uint64_t fallback = 0) {
  const auto it = object.find(key);
  if (it == object.end()) return fallback;
  return it->is_number_unsigned() ? it->get<std::uint64_t>() : 0;
}

// The triangles and vertices of the meshes a glTF file's nodes place (every mesh once where no node does),
// from its accessors' counts, each capped by the bytes its buffers declare (so that a lying count does
// not pass for a huge mesh). Anything malformed counts as nothing: the reader will say what it is.
MeshFileSize gltfSize(const nlohmann::json& gltf) {
  const auto array = [&gltf](const char* key) {
    const auto it = gltf.find(key);
    return it != gltf.end() && it->is_array() ? *it : nlohmann::json::array();
  };
  const nlohmann::json accessors = array("accessors"), meshes = array("meshes"), nodes = array("nodes");
  std::uint64_t bufferBytes = 0;
  for (const nlohmann::json& buffer : array("buffers"))
    if (buffer.is_object()) bufferBytes += unsignedField(buffer, "byteLength");
  const auto count = [&](const nlohmann::json& index) -> std::uint64_t {
    if (!index.is_number_unsigned() || index.get<std::uint64_t>() >= accessors.size()) return 0;
    const nlohmann::json& a = accessors[index.get<std::size_t>()];
    return a.is_object() ? std::min(unsignedField(a, "count"), bufferBytes) : 0;
  };
  MeshFileSize size;
  const auto addMesh = [&](const nlohmann::json& index) {
    if (!index.is_number_unsigned() || index.get<std::uint64_t>() >= meshes.size()) return;
    const nlohmann::json& mesh = meshes[index.get<std::size_t>()];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) return;
    for (const nlohmann::json& primitive : mesh["primitives"]) {
      if (!primitive.is_object() || !primitive.contains("attributes") || !primitive["attributes"].is_object())
        continue;
      const std::uint64_t mode = unsignedField(primitive, "mode", 4);
      if (mode < 4 || mode > 6) continue;
      const nlohmann::json& attributes = primitive["attributes"];
      const std::uint64_t vertices = attributes.contains("POSITION") ? count(attributes["POSITION"]) : 0;
      const std::uint64_t corners = primitive.contains("indices") ? count(primitive["indices"]) : vertices;
      size.vertices += vertices;
      size.triangles += mode == 4 ? corners / 3 : (corners > 2 ? corners - 2 : 0);
    }
  };
  bool placed = false;
  for (const nlohmann::json& node : nodes)
    if (node.is_object() && node.contains("mesh")) {
      addMesh(node["mesh"]);
      placed = true;
    }
  if (!placed)
    for (std::size_t m = 0; m < meshes.size(); ++m)
      addMesh(m);
  return size;
}

std::optional<std::uint64_t> readUnsigned(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text)) return std::nullopt;
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;  // "max": no limit
  return value;
}

}  // namespace

Result<MeshFileSize> estimateMeshFile(const std::filesystem::path& path) {
  const std::string format = detail::lowercaseExtension(path);
  if (!detail::isMeshFormat(format))
    return Error{ErrorCode::kUnknownFormat,
                 path.string() + ": unknown mesh format '" + path.extension().string() + "'"};
  std::error_code ec;
  const std::uintmax_t fileSize = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) return Error{ErrorCode::kIo, path.string() + ": cannot read file"};

  MeshFileSize size;
  // FBX and COLLADA are parsed by assimp alone, in a worker process, whose count of the mesh is checked
  // against the memory budget before the mesh enters this one (assimp_reader.h): not estimated here.
  if (detail::isAssimpFormat(format)) return size;
  if (detail::isGltf(format)) {
    const std::optional<nlohmann::json> json = gltfJson(in, format == "glb", fileSize);
    return json ? gltfSize(*json) : size;
  }
  if (format == "ply" || format == "off") {
    size = format == "ply" ? plyHeader(in) : offHeader(in);
    // A count the file cannot hold is a corrupt header (the reader will say so), not a huge mesh: at
    // least 3 bytes a vertex (three one-byte scalars) and 4 a face (a count and three one-byte indices).
    size.vertices = std::min<std::uint64_t>(size.vertices, fileSize / 3);
    size.triangles = std::min<std::uint64_t>(size.triangles, fileSize / 4);
    return size;
  }
  if (format == "stl") {
    std::array<char, 84> header{};
    in.read(header.data(), header.size());
    std::uint32_t claimed = 0;
    std::memcpy(&claimed, header.data() + 80, sizeof claimed);
    if (in.gcount() == 84 && 84 + 50 * std::uintmax_t{claimed} == fileSize) {
      size.triangles = claimed;
      size.vertices = claimed / 2;  // once OpenMesh's reader has merged the corners
      return size;
    }
    in.clear();
    in.seekg(0);
  }
  if (fileSize <= kCountedAbove) return size;
  return countLines(in, format == "stl");
}

std::optional<std::uint64_t> availableMemory() {
  std::optional<std::uint64_t> least;
  const auto consider = [&least](std::uint64_t bytes) { least = least ? std::min(*least, bytes) : bytes; };

  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);)
    if (line.rfind("MemAvailable:", 0) == 0) {
      std::istringstream words(line.substr(13));
      std::uint64_t kib = 0;
      if (words >> kib) consider(kib << 10);
      break;
    }

  // cgroup v2: this process's group's limit and use.
  if (const std::optional<std::uint64_t> limit = readUnsigned("/sys/fs/cgroup/memory.max"))
    if (const std::optional<std::uint64_t> used = readUnsigned("/sys/fs/cgroup/memory.current"))
      consider(*limit > *used ? *limit - *used : 0);

  // The address-space limit (ulimit -v) less what the process has mapped already.
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    std::ifstream statm("/proc/self/statm");
    std::uint64_t pages = 0;
    if (statm >> pages) {
      const std::uint64_t mapped = pages * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
      consider(limit.rlim_cur > mapped ? limit.rlim_cur - mapped : 0);
    }
  }
  return least;
}

}  // namespace shapedb::io
