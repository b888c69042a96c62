#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <utility>

#include <tbb/parallel_for.h>

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

double rayTriangleDistance(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b,
                           const Vec3& c) {
  constexpr double kMiss = std::numeric_limits<double>::infinity();
  const Vec3 e1 = b - a, e2 = c - a, p = direction.cross(e2);
  const double det = e1.dot(p);
  if (det == 0.0) return kMiss;
  const double inverse = 1.0 / det;
  const Vec3 s = origin - a;
  const double u = s.dot(p) * inverse;
  if (!(u >= 0.0 && u <= 1.0)) return kMiss;
  const Vec3 q = s.cross(e1);
  const double v = direction.dot(q) * inverse;
  if (!(v >= 0.0 && u + v <= 1.0)) return kMiss;
  return e2.dot(q) * inverse;
}

std::optional<RayHit> firstHitBruteForce(const TriangleMesh& surface, const Vec3& origin,
                                         const Vec3& direction, double minDistance, std::uint32_t skip) {
  std::optional<RayHit> best;
  for (std::uint32_t t = 0; t < surface.triangles.size(); ++t) {
    if (t == skip) continue;
    const TriangleMesh::Triangle& tri = surface.triangles[t];
    const double d = rayTriangleDistance(origin, direction, surface.vertices[tri[0]],
                                         surface.vertices[tri[1]], surface.vertices[tri[2]]);
    if (d > minDistance && d < std::numeric_limits<double>::infinity() && (!best || d < best->distance))
      best = RayHit{t, d};
  }
  return best;
}

std::vector<double> wallThickness(const TriangleMesh& surface) {
  std::vector<double> thickness(surface.vertices.size(), std::numeric_limits<double>::infinity());
  if (surface.triangles.empty()) return thickness;
  const ClosestPointTree tree(surface);
  for (std::uint32_t t = 0; t < surface.triangles.size(); ++t) {
    const TriangleMesh::Triangle& tri = surface.triangles[t];
    const Vec3 &a = surface.vertices[tri[0]], &b = surface.vertices[tri[1]], &c = surface.vertices[tri[2]];
    const Vec3 normal = (b - a).cross(c - a);
    const double area2 = normal.norm();
    if (!(area2 > 0.0)) continue;
    // Past the triangle's own plane by round-off, not past anything a real wall could be.
    const double size = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const auto hit = tree.firstHit((a + b + c) / 3.0, -normal / area2, 1e-9 * size, t);
    if (!hit) continue;
    for (const std::uint32_t v : tri)
      thickness[v] = std::min(thickness[v], hit->distance);
  }
  return thickness;
}

namespace {

constexpr std::uint32_t kLeafSize = 4;
/// A ClosestPointTree node over at least this many triangles builds its children in parallel: below it a
/// task costs more than it saves.
constexpr std::uint32_t kParallelBuild = 8192;

// The nearest float at or below x, and at or above it: a box rounded outward still holds what the
// double one did. Beyond float's range, the largest float or infinity (a conversion there is undefined).
constexpr float kFloatMax = std::numeric_limits<float>::max();
constexpr float kFloatInfinity = std::numeric_limits<float>::infinity();

float floatBelow(double x) {
  if (x >= static_cast<double>(kFloatMax)) return kFloatMax;
  if (x < -static_cast<double>(kFloatMax)) return -kFloatInfinity;
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -kFloatInfinity) : f;
}

float floatAbove(double x) {
  return -floatBelow(-x);
}

// Squared distances from p to the four boxes of a tree node, +∞ to an empty slot's: the four at once.
template <class Node>
Eigen::Array4d boxSquaredDistances(const Vec3& p, const Node& node) {
  Eigen::Array4d sum = Eigen::Array4d::Zero();
  for (std::size_t a = 0; a < 3; ++a) {
    const double x = p[static_cast<Eigen::Index>(a)];
    const Eigen::Array4d lo = Eigen::Map<const Eigen::Array4f>(node.min[a].data()).template cast<double>();
    const Eigen::Array4d hi = Eigen::Map<const Eigen::Array4f>(node.max[a].data()).template cast<double>();
    const Eigen::Array4d gap = (lo - x).max(x - hi).max(0.0);
    sum += gap * gap;
  }
  return sum;
}

