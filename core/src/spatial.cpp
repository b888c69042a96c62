#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <shapedb/core/spatial.h>

namespace shapedb::core {

TrianglePoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Voronoi regions of the vertices, then of the edges, then the face.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const auto result = [&p](const Vec3& q, double u, double v, double w) {
    return TrianglePoint{q, {u, v, w}, (p - q).squaredNorm()};
  };
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return result(a, 1, 0, 0);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return result(b, 0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return result(a + v * ab, 1 - v, v, 0);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return result(c, 0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return result(a + w * ac, 1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return result(b + w * (c - b), 0, 1 - w, w);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return result(a + v * ab + w * ac, 1 - v - w, v, w);
}

namespace {

constexpr std::uint32_t kLeafSize = 4;

double boxSquaredDistance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
}

}  // namespace

ClosestPointTree::ClosestPointTree(const TriangleMesh& surface) {
  const auto n = static_cast<std::uint32_t>(surface.triangles.size());
  mOrder.resize(n);
  std::iota(mOrder.begin(), mOrder.end(), 0u);
  mCorners.resize(n);
  std::vector<Vec3> centroids(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    const auto& tri = surface.triangles[t];
    mCorners[t] = {surface.vertices[tri[0]], surface.vertices[tri[1]], surface.vertices[tri[2]]};
    centroids[t] = (mCorners[t].a + mCorners[t].b + mCorners[t].c) / 3.0;
  }
  mNodes.reserve(2 * (n / kLeafSize + 1));
  if (n > 0) build(0, n, centroids);
  // Corners in leaf order, so that a leaf's triangles sit next to each other.
  std::vector<Corners> ordered(n);
  mPosition.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    ordered[i] = mCorners[mOrder[i]];
    mPosition[mOrder[i]] = i;
  }
  mCorners = std::move(ordered);
}

// Splits the triangles mOrder[begin, end) at the median centroid along the centroids' longest extent;
// boxes are merged bottom-up, so each triangle's corners are read once, at its leaf.
std::int32_t ClosestPointTree::build(std::uint32_t begin, std::uint32_t end,
                                     const std::vector<Vec3>& centroids) {
  const auto index = static_cast<std::int32_t>(mNodes.size());
  mNodes.emplace_back();
  mNodes.back().begin = begin;
  mNodes.back().end = end;
  if (end - begin <= kLeafSize) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::uint32_t i = begin; i < end; ++i) {
      const Corners& c = mCorners[mOrder[i]];
      lo = lo.cwiseMin(c.a).cwiseMin(c.b).cwiseMin(c.c);
      hi = hi.cwiseMax(c.a).cwiseMax(c.b).cwiseMax(c.c);
    }
    mNodes[static_cast<std::size_t>(index)].min = lo;
    mNodes[static_cast<std::size_t>(index)].max = hi;
    return index;
  }
  Vec3 cmin = Vec3::Constant(std::numeric_limits<double>::infinity()), cmax = -cmin;
  for (std::uint32_t i = begin; i < end; ++i) {
    cmin = cmin.cwiseMin(centroids[mOrder[i]]);
    cmax = cmax.cwiseMax(centroids[mOrder[i]]);
  }
  int axis = 0;
  (cmax - cmin).maxCoeff(&axis);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(mOrder.begin() + begin, mOrder.begin() + mid, mOrder.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  const std::int32_t left = build(begin, mid, centroids);
  const std::int32_t right = build(mid, end, centroids);
  Node& node = mNodes[static_cast<std::size_t>(index)];
  node.left = left;
  node.right = right;
  node.min = mNodes[static_cast<std::size_t>(left)].min.cwiseMin(mNodes[static_cast<std::size_t>(right)].min);
  node.max = mNodes[static_cast<std::size_t>(left)].max.cwiseMax(mNodes[static_cast<std::size_t>(right)].max);
  return index;
}

ClosestPointTree::Hit ClosestPointTree::closest(const Vec3& p) const {
  return search(p, Hit{}, std::numeric_limits<double>::infinity());
}

ClosestPointTree::Hit ClosestPointTree::closest(const Vec3& p, std::uint32_t hint) const {
  if (hint >= mPosition.size()) return closest(p);
  const Corners& c = mCorners[mPosition[hint]];
  const TrianglePoint q = closestPointOnTriangle(p, c.a, c.b, c.c);
  return search(p, Hit{hint, q}, q.squaredDistance);
}

