#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <shapedb/core/self_intersection.h>
#include <shapedb/core/spatial.h>

namespace shapedb::core {
namespace {

/// What a pair is tested with: the surface's corners and the tolerances of a clear crossing.
struct CrossingTest {
  const TriangleMesh& surface;
  double planeTolerance;  ///< metres: how far off the plane both ends of an edge must be

  static constexpr double kBarycentricMargin = 1e-9;

  /// Where segment pq clearly crosses the inside of triangle t.
  std::optional<Vec3> segmentThrough(const Vec3& p, const Vec3& q, std::uint32_t t) const {
    const auto& tri = surface.triangles[t];
    const Vec3& a = surface.vertices[tri[0]];
    const Vec3& b = surface.vertices[tri[1]];
    const Vec3& c = surface.vertices[tri[2]];
    const Vec3 n = (b - a).cross(c - a);
    const double area2 = n.norm();
    if (!(area2 > 0.0)) return std::nullopt;
    const double dp = n.dot(p - a) / area2, dq = n.dot(q - a) / area2;
    if (!((dp > planeTolerance && dq < -planeTolerance) || (dp < -planeTolerance && dq > planeTolerance)))
      return std::nullopt;
    const Vec3 x = p + (dp / (dp - dq)) * (q - p);
    const double squared = area2 * area2;
    const double u = n.dot((c - b).cross(x - b)) / squared;
    const double v = n.dot((a - c).cross(x - c)) / squared;
    const double w = 1.0 - u - v;
    if (u > kBarycentricMargin && v > kBarycentricMargin && w > kBarycentricMargin) return x;
    return std::nullopt;
  }

  /// Whether triangles s and t (s < t) cross, and where.
  std::optional<TriangleCrossing> pair(std::uint32_t s, std::uint32_t t) const {
    const auto& a = surface.triangles[s];
    const auto& b = surface.triangles[t];
    int shared = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (a[i] == b[j]) ++shared;
    if (shared >= 2) return std::nullopt;
    const auto crossing = [&](const std::array<std::uint32_t, 3>& edgeOwner, int k,
                              std::uint32_t other) -> std::optional<TriangleCrossing> {
      const Vec3& p = surface.vertices[edgeOwner[k]];
      const Vec3& q = surface.vertices[edgeOwner[(k + 1) % 3]];
      if (auto x = segmentThrough(p, q, other)) return TriangleCrossing{s, t, *x};
      return std::nullopt;
    };
    if (shared == 1) {
      // Each triangle's edge opposite the shared corner (edge k runs from corner k to corner k + 1): the
      // other two end at the corner, which lies on the other triangle, so they cannot cross it clearly.
      int aOpposite = 0, bOpposite = 0;
      for (int i = 0; i < 3; ++i) {
        if (std::find(b.begin(), b.end(), a[i]) != b.end()) aOpposite = (i + 1) % 3;
        if (std::find(a.begin(), a.end(), b[i]) != a.end()) bOpposite = (i + 1) % 3;
      }
      if (auto x = crossing(a, aOpposite, t)) return x;
      return crossing(b, bOpposite, s);
    }
    for (int k = 0; k < 3; ++k)
      if (auto x = crossing(a, k, t)) return x;
    for (int k = 0; k < 3; ++k)
      if (auto x = crossing(b, k, s)) return x;
    return std::nullopt;
  }
};

CrossingTest testFor(const TriangleMesh& surface) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& v : surface.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double size = surface.vertices.empty() ? 0.0 : (hi - lo).norm();
  return {surface, 1e-9 * size};
}

bool byPair(const TriangleCrossing& x, const TriangleCrossing& y) {
  return x.first != y.first ? x.first < y.first : x.second < y.second;
}

}  // namespace

std::vector<TriangleCrossing> findSelfIntersections(const TriangleMesh& surface) {
  std::vector<TriangleCrossing> crossings;
  if (surface.triangles.size() < 2) return crossings;
  const CrossingTest test = testFor(surface);
  const ClosestPointTree tree(surface);
  tbb::combinable<std::vector<TriangleCrossing>> found;
  const auto n = static_cast<std::uint32_t>(surface.triangles.size());
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, n, 1024), [&](const auto& range) {
    std::vector<std::uint32_t> near;
    std::vector<TriangleCrossing>& mine = found.local();
    for (std::uint32_t s = range.begin(); s < range.end(); ++s) {
      const auto& tri = surface.triangles[s];
      Vec3 lo = surface.vertices[tri[0]], hi = lo;
      for (int k = 1; k < 3; ++k) {
        lo = lo.cwiseMin(surface.vertices[tri[k]]);
        hi = hi.cwiseMax(surface.vertices[tri[k]]);
      }
      near.clear();
      tree.overlapping(lo, hi, near);
      for (const std::uint32_t t : near)
        if (t > s)
          if (auto x = test.pair(s, t)) mine.push_back(*x);
    }
  });
  found.combine_each([&](const std::vector<TriangleCrossing>& mine) {
    crossings.insert(crossings.end(), mine.begin(), mine.end());
  });
  std::sort(crossings.begin(), crossings.end(), byPair);
  return crossings;
}

std::vector<TriangleCrossing> findSelfIntersectionsBruteForce(const TriangleMesh& surface) {
  std::vector<TriangleCrossing> crossings;
  const CrossingTest test = testFor(surface);
  const auto n = static_cast<std::uint32_t>(surface.triangles.size());
  for (std::uint32_t s = 0; s < n; ++s)
    for (std::uint32_t t = s + 1; t < n; ++t)
      if (auto x = test.pair(s, t)) crossings.push_back(*x);
  return crossings;
}

}  // namespace shapedb::core