/// Where the ray origin + t·direction enters child c's box of a tree node within t ∈ [near, far] (the
/// slab method), or +∞ if it does not. A ray along a box face counts as in the box; round-off may only
/// widen the interval.
template <class Node>
double rayBoxEntry(const Vec3& origin, const Vec3& direction, const Node& node, std::size_t c, double near,
                   double far) {
  for (int a = 0; a < 3; ++a) {
    const auto axis = static_cast<std::size_t>(a);
    const double l = node.min[axis][c], h = node.max[axis][c];
    if (direction[a] == 0.0) {
      if (origin[a] < l || origin[a] > h) return std::numeric_limits<double>::infinity();
      continue;
    }
    const double t1 = (l - origin[a]) / direction[a], t2 = (h - origin[a]) / direction[a];
    near = std::max(near, std::min(t1, t2));
    far = std::min(far, std::max(t1, t2));
  }
  return near <= far * (1.0 + 1e-12) + 1e-300 ? near : std::numeric_limits<double>::infinity();
}

/// A child waiting on a tree search's stack: a node (count 0) or a leaf's triangles, and its key (the
/// squared distance to its box, or where a ray enters it).
struct Pending {
  std::uint32_t child, count;
  double key;
};
// Each node popped pushes at most four: a tree over 2³² triangles is < 17 nodes deep.
using SearchStack = std::array<Pending, 72>;

/// Pushes the children of `node` whose key is finite, the smallest last so that it is taken first.
template <class Node>
void pushNearestLast(const Node& node, const std::array<double, 4>& keys, SearchStack& stack, int& top) {
  std::array<Pending, 4> sorted;
  int count = 0;
  for (std::size_t c = 0; c < 4; ++c) {
    if (!(keys[c] < std::numeric_limits<double>::infinity())) continue;
    int at = count++;
    for (; at > 0 && sorted[static_cast<std::size_t>(at - 1)].key < keys[c]; --at)
      sorted[static_cast<std::size_t>(at)] = sorted[static_cast<std::size_t>(at - 1)];
    sorted[static_cast<std::size_t>(at)] = {node.child[c], node.count[c], keys[c]};
  }
  for (int c = 0; c < count; ++c)
    stack[static_cast<std::size_t>(top++)] = sorted[static_cast<std::size_t>(c)];
}

// The sizes of a node's children over n triangles: n halved, and each half over a leaf's size halved
// again (the build's median splits), so that a node has two to four children.
std::array<std::uint32_t, 4> childSizes(std::uint32_t n, int& count) {
  std::array<std::uint32_t, 4> sizes{};
  count = 0;
  if (n <= kLeafSize) {
    sizes[count++] = n;
    return sizes;
  }
  for (const std::uint32_t half : {n / 2, n - n / 2}) {
    if (half <= kLeafSize) {
      sizes[count++] = half;
    } else {
      sizes[count++] = half / 2;
      sizes[count++] = half - half / 2;
    }
  }
  return sizes;
}

// How many nodes build() makes for n triangles, which follows from n alone (the node array is sized
// exactly once), memoized: every subtree size build() meets is entered, so that it can look up where
// each subtree goes.
std::size_t treeNodeCount(std::uint32_t n, std::map<std::uint32_t, std::size_t>& memo) {
  if (auto it = memo.find(n); it != memo.end()) return it->second;
  int children = 0;
  const std::array<std::uint32_t, 4> sizes = childSizes(n, children);
  std::size_t count = 1;
  for (int c = 0; c < children; ++c)
    if (sizes[static_cast<std::size_t>(c)] > kLeafSize)
      count += treeNodeCount(sizes[static_cast<std::size_t>(c)], memo);
  memo.emplace(n, count);
  return count;
}

}  // namespace