ClosestPointTree::Hit ClosestPointTree::search(const Vec3& p, Hit best, double bestSq) const {
  std::array<std::pair<std::int32_t, double>, 64> stack;
  int top = 0;
  stack[top++] = {0, boxSquaredDistance(p, mNodes[0].min, mNodes[0].max)};
  while (top > 0) {
    const auto [index, boxSq] = stack[--top];
    if (boxSq >= bestSq) continue;
    const Node& node = mNodes[index];
    if (node.left < 0) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        const Corners& c = mCorners[i];
        const TrianglePoint q = closestPointOnTriangle(p, c.a, c.b, c.c);
        if (q.squaredDistance < bestSq) {
          bestSq = q.squaredDistance;
          best = {mOrder[i], q};
        }
      }
      continue;
    }
    const Node& l = mNodes[node.left];
    const Node& r = mNodes[node.right];
    const double dl = boxSquaredDistance(p, l.min, l.max);
    const double dr = boxSquaredDistance(p, r.min, r.max);
    // Nearer child on top of the stack. A median-split tree over 2³² triangles is < 64 deep.
    if (dl < dr) {
      stack[top++] = {node.right, dr};
      stack[top++] = {node.left, dl};
    } else {
      stack[top++] = {node.left, dl};
      stack[top++] = {node.right, dr};
    }
  }
  return best;
}

TetLocator::TetLocator(const TetMesh& mesh) : mNodes(mesh.nodes), mTets(mesh.tets) {
  const std::size_t n = mTets.size();
  mInverse.resize(n);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& x : mNodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  for (std::size_t t = 0; t < n; ++t) {
    const auto& k = mTets[t];
    Mat3 edges;
    edges << mNodes[k[1]] - mNodes[k[0]], mNodes[k[2]] - mNodes[k[0]], mNodes[k[3]] - mNodes[k[0]];
    mInverse[t] = edges.inverse();
  }

  // About two cells per tet, shaped like the bounding box.
  const Vec3 extent = (hi - lo).cwiseMax(1e-12 * (hi - lo).maxCoeff());
  const double cell = std::cbrt(extent.prod() / std::max<double>(1.0, 2.0 * static_cast<double>(n)));
  for (int a = 0; a < 3; ++a)
    mDims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / cell)), 1, 256);
  mOrigin = lo;
  for (int a = 0; a < 3; ++a)
    mInvCell[a] = mDims[a] / extent[a];
  const auto cellRange = [&](const Vec3& p, int a) {
    return std::clamp(static_cast<int>(std::floor((p[a] - mOrigin[a]) * mInvCell[a])), 0, mDims[a] - 1);
  };
  const std::size_t cells = static_cast<std::size_t>(mDims[0]) * mDims[1] * mDims[2];
  std::vector<std::array<int, 6>> ranges(n);
  std::vector<std::uint32_t> counts(cells + 1, 0);
  for (std::size_t t = 0; t < n; ++t) {
    Vec3 tlo = mNodes[mTets[t][0]], thi = tlo;
    for (std::uint32_t v : mTets[t]) {
      tlo = tlo.cwiseMin(mNodes[v]);
      thi = thi.cwiseMax(mNodes[v]);
    }
    auto& r = ranges[t];
    for (int a = 0; a < 3; ++a) {
      r[a] = cellRange(tlo, a);
      r[3 + a] = cellRange(thi, a);
    }
    for (int z = r[2]; z <= r[5]; ++z)
      for (int y = r[1]; y <= r[4]; ++y)
        for (int x = r[0]; x <= r[3]; ++x)
          ++counts[(static_cast<std::size_t>(z) * mDims[1] + y) * mDims[0] + x + 1];
  }
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  mCellBegin = counts;
  mCellTets.resize(counts.back());
  for (std::size_t t = 0; t < n; ++t) {
    const auto& r = ranges[t];
    for (int z = r[2]; z <= r[5]; ++z)
      for (int y = r[1]; y <= r[4]; ++y)
        for (int x = r[0]; x <= r[3]; ++x)
          mCellTets[counts[(static_cast<std::size_t>(z) * mDims[1] + y) * mDims[0] + x]++] =
              static_cast<std::uint32_t>(t);
  }

  mBoundarySurface.vertices = mNodes;
  for (const BoundaryFace& face : boundaryFaces(mesh)) {
    mBoundarySurface.triangles.push_back(face.nodes);
    mOwner.push_back(face.tet);
  }
  mBoundary = ClosestPointTree(mBoundarySurface);
}

