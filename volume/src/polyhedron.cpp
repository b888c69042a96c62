#include "polyhedron.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace shapedb::volume::detail {

using core::TriangleMesh;
using core::Vec3;

namespace {

/// The point where segment pq crosses the plane n·x = d, computed from the endpoints in a fixed order,
/// so the two faces sharing the edge get the same bits.
Vec3 crossing(Vec3 p, Vec3 q, const Vec3& n, double d) {
  if (std::lexicographical_compare(q.data(), q.data() + 3, p.data(), p.data() + 3)) std::swap(p, q);
  const double dp = n.dot(p) - d, dq = n.dot(q) - d;
  return p + (dp / (dp - dq)) * (q - p);
}

}  // namespace

std::vector<Polygon> boxFaces(const Vec3& lo, const Vec3& hi) {
  const auto corner = [&](int i) {
    return Vec3(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  };
  // Corner i has x from bit 0, y from bit 1, z from bit 2; each quad counter-clockwise seen from outside.
  static constexpr int kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  std::vector<Polygon> faces;
  for (const auto& f : kFaces)
    faces.push_back({corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3])});
  return faces;
}

std::vector<Polygon> clip(const std::vector<Polygon>& faces, const Vec3& n, double d) {
  std::vector<Polygon> result;
  std::vector<Vec3> cut;
  for (const Polygon& face : faces) {
    Polygon kept;
    for (std::size_t i = 0; i < face.size(); ++i) {
      const Vec3& p = face[i];
      const Vec3& q = face[(i + 1) % face.size()];
      const bool pIn = n.dot(p) <= d, qIn = n.dot(q) <= d;
      if (pIn) kept.push_back(p);
      if (pIn != qIn) {
        kept.push_back(crossing(p, q, n, d));
        cut.push_back(kept.back());
      }
    }
    if (kept.size() >= 3) result.push_back(std::move(kept));
  }
  if (cut.size() >= 3) {
    // The cap: the cut points ordered counter-clockwise about n (outward for the kept side).
    Vec3 center = Vec3::Zero();
    for (const Vec3& p : cut)
      center += p;
    center /= static_cast<double>(cut.size());
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    std::sort(cut.begin(), cut.end(), [&](const Vec3& a, const Vec3& b) {
      return std::atan2((a - center).dot(v), (a - center).dot(u)) <
             std::atan2((b - center).dot(v), (b - center).dot(u));
    });
    cut.erase(std::unique(cut.begin(), cut.end()), cut.end());
    if (cut.size() >= 3) result.push_back(cut);
  }
  return result;
}

std::vector<Polygon> voronoiCell(std::vector<Polygon> solid, std::span<const Vec3> seeds, std::size_t i) {
  for (std::size_t j = 0; j < seeds.size() && !solid.empty(); ++j) {
    if (j == i) continue;
    const Vec3 n = seeds[j] - seeds[i];
    if (n.squaredNorm() == 0.0) {
      if (j < i) solid.clear();
      continue;
    }
    solid = clip(solid, n, n.dot(0.5 * (seeds[i] + seeds[j])));
  }
  return solid;
}

TriangleMesh triangulate(const std::vector<Polygon>& faces) {
  TriangleMesh mesh;
  std::map<std::array<double, 3>, std::uint32_t> ids;
  const auto id = [&](const Vec3& p) {
    const double q = std::ldexp(1.0, 30);
    const std::array<double, 3> key = {std::round(p.x() * q) / q, std::round(p.y() * q) / q,
                                       std::round(p.z() * q) / q};
    auto [it, inserted] = ids.try_emplace(key, static_cast<std::uint32_t>(mesh.vertices.size()));
    if (inserted) mesh.vertices.emplace_back(key[0], key[1], key[2]);
    return it->second;
  };
  for (const Polygon& face : faces) {
    std::vector<std::uint32_t> v;
    for (const Vec3& p : face)
      if (const std::uint32_t i = id(p); v.empty() || (i != v.back() && i != v.front())) v.push_back(i);
    for (std::size_t i = 1; i + 1 < v.size(); ++i)
      mesh.triangles.push_back({v[0], v[i], v[i + 1]});
  }
  return mesh;
}

}  // namespace shapedb::volume::detail