ClosestPointTree::ClosestPointTree(const TriangleMesh& surface, bool parallel) {
  const auto n = static_cast<std::uint32_t>(surface.triangles.size());
  if (n == 0) return;
  mOrder.resize(n);
  {
    std::vector<Keyed> items(n);
    for (std::uint32_t t = 0; t < n; ++t) {
      const auto& tri = surface.triangles[t];
      items[t] = {(surface.vertices[tri[0]] + surface.vertices[tri[1]] + surface.vertices[tri[2]]) / 3.0, t};
    }
    NodeCounts counts;
    mNodes.resize(treeNodeCount(n, counts));
    std::array<float, 3> lo{}, hi{};
    build(0, 0, n, surface, items, counts, parallel, lo, hi);
    for (std::uint32_t i = 0; i < n; ++i)
      mOrder[i] = items[i].triangle;
  }
  // Triangles in leaf order, so that a leaf's sit next to each other, and the vertices numbered as the
  // leaves first use them, so that a leaf's corners are near each other in memory too.
  constexpr std::uint32_t kUnseen = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> renumbered(surface.vertices.size(), kUnseen);
  mTriangles.resize(n);
  mPosition.resize(n);
  mVertices.reserve(surface.vertices.size());
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto& tri = surface.triangles[mOrder[i]];
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& v = renumbered[tri[k]];
      if (v == kUnseen) {
        v = static_cast<std::uint32_t>(mVertices.size());
        mVertices.push_back(surface.vertices[tri[k]]);
      }
      mTriangles[i][k] = v;
    }
    mPosition[mOrder[i]] = i;
  }
  mVertices.shrink_to_fit();  // a no-op unless the surface has vertices no triangle uses
}

TrianglePoint ClosestPointTree::closestOnTriangle(const Vec3& p, std::uint32_t position) const {
  const auto& t = mTriangles[position];
  return closestPointOnTriangle(p, mVertices[t[0]], mVertices[t[1]], mVertices[t[2]]);
}