std::array<double, 4> TetLocator::weightsIn(std::uint32_t t, const Vec3& p) const {
  const Vec3 l = mInverse[t] * (p - mNodes[mTets[t][0]]);
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

namespace {

/// Barycentric weights count as inside down to this (they are scale-free).
constexpr double kInsideTolerance = 1e-10;
/// A point this deep in a tet (every weight above it) is in no other tet of a conforming mesh, to
/// round-off: the search stops there.
constexpr double kClearlyInside = 1e-6;

double minWeight(const std::array<double, 4>& w) {
  return std::min(std::min(w[0], w[1]), std::min(w[2], w[3]));
}

}  // namespace

TetLocation TetLocator::outside(const Vec3& p, Hint* hint) const {
  const ClosestPointTree::Hit hit = hint ? mBoundary.closest(p, hint->face) : mBoundary.closest(p);
  if (hint) hint->face = hit.triangle;
  const std::uint32_t t = mOwner[hit.triangle];
  return {t, weightsIn(t, hit.closest.point), std::sqrt(hit.closest.squaredDistance)};
}

TetLocation TetLocator::locate(const Vec3& p) const {
  return locate(p, nullptr);
}

TetLocation TetLocator::locate(const Vec3& p, Hint& hint) const {
  return locate(p, &hint);
}

TetLocation TetLocator::locate(const Vec3& p, Hint* hint) const {
  std::array<int, 3> c;
  for (int a = 0; a < 3; ++a) {
    const double u = (p[a] - mOrigin[a]) * mInvCell[a];
    if (!(u >= 0.0 && u <= mDims[a])) return outside(p, hint);  // also NaN
    c[a] = std::min(static_cast<int>(u), mDims[a] - 1);
  }
  const std::size_t cell = (static_cast<std::size_t>(c[2]) * mDims[1] + c[1]) * mDims[0] + c[0];
  double bestMin = -std::numeric_limits<double>::infinity();
  TetLocation best;
  for (std::uint32_t i = mCellBegin[cell]; i < mCellBegin[cell + 1]; ++i) {
    const std::uint32_t t = mCellTets[i];
    const auto w = weightsIn(t, p);
    const double m = minWeight(w);
    if (m > bestMin || (m == bestMin && t < best.tet)) {
      bestMin = m;
      best = {t, w, 0.0};
      // Well inside one tet: the tets of a conforming mesh do not overlap, so no other holds p.
      if (m > kClearlyInside) return best;
    }
  }
  if (bestMin >= -kInsideTolerance) return best;
  return outside(p, hint);
}

TetLocation locateBruteForce(const TetLocator& locator, const Vec3& p) {
  double bestMin = -std::numeric_limits<double>::infinity();
  TetLocation best;
  for (std::uint32_t t = 0; t < locator.mTets.size(); ++t) {
    const auto w = locator.weightsIn(t, p);
    const double m = minWeight(w);
    if (m > bestMin) {
      bestMin = m;
      best = {t, w, 0.0};
    }
  }
  if (bestMin >= -kInsideTolerance) return best;
  const TriangleMesh& boundary = locator.boundary();
  double bestSq = std::numeric_limits<double>::infinity();
  std::uint32_t face = 0;
  TrianglePoint closest;
  for (std::uint32_t f = 0; f < boundary.triangles.size(); ++f) {
    const auto& tri = boundary.triangles[f];
    const TrianglePoint q = closestPointOnTriangle(p, boundary.vertices[tri[0]], boundary.vertices[tri[1]],
                                                   boundary.vertices[tri[2]]);
    if (q.squaredDistance < bestSq) {
      bestSq = q.squaredDistance;
      face = f;
      closest = q;
    }
  }
  const std::uint32_t t = locator.mOwner[face];
  return {t, locator.weightsIn(t, closest.point), std::sqrt(bestSq)};
}

}  // namespace shapedb::core
