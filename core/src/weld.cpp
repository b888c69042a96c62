#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <shapedb/core/weld.h>

namespace shapedb::core {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

/// Rewrites `mesh` given each vertex's representative (a vertex that is its own representative is kept):
/// triangles re-indexed, those with a repeated corner removed, unused vertices dropped.
WeldReport rewrite(TriangleMesh& mesh, const std::vector<std::uint32_t>& representative) {
  WeldReport report;
  for (std::size_t v = 0; v < representative.size(); ++v)
    if (representative[v] != v) ++report.verticesMerged;
  std::vector<TriangleMesh::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const TriangleMesh::Triangle w{representative[t[0]], representative[t[1]], representative[t[2]]};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) {
      ++report.facesCollapsed;
      continue;
    }
    triangles.push_back(w);
  }
  mesh.triangles = std::move(triangles);
  removeUnusedVertices(mesh);
  return report;
}

struct CellHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
    // In unsigned arithmetic, which wraps: a far cell's index times a prime overflows a signed integer.
    const auto u = [](std::int64_t x) { return static_cast<std::uint64_t>(x); };
    return static_cast<std::size_t>(u(c[0]) * 73856093u ^ u(c[1]) * 19349663u ^ u(c[2]) * 83492791u);
  }
};

struct ExactHash {
  std::size_t operator()(const Vec3& p) const {
    std::size_t h = 0;
    for (int i = 0; i < 3; ++i)
      h = h * 1000003u ^ std::hash<double>{}(p[i] == 0.0 ? 0.0 : p[i]);  // -0 and +0 alike
    return h;
  }
};

struct ExactEqual {
  bool operator()(const Vec3& a, const Vec3& b) const {
    return a.x() == b.x() && a.y() == b.y() && a.z() == b.z();
  }
};

// The hash-grid cell of coordinate x. Clamped: a huge coordinate over a small tolerance would not fit
// in an integer (and converting it would be undefined); clamped cells merely share more candidates, each
// still checked by distance.
std::int64_t cellOf(double x, double tolerance) {
  constexpr double kLimit = 4e18;  // |cell ± 1| stays well inside int64
  return static_cast<std::int64_t>(std::clamp(std::floor(x / tolerance), -kLimit, kLimit));
}

// The tolerance both welds use: a finite positive one as given, anything else (0, or against the
// contract NaN, ∞ or negative) 0, which welds exact equals only.
double usableTolerance(double tolerance) {
  return tolerance > 0.0 && std::isfinite(tolerance) ? tolerance : 0.0;
}

}  // namespace

WeldReport weldVertices(TriangleMesh& mesh, double tolerance) {
  tolerance = usableTolerance(tolerance);
  std::vector<std::uint32_t> representative(mesh.vertices.size());
  if (tolerance == 0.0) {
    std::unordered_map<Vec3, std::uint32_t, ExactHash, ExactEqual> first;
    first.reserve(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
      representative[v] = first.try_emplace(mesh.vertices[v], static_cast<std::uint32_t>(v)).first->second;
    return rewrite(mesh, representative);
  }
  // Kept vertices bucketed by cells of the tolerance: a vertex's candidates lie in the 27 cells around it.
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::uint32_t>, CellHash> cells;
  cells.reserve(mesh.vertices.size());
  const double toleranceSq = tolerance * tolerance;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3& p = mesh.vertices[v];
    const std::array<std::int64_t, 3> cell{cellOf(p.x(), tolerance), cellOf(p.y(), tolerance),
                                           cellOf(p.z(), tolerance)};
    std::uint32_t best = kNone;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto found = cells.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (found == cells.end()) continue;
          for (const std::uint32_t r : found->second)
            if (r < best && (mesh.vertices[r] - p).squaredNorm() <= toleranceSq) best = r;
        }
    if (best == kNone) {
      best = static_cast<std::uint32_t>(v);
      cells[cell].push_back(best);
    }
    representative[v] = best;
  }
  return rewrite(mesh, representative);
}

WeldReport weldVerticesBruteForce(TriangleMesh& mesh, double tolerance) {
  tolerance = usableTolerance(tolerance);
  std::vector<std::uint32_t> representative(mesh.vertices.size());
  std::vector<std::uint32_t> kept;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    representative[v] = static_cast<std::uint32_t>(v);
    for (const std::uint32_t r : kept)
      if ((mesh.vertices[r] - mesh.vertices[v]).squaredNorm() <= tolerance * tolerance) {
        representative[v] = r;
        break;
      }
    if (representative[v] == v) kept.push_back(static_cast<std::uint32_t>(v));
  }
  return rewrite(mesh, representative);
}

}  // namespace shapedb::core