// A node over items[begin, end): halved at the median centroid along the centroids' longest extent, and
// each half over a leaf's size halved again; each part a leaf or a node of its own. Boxes are merged
// bottom-up, so each triangle's corners are read once, at its leaf. A subtree's node count follows from
// its size, so each child's place is known before it is built: the children of a node over
// kParallelBuild triangles or more are built at once, each into its own range of mNodes and of items, and
// the tree is the one a serial build makes.
void ClosestPointTree::build(std::uint32_t index, std::uint32_t begin, std::uint32_t end,
                             const TriangleMesh& surface, std::vector<Keyed>& items, const NodeCounts& counts,
                             bool parallel, std::array<float, 3>& lo, std::array<float, 3>& hi) {
  {
    Node& node = mNodes[index];
    for (auto& axis : node.min)
      axis.fill(kFloatInfinity);
    for (auto& axis : node.max)
      axis.fill(-kFloatInfinity);
    node.child.fill(Node::kNoChild);
  }
  const auto split = [&](std::uint32_t b, std::uint32_t e) {
    Vec3 cmin = Vec3::Constant(std::numeric_limits<double>::infinity()), cmax = -cmin;
    for (std::uint32_t i = b; i < e; ++i) {
      cmin = cmin.cwiseMin(items[i].centroid);
      cmax = cmax.cwiseMax(items[i].centroid);
    }
    int axis = 0;
    (cmax - cmin).maxCoeff(&axis);
    const std::uint32_t mid = b + (e - b) / 2;
    std::nth_element(items.begin() + b, items.begin() + mid, items.begin() + e,
                     [axis](const Keyed& x, const Keyed& y) { return x.centroid[axis] < y.centroid[axis]; });
    return mid;
  };
  // The parts, in the order childSizes gives their sizes.
  std::array<std::uint32_t, 5> bounds{begin};
  std::size_t parts = 0;
  if (end - begin <= kLeafSize) {
    bounds[++parts] = end;
  } else {
    const std::uint32_t mid = split(begin, end);
    for (const auto& [b, e] : {std::pair{begin, mid}, std::pair{mid, end}}) {
      if (e - b > kLeafSize) bounds[++parts] = split(b, e);
      bounds[++parts] = e;
    }
  }
  // Where each part's subtree goes (a leaf's triangles stay where they are).
  std::array<std::uint32_t, 4> place{};
  std::size_t next = index + 1;
  for (std::size_t c = 0; c < parts; ++c)
    if (const std::uint32_t count = bounds[c + 1] - bounds[c]; count > kLeafSize) {
      place[c] = static_cast<std::uint32_t>(next);
      next += counts.at(count);
    }
  std::array<std::array<float, 3>, 4> clo{}, chi{};
  const auto part = [&](std::size_t c) {
    const std::uint32_t b = bounds[c], e = bounds[c + 1];
    if (e - b > kLeafSize) return build(place[c], b, e, surface, items, counts, parallel, clo[c], chi[c]);
    Vec3 dlo = Vec3::Constant(std::numeric_limits<double>::infinity()), dhi = -dlo;
    for (std::uint32_t i = b; i < e; ++i)
      for (std::uint32_t v : surface.triangles[items[i].triangle]) {
        dlo = dlo.cwiseMin(surface.vertices[v]);
        dhi = dhi.cwiseMax(surface.vertices[v]);
      }
    for (int a = 0; a < 3; ++a) {
      clo[c][static_cast<std::size_t>(a)] = floatBelow(dlo[a]);
      chi[c][static_cast<std::size_t>(a)] = floatAbove(dhi[a]);
    }
  };
  if (parallel && end - begin >= kParallelBuild) {
    tbb::parallel_for(std::size_t{0}, parts, part);
  } else {
    for (std::size_t c = 0; c < parts; ++c)
      part(c);
  }
  lo.fill(kFloatInfinity);
  hi.fill(-kFloatInfinity);
  Node& node = mNodes[index];
  for (std::size_t c = 0; c < parts; ++c) {
    const std::uint32_t count = bounds[c + 1] - bounds[c];
    node.child[c] = count > kLeafSize ? place[c] : bounds[c];
    node.count[c] = count > kLeafSize ? 0 : count;
    for (std::size_t a = 0; a < 3; ++a) {
      node.min[a][c] = clo[c][a];
      node.max[a][c] = chi[c][a];
      lo[a] = std::min(lo[a], clo[c][a]);
      hi[a] = std::max(hi[a], chi[c][a]);
    }
  }
}

ClosestPointTree::Hit ClosestPointTree::closest(const Vec3& p) const {
  return search(p, Hit{}, std::numeric_limits<double>::infinity());
}

ClosestPointTree::Hit ClosestPointTree::closest(const Vec3& p, std::uint32_t hint) const {
  if (hint >= mPosition.size()) return closest(p);
  const TrianglePoint q = closestOnTriangle(p, mPosition[hint]);
  return search(p, Hit{hint, q}, q.squaredDistance);
}

ClosestPointTree::Hit ClosestPointTree::search(const Vec3& p, Hit best, double bestSq) const {
  SearchStack stack;
  int top = 0;
  stack[static_cast<std::size_t>(top++)] = {0, 0, 0.0};
  while (top > 0) {
    const Pending pending = stack[static_cast<std::size_t>(--top)];
    if (pending.key >= bestSq) continue;
    if (pending.count > 0) {
      for (std::uint32_t i = pending.child; i < pending.child + pending.count; ++i) {
        const auto& t = mTriangles[i];
        const Vec3 &a = mVertices[t[0]], &b = mVertices[t[1]], &c = mVertices[t[2]];
        const Vec3 gap =
            (a.cwiseMin(b).cwiseMin(c) - p).cwiseMax(p - a.cwiseMax(b).cwiseMax(c)).cwiseMax(0.0);
        if (gap.squaredNorm() >= bestSq) continue;
        const TrianglePoint q = closestPointOnTriangle(p, a, b, c);
        if (q.squaredDistance < bestSq) {
          bestSq = q.squaredDistance;
          best = {mOrder[i], q};
        }
      }
      continue;
    }
    // The children that may hold a closer point.
    const Eigen::Array4d boxSq = boxSquaredDistances(p, mNodes[pending.child]);
    std::array<double, 4> keys;
    for (std::size_t c = 0; c < 4; ++c) {
      const double d = boxSq[static_cast<Eigen::Index>(c)];
      keys[c] = d < bestSq ? d : std::numeric_limits<double>::infinity();
    }
    pushNearestLast(mNodes[pending.child], keys, stack, top);
  }
  return best;
}

