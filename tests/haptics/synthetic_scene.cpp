#include "synthetic_scene.h"

#include <cmath>
#include <numbers>

#include <shapedb/core/primitives.h>

namespace shapedb::haptics::test {

using core::Vec3;

SceneObject boxObject(const std::string& name, const Vec3& center, double size) {
  core::TriangleMesh mesh = core::makeBox(Vec3::Constant(size));
  const core::Bounds box = core::computeBounds(mesh);
  const Vec3 shift = center - 0.5 * (box.min + box.max);
  for (Vec3& v : mesh.vertices)
    v += shift;
  return {name, std::move(mesh)};
}

std::vector<SceneObject> boxRow(int count, double size, double spacing) {
  std::vector<SceneObject> objects;
  for (int i = 0; i < count; ++i)
    objects.push_back(boxObject("box-" + std::to_string(i), Vec3(i * spacing, 0.0, 0.0), size));
  return objects;
}

Result<AugmentedObject> augmentBox(const SceneObject& object, int modes) {
  const core::Bounds box = core::computeBounds(object.mesh);
  const Vec3 extent = box.max - box.min;
  constexpr int n = 3;
  AugmentedObject out;
  out.source = "synthetic-box";
  core::TetMesh& tets = out.physics.tetMesh;
  const auto id = [](int x, int y, int z) {
    return static_cast<std::uint32_t>((z * (n + 1) + y) * (n + 1) + x);
  };
  for (int z = 0; z <= n; ++z)
    for (int y = 0; y <= n; ++y)
      for (int x = 0; x <= n; ++x)
        tets.nodes.push_back(box.min + extent.cwiseProduct(Vec3(x, y, z) / n));
  static constexpr int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (const auto& path : kPaths) {
          std::array<int, 3> c{x, y, z};
          core::TetMesh::Tet tet{};
          tet[0] = id(c[0], c[1], c[2]);
          for (int k = 0; k < 3; ++k) {
            ++c[path[k]];
            tet[k + 1] = id(c[0], c[1], c[2]);
          }
          const Vec3& a = tets.nodes[tet[0]];
          const double det =
              (tets.nodes[tet[1]] - a).dot((tets.nodes[tet[2]] - a).cross(tets.nodes[tet[3]] - a));
          if (det < 0.0) std::swap(tet[2], tet[3]);
          tets.tets.push_back(tet);
        }

  // Smooth mode shapes (a sine along one axis moving along another), normalized for lumped masses.
  const double density = 1000.0;
  const double volume = extent.prod();
  const double nodeMass = density * volume / static_cast<double>(tets.nodes.size());
  const auto nodes = static_cast<Eigen::Index>(tets.nodes.size());
  out.physics.modeShapes = Eigen::MatrixXd::Zero(3 * nodes, modes);
  out.physics.eigenvalues.resize(modes);
  for (int j = 0; j < modes; ++j) {
    for (Eigen::Index i = 0; i < nodes; ++i) {
      const Vec3 local = (tets.nodes[static_cast<std::size_t>(i)] - box.min).cwiseQuotient(extent);
      out.physics.modeShapes(3 * i + (j % 3), j) =
          std::sin(std::numbers::pi * (1 + j / 3) * local[(j + 1) % 3]) + 0.25;
    }
    out.physics.modeShapes.col(j) /= std::sqrt(nodeMass) * out.physics.modeShapes.col(j).norm();
    out.physics.eigenvalues[j] = std::pow(2.0 * std::numbers::pi * 200.0 * (j + 1), 2);
  }
  out.physics.material = {"synthetic", density, 1e9, 0.3};
  out.physics.damping = {2.0, 2e-6};

  core::CollisionShape shape;
  shape.type = core::CollisionShape::Type::kBox;
  shape.center = 0.5 * (box.min + box.max);
  shape.halfExtents = 0.5 * extent;
  out.physics.collision.shapes.push_back(shape);
  out.physics.collision.coverage = 1.0;

  auto locator = std::make_shared<core::TetLocator>(tets);
  for (const Vec3& v : object.mesh.vertices)
    out.link.locations.push_back(locator->locate(v));
  out.locator = std::move(locator);
  return out;
}

}  // namespace shapedb::haptics::test
