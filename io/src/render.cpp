#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>

#include <stb_image_write.h>

#include <shapedb/core/primitives.h>
#include <shapedb/io/render.h>

#include "obj_writer.h"

namespace shapedb::io {

namespace {

struct Box2 {
  core::Vec3 min = core::Vec3::Constant(std::numeric_limits<double>::infinity());
  core::Vec3 max = -min;
};

}  // namespace

Image renderPanels(std::span<const Panel> panels, const core::Mat3& viewFromWorld, int panelSize) {
  Image image;
  image.width = panelSize * static_cast<int>(std::max<std::size_t>(1, panels.size()));
  image.height = panelSize;
  image.rgb.assign(static_cast<std::size_t>(image.width) * image.height * 3, 255);
  std::vector<double> depth(static_cast<std::size_t>(image.width) * image.height,
                            -std::numeric_limits<double>::infinity());

  // One scale for every panel: the largest projected extent fills 80 % of a panel.
  std::vector<Box2> boxes(panels.size());
  double extent = 0.0;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    for (const core::TriangleMesh* mesh : panels[p].meshes)
      for (const core::Vec3& v : mesh->vertices) {
        const core::Vec3 q = viewFromWorld * v;
        boxes[p].min = boxes[p].min.cwiseMin(q);
        boxes[p].max = boxes[p].max.cwiseMax(q);
      }
    if (boxes[p].min.x() <= boxes[p].max.x())
      extent = std::max(extent, (boxes[p].max - boxes[p].min).head<2>().maxCoeff());
  }
  if (!(extent > 0.0)) return image;
  const double pixels = 0.8 * panelSize / extent;
  const core::Vec3 light = core::Vec3(-0.4, 0.6, 0.7).normalized();

  for (std::size_t p = 0; p < panels.size(); ++p) {
    const core::Vec3 centre = 0.5 * (boxes[p].min + boxes[p].max);
    const double x0 = static_cast<double>(p) * panelSize + 0.5 * panelSize;
    const double y0 = 0.5 * panelSize;
    for (std::size_t m = 0; m < panels[p].meshes.size(); ++m) {
      const core::TriangleMesh& mesh = *panels[p].meshes[m];
      const auto color =
          m < panels[p].colors.size() ? panels[p].colors[m] : std::array<std::uint8_t, 3>{160, 160, 160};
      for (const auto& t : mesh.triangles) {
        std::array<core::Vec3, 3> s;
        for (int k = 0; k < 3; ++k) {
          const core::Vec3 q = viewFromWorld * mesh.vertices[t[k]] - centre;
          s[k] = core::Vec3(x0 + q.x() * pixels, y0 - q.y() * pixels, q.z());
        }
        const core::Vec3 normal = (viewFromWorld * (mesh.vertices[t[1]] - mesh.vertices[t[0]]))
                                      .cross(viewFromWorld * (mesh.vertices[t[2]] - mesh.vertices[t[0]]));
        if (normal.z() <= 0.0) continue;  // facing away (closed surfaces: the front hides it anyway)
        const double shade = 0.25 + 0.75 * std::max(0.0, normal.normalized().dot(light));
        // Edge functions over the triangle's pixel box, pixel centres at +0.5.
        const double area =
            (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[2].x() - s[0].x()) * (s[1].y() - s[0].y());
        if (std::abs(area) < 1e-12) continue;
        const int xmin = std::max(static_cast<int>(p) * panelSize,
                                  static_cast<int>(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}))));
        const int xmax = std::min(static_cast<int>(p + 1) * panelSize - 1,
                                  static_cast<int>(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
        const int ymin = std::max(0, static_cast<int>(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}))));
        const int ymax =
            std::min(panelSize - 1, static_cast<int>(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
        for (int y = ymin; y <= ymax; ++y)
          for (int x = xmin; x <= xmax; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            const double w0 = ((s[1].x() - px) * (s[2].y() - py) - (s[2].x() - px) * (s[1].y() - py)) / area;
            const double w1 = ((s[2].x() - px) * (s[0].y() - py) - (s[0].x() - px) * (s[2].y() - py)) / area;
            const double w2 = 1.0 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            const double z = w0 * s[0].z() + w1 * s[1].z() + w2 * s[2].z();
            const std::size_t i = static_cast<std::size_t>(y) * image.width + x;
            if (z <= depth[i]) continue;
            depth[i] = z;
            for (int c = 0; c < 3; ++c)
              image.rgb[3 * i + c] = static_cast<std::uint8_t>(std::lround(color[c] * shade));
          }
      }
    }
  }
  return image;
}

Status savePng(const Image& image, const std::filesystem::path& path) {
  if (image.width <= 0 || image.height <= 0)
    return Error{ErrorCode::kInvalidArgument, path.string() + ": empty image"};
  if (!stbi_write_png(path.c_str(), image.width, image.height, 3, image.rgb.data(), image.width * 3))
    return Error{ErrorCode::kIo, path.string() + ": cannot write PNG"};
  return Ok{};
}

std::vector<core::TriangleMesh> tessellate(const core::CollisionCompound& compound) {
  std::vector<core::TriangleMesh> out;
  for (const core::CollisionShape& s : compound.shapes) {
    core::TriangleMesh mesh;
    switch (s.type) {
      case core::CollisionShape::Type::kSphere:
        mesh = core::makeIcosphere(s.radius, 2);
        break;
      case core::CollisionShape::Type::kBox:
        mesh = core::makeBox(2.0 * s.halfExtents);
        break;
      case core::CollisionShape::Type::kCapsule:
        mesh = core::makeCapsule(s.radius, 2.0 * s.halfLength, 24, 6);
        break;
    }
    for (core::Vec3& v : mesh.vertices)
      v = s.center + s.rotation * v;
    out.push_back(std::move(mesh));
  }
  return out;
}

Status saveObjParts(std::span<const std::pair<std::string, core::TriangleMesh>> parts,
                    const std::filesystem::path& path) {
  std::ofstream file(path);
  if (!file) return Error{ErrorCode::kIo, path.string() + ": cannot open for writing"};
  file << "# written by shapedb\n";
  std::size_t base = 0;
  for (const auto& [name, mesh] : parts) {
    detail::writeObjPart(file, mesh, base, name);
    base += mesh.vertices.size();
  }
  file.close();
  if (!file) return Error{ErrorCode::kIo, path.string() + ": write failed"};
  return Ok{};
}

}  // namespace shapedb::io