void ClosestPointTree::overlapping(const Vec3& lo, const Vec3& hi, std::vector<std::uint32_t>& out) const {
  if (mNodes.empty()) return;
  std::array<std::uint32_t, 72> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = mNodes[stack[--top]];
    for (std::size_t c = 0; c < 4; ++c) {
      bool meets = node.child[c] != Node::kNoChild;
      for (std::size_t a = 0; a < 3 && meets; ++a)
        meets = node.min[a][c] <= hi[static_cast<Eigen::Index>(a)] &&
                lo[static_cast<Eigen::Index>(a)] <= node.max[a][c];
      if (!meets) continue;
      if (node.count[c] > 0) {
        out.insert(out.end(), mOrder.begin() + node.child[c], mOrder.begin() + node.child[c] + node.count[c]);
      } else {
        stack[top++] = node.child[c];
      }
    }
  }
}

std::optional<RayHit> ClosestPointTree::firstHit(const Vec3& origin, const Vec3& direction,
                                                 double minDistance, std::uint32_t skip) const {
  std::optional<RayHit> best;
  if (mNodes.empty()) return best;
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double bestDistance = kInfinity;
  SearchStack stack;
  int top = 0;
  stack[static_cast<std::size_t>(top++)] = {0, 0, minDistance};
  while (top > 0) {
    const Pending pending = stack[static_cast<std::size_t>(--top)];
    if (pending.key > bestDistance) continue;  // the ray enters its box behind the best hit
    if (pending.count > 0) {
      for (std::uint32_t i = pending.child; i < pending.child + pending.count; ++i) {
        if (mOrder[i] == skip) continue;
        const auto& t = mTriangles[i];
        const double d =
            rayTriangleDistance(origin, direction, mVertices[t[0]], mVertices[t[1]], mVertices[t[2]]);
        if (d > minDistance && d < bestDistance) {
          bestDistance = d;
          best = RayHit{mOrder[i], d};
        }
      }
      continue;
    }
    // The children the ray enters before the best hit.
    const Node& node = mNodes[pending.child];
    std::array<double, 4> keys;
    for (std::size_t c = 0; c < 4; ++c)
      keys[c] = node.child[c] == Node::kNoChild
                    ? kInfinity
                    : rayBoxEntry(origin, direction, node, c, minDistance, bestDistance);
    pushNearestLast(node, keys, stack, top);
  }
  return best;
}

TetLocator::TetLocator(const TetMesh& mesh) : mNodes(mesh.nodes), mTets(mesh.tets) {
  const std::size_t n = mTets.size();
  mToWeights.resize(n);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& x : mNodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  for (std::size_t t = 0; t < n; ++t) {
    const auto& k = mTets[t];
    Mat3 edges;
    edges << mNodes[k[1]] - mNodes[k[0]], mNodes[k[2]] - mNodes[k[0]], mNodes[k[3]] - mNodes[k[0]];
    mToWeights[t] << edges.inverse(), mNodes[k[0]];
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
  const Eigen::Matrix<double, 3, 4>& m = mToWeights[t];
  const Vec3 l = m.leftCols<3>() * (p - m.col(3));
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
  // Well inside one tet: the tets of a conforming mesh do not overlap, so no other holds p. The tet that
  // held the last point is tried first: the next point on a surface is often in it too.
  if (hint && hint->tet < mTets.size()) {
    const auto w = weightsIn(hint->tet, p);
    if (minWeight(w) > kClearlyInside) return {hint->tet, w, 0.0};
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
      if (m > kClearlyInside) break;
    }
  }
  if (bestMin >= -kInsideTolerance) {
    if (hint) hint->tet = best.tet;
    return best;
  }
  return outside(p, hint);
}

