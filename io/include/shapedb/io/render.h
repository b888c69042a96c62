#pragma once
// Pictures and files for people to look at: a small software rasterizer (flat-shaded triangles, z-buffer,
// orthographic view) written out as PNG through stb, and OBJ files with one named object per part.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::io {

/// An 8-bit RGB image, rows top to bottom.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 · width · height
};

/// One panel of a picture: meshes drawn together, each in its colour.
struct Panel {
  std::vector<const core::TriangleMesh*> meshes;
  std::vector<std::array<std::uint8_t, 3>> colors;
};

/// Draws the panels side by side, each `panelSize` pixels square, all seen from the same direction
/// (`viewFromWorld`: rows are the camera's right, up and backward axes) at the same scale, so that sizes
/// compare across panels; each panel centred on its own bounding box. Flat Lambert shading, one light.
Image renderPanels(std::span<const Panel> panels, const core::Mat3& viewFromWorld, int panelSize = 400);

/// Errors: kIo naming the file.
Status savePng(const Image& image, const std::filesystem::path& path);

/// A collision compound as triangle meshes, one per shape (spheres and capsules tessellated).
std::vector<core::TriangleMesh> tessellate(const core::CollisionCompound& compound);

/// Writes an OBJ with one `o` object per part, named. Errors: kIo naming the file.
Status saveObjParts(std::span<const std::pair<std::string, core::TriangleMesh>> parts,
                    const std::filesystem::path& path);

}  // namespace shapedb::io
