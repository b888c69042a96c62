#include <cassert>
#include <cmath>
#include <numbers>
#include <vector>

#include <shapedb/core/primitives.h>

namespace shapedb::core {

TriangleMesh makeTetrahedron(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  TriangleMesh mesh;
  mesh.vertices = {a, b, c, d};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  // Outward when (b−a, c−a, d−a) is right-handed; otherwise reverse every face.
  if ((b - a).cross(c - a).dot(d - a) < 0.0) return flipped(mesh);
  return mesh;
}

TriangleMesh makeBox(const Vec3& size) {
  TriangleMesh mesh;
  const Vec3 h = 0.5 * size;
  for (int i = 0; i < 8; ++i)
    mesh.vertices.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
  // Two triangles per face, counter-clockwise seen from outside; vertex i has bits (x, y, z).
  mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return mesh;
}

TriangleMesh makeUvEllipsoid(const Vec3& radii, int slices, int stacks) {
  assert(slices >= 3 && stacks >= 2);
  TriangleMesh mesh;
  const auto u = [](int i) { return static_cast<std::uint32_t>(i); };
  // Poles first, then rings from the top down.
  mesh.vertices.emplace_back(0.0, 0.0, radii.z());
  mesh.vertices.emplace_back(0.0, 0.0, -radii.z());
  for (int i = 1; i < stacks; ++i) {
    const double theta = std::numbers::pi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / slices;
      mesh.vertices.emplace_back(radii.x() * std::sin(theta) * std::cos(phi),
                                 radii.y() * std::sin(theta) * std::sin(phi), radii.z() * std::cos(theta));
    }
  }
  const auto ring = [&](int i, int j) { return u(2 + (i - 1) * slices + (j % slices)); };
  for (int j = 0; j < slices; ++j) {
    mesh.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
    mesh.triangles.push_back({1, ring(stacks - 1, j + 1), ring(stacks - 1, j)});
  }
  for (int i = 1; i + 1 < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      mesh.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      mesh.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  return mesh;
}

TriangleMesh makeIcosphere(double radius, int subdivisions) {
  const double g = std::numbers::phi;
  TriangleMesh mesh;
  mesh.vertices = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                   {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  mesh.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int i = 0; i < subdivisions; ++i)
    mesh = subdivideMidpoint(mesh);
  for (Vec3& p : mesh.vertices)
    p = radius * p.normalized();
  return mesh;
}

TriangleMesh makeCylinder(double radius, double height, int segments) {
  assert(segments >= 3);
  TriangleMesh mesh;
  const double h = 0.5 * height;
  // Cap centres, then the bottom ring, then the top ring.
  mesh.vertices.emplace_back(0.0, 0.0, -h);
  mesh.vertices.emplace_back(0.0, 0.0, h);
  for (double z : {-h, h}) {
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / segments;
      mesh.vertices.emplace_back(radius * std::cos(phi), radius * std::sin(phi), z);
    }
  }
  const auto bottom = [&](int j) { return static_cast<std::uint32_t>(2 + j % segments); };
  const auto top = [&](int j) { return static_cast<std::uint32_t>(2 + segments + j % segments); };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({0, bottom(j + 1), bottom(j)});
    mesh.triangles.push_back({1, top(j), top(j + 1)});
    mesh.triangles.push_back({bottom(j), bottom(j + 1), top(j + 1)});
    mesh.triangles.push_back({bottom(j), top(j + 1), top(j)});
  }
  return mesh;
}

TriangleMesh makeCone(double radius, double height, int segments) {
  assert(segments >= 3);
  TriangleMesh mesh;
  const double h = 0.5 * height;
  // Base centre, apex, then the base ring.
  mesh.vertices.emplace_back(0.0, 0.0, -h);
  mesh.vertices.emplace_back(0.0, 0.0, h);
  for (int j = 0; j < segments; ++j) {
    const double phi = 2.0 * std::numbers::pi * j / segments;
    mesh.vertices.emplace_back(radius * std::cos(phi), radius * std::sin(phi), -h);
  }
  const auto ring = [&](int j) { return static_cast<std::uint32_t>(2 + j % segments); };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({0, ring(j + 1), ring(j)});
    mesh.triangles.push_back({ring(j), ring(j + 1), 1});
  }
  return mesh;
}

TriangleMesh makeCapsule(double radius, double length, int segments, int capStacks) {
  assert(segments >= 3 && capStacks >= 1 && length >= 0.0);
  TriangleMesh mesh;
  const double h = 0.5 * length;
  // Poles, then rings from the top pole down: capStacks rings on the upper hemisphere (the last on its
  // equator at z = +h), the same mirrored below. With length 0 the two equators coincide and become one.
  mesh.vertices.emplace_back(0.0, 0.0, h + radius);
  mesh.vertices.emplace_back(0.0, 0.0, -h - radius);
  std::vector<double> ringZ, ringR;
  for (int i = 1; i <= capStacks; ++i) {
    const double theta = 0.5 * std::numbers::pi * i / capStacks;
    ringZ.push_back(h + radius * std::cos(theta));
    ringR.push_back(radius * std::sin(theta));
  }
  for (int i = capStacks - (length > 0.0 ? 1 : 2); i >= 0; --i) {
    ringZ.push_back(-ringZ[static_cast<std::size_t>(i)]);
    ringR.push_back(ringR[static_cast<std::size_t>(i)]);
  }
  for (std::size_t i = 0; i < ringZ.size(); ++i) {
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / segments;
      mesh.vertices.emplace_back(ringR[i] * std::cos(phi), ringR[i] * std::sin(phi), ringZ[i]);
    }
  }
  const int rings = static_cast<int>(ringZ.size());
  const auto ring = [&](int i, int j) { return static_cast<std::uint32_t>(2 + i * segments + j % segments); };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({0, ring(0, j), ring(0, j + 1)});
    mesh.triangles.push_back({1, ring(rings - 1, j + 1), ring(rings - 1, j)});
  }
  for (int i = 0; i + 1 < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      mesh.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      mesh.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  return mesh;
}

TriangleMesh makeTriangularPrism(double base, double height, double length) {
  TriangleMesh mesh;
  const double b = 0.5 * base, c = 0.5 * height, h = 0.5 * length;
  // Bottom triangle (0, 1, 2) counter-clockwise seen from +z, then the top one.
  for (double z : {-h, h}) {
    mesh.vertices.emplace_back(-b, -c, z);
    mesh.vertices.emplace_back(b, -c, z);
    mesh.vertices.emplace_back(0.0, c, z);
  }
  mesh.triangles = {{0, 2, 1}, {3, 4, 5}};
  for (std::uint32_t j = 0; j < 3; ++j) {
    const std::uint32_t k = (j + 1) % 3;
    mesh.triangles.push_back({j, k, k + 3});
    mesh.triangles.push_back({j, k + 3, j + 3});
  }
  return mesh;
}

}  // namespace shapedb::core