SurfaceSide::SurfaceSide(const TriangleMesh& surface)
    : mTree(surface), mSurface(surface), mFirst(surface.vertices.size() + 1, 0) {
  // The triangles around each vertex, by counting.
  for (const TriangleMesh::Triangle& t : surface.triangles)
    for (const std::uint32_t v : t)
      ++mFirst[v + 1];
  std::partial_sum(mFirst.begin(), mFirst.end(), mFirst.begin());
  mIncident.resize(mFirst.back());
  std::vector<std::uint32_t> next(mFirst.begin(), mFirst.end() - 1);
  for (std::uint32_t t = 0; t < surface.triangles.size(); ++t)
    for (const std::uint32_t v : surface.triangles[t])
      mIncident[next[v]++] = t;
}

Vec3 SurfaceSide::faceNormal(std::uint32_t triangle) const {
  const TriangleMesh::Triangle& t = mSurface.triangles[triangle];
  const Vec3 n = (mSurface.vertices[t[1]] - mSurface.vertices[t[0]])
                     .cross(mSurface.vertices[t[2]] - mSurface.vertices[t[0]]);
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

double SurfaceSide::signedDistance(const Vec3& p) const {
  std::uint32_t none = ClosestPointTree::kNoHint;
  return signedDistance(p, none);
}

double SurfaceSide::signedDistance(const Vec3& p, std::uint32_t& near) const {
  const ClosestPointTree::Hit hit = mTree.closest(p, near);
  near = hit.triangle;
  // closestPointOnTriangle gives exact zeros outside the face's own Voronoi region: one zero, an edge;
  // two, a corner.
  const std::array<double, 3>& b = hit.closest.barycentric;
  const TriangleMesh::Triangle& tri = mSurface.triangles[hit.triangle];
  const int zeros = (b[0] == 0.0) + (b[1] == 0.0) + (b[2] == 0.0);
  Vec3 normal = Vec3::Zero();
  if (zeros == 2) {
    // A corner: every triangle around it, weighted by its angle there.
    const std::uint32_t v = tri[b[0] != 0.0 ? 0 : b[1] != 0.0 ? 1 : 2];
    for (std::uint32_t i = mFirst[v]; i < mFirst[v + 1]; ++i) {
      const TriangleMesh::Triangle& t = mSurface.triangles[mIncident[i]];
      const std::size_t k = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const Vec3 u = mSurface.vertices[t[(k + 1) % 3]] - mSurface.vertices[v];
      const Vec3 w = mSurface.vertices[t[(k + 2) % 3]] - mSurface.vertices[v];
      normal += std::atan2(u.cross(w).norm(), u.dot(w)) * faceNormal(mIncident[i]);
    }
  } else if (zeros == 1) {
    // An edge: the triangles on both sides of it (those around one end that hold the other).
    const std::size_t opposite = b[0] == 0.0 ? 0 : b[1] == 0.0 ? 1 : 2;
    const std::uint32_t from = tri[(opposite + 1) % 3], to = tri[(opposite + 2) % 3];
    for (std::uint32_t i = mFirst[from]; i < mFirst[from + 1]; ++i) {
      const TriangleMesh::Triangle& t = mSurface.triangles[mIncident[i]];
      if (t[0] == to || t[1] == to || t[2] == to) normal += faceNormal(mIncident[i]);
    }
  } else {
    normal = faceNormal(hit.triangle);
  }
  const double distance = std::sqrt(hit.closest.squaredDistance);
  return (p - hit.closest.point).dot(normal) < 0.0 ? -distance : distance;
}

double windingNumber(const TriangleMesh& surface, const Vec3& p) {
  // Van Oosterom & Strackee's solid angle of each triangle seen from p.
  double sum = 0.0;
  for (const TriangleMesh::Triangle& t : surface.triangles) {
    const Vec3 a = surface.vertices[t[0]] - p, b = surface.vertices[t[1]] - p, c = surface.vertices[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2.0 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4.0 * std::numbers::pi);
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
