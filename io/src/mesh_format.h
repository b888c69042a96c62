#pragma once

// A mesh file's format, from its name: one rule for the readers, the size estimate and folder listings.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace shapedb::io::detail {

/// The extension without its dot, in lower case: "obj" for "Part.OBJ"; "" for none.
inline std::string lowercaseExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// Whether `format` is glTF's, as text (gltf) or binary (glb).
inline bool isGltf(const std::string& format) {
  return format == "gltf" || format == "glb";
}

/// Whether `format` is one read through assimp in a worker process (assimp_reader.h): FBX and COLLADA.
inline bool isAssimpFormat(const std::string& format) {
  return format == "fbx" || format == "dae";
}

/// Whether `format` (as lowercaseExtension gives it) is one shapedb reads: obj, ply, off, stl, gltf, glb,
/// fbx or dae.
inline bool isMeshFormat(const std::string& format) {
  return format == "obj" || format == "ply" || format == "off" || format == "stl" || isGltf(format) ||
         isAssimpFormat(format);
}

}  // namespace shapedb::io::detail
