#pragma once
// Spatial queries on the meshes a query meets: where a point lies in a tet mesh, and the closest point
// of a triangle surface. Both are built once per mesh and then answer queries from many threads.
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <vector>

#include <shapedb/core/physics.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// Closest point of a triangle to a point (Ericson, Real-Time Collision Detection §5.1.5), with the
/// barycentric coordinates of that point on the triangle (they sum to 1 and are ≥ 0).
struct TrianglePoint {
  Vec3 point = Vec3::Zero();
  std::array<double, 3> barycentric{};
  double squaredDistance = 0.0;
};
TrianglePoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Where a ray first crosses a triangle surface.
struct RayHit {
  std::uint32_t triangle = 0;
  double distance = 0.0;  ///< along the ray, in lengths of its direction
};

/// The t at which the line origin + t·direction crosses triangle abc, from either side, edges included
/// (Möller & Trumbore 1997): negative behind the origin; +∞ if it misses the triangle or runs in its
/// plane.
double rayTriangleDistance(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b,
                           const Vec3& c);

/// Closest-point (and ray) queries on a triangle surface: an AABB tree of four children a node (median
/// splits, two levels of them a node; ≤ 4 triangles a leaf), searched nearest box first. A node keeps its
/// four children's boxes side by side, axis by axis, so that their distances are computed together, and a
/// search descends half as many levels as a binary tree's. Keeps its own copy of the surface, triangles in
/// leaf order and vertices numbered in the order the leaves first use them, so that a search reads memory
/// nearly in sequence; the surface need not outlive it. Its boxes are single precision, rounded outward
/// (they still hold their triangles; distances are computed in double on the vertices): about 55 bytes a
/// triangle in all on a closed surface, built without a second copy, so that a ten-million-triangle scan's
/// costs about 0.55 GB. Immutable once built: concurrent queries are safe.
class ClosestPointTree {
 public:
  ClosestPointTree() = default;
  /// The tree of `surface`'s triangles. A large surface's is built on several threads (TBB), unless
  /// `parallel` is false: a process forked from one that runs TBB (TetGen's worker) has none of its
  /// threads, and must not use it. The tree is the same either way.
  explicit ClosestPointTree(const TriangleMesh& surface, bool parallel = true);

  struct Hit {
    std::uint32_t triangle = 0;  ///< index in the surface the tree was built from
    TrianglePoint closest;
  };
  /// The closest point of the surface to `p`. Precondition: the surface has a triangle.
  Hit closest(const Vec3& p) const;
  /// The same, starting from triangle `hint` (say, the answer for a nearby point; kNoHint, or any value
  /// out of range, for none): its distance bounds the search from the start, so fewer boxes are opened.
  /// The same closest point and distance whatever the hint; where several triangles are equally close
  /// (at a shared edge or vertex) it may name another of them.
  Hit closest(const Vec3& p, std::uint32_t hint) const;
  /// No triangle to start a search from (closest, and the searches built on it).
  static constexpr std::uint32_t kNoHint = std::numeric_limits<std::uint32_t>::max();
  /// The first triangle other than `skip` that the ray origin + t·direction crosses at a t over
  /// `minDistance`, nearest box first; none if it crosses none. Where it crosses several at the same t
  /// (through a shared edge) it may name any of them.
  std::optional<RayHit> firstHit(const Vec3& origin, const Vec3& direction, double minDistance = 0.0,
                                 std::uint32_t skip = std::numeric_limits<std::uint32_t>::max()) const;
  /// Appends to `out` every triangle whose box (the tree's own: single precision, rounded outward) meets
  /// the box [lo, hi]: every triangle that reaches into it, and maybe a few that only come close.
  void overlapping(const Vec3& lo, const Vec3& hi, std::vector<std::uint32_t>& out) const;
  bool empty() const { return mOrder.empty(); }
  std::size_t triangleCount() const { return mOrder.size(); }

 private:
  /// A node of up to four children, each a node or a leaf (a run of triangles); nodes in depth-first
  /// order, the root first. A slot with no child has an empty box (min +∞, max −∞) and kNoChild.
  struct Node {
    static constexpr std::uint32_t kNoChild = std::numeric_limits<std::uint32_t>::max();
    std::array<std::array<float, 4>, 3> min{}, max{};  ///< [axis][child]
    std::array<std::uint32_t, 4> child{};  ///< a node's index; a leaf's first triangle in mOrder, mTriangles
    std::array<std::uint32_t, 4> count{};  ///< a leaf's triangles (≥ 1); 0 for a node or no child
  };
  /// A triangle as the build splits them: its centroid beside its index, so that a split reads the
  /// centroids in sequence, not through the index.
  struct Keyed {
    Vec3 centroid;
    std::uint32_t triangle;
  };
  /// Node counts by number of triangles (a subtree's shape follows from its size alone).
  using NodeCounts = std::map<std::uint32_t, std::size_t>;
  /// Builds the node of triangles items[begin, end) at mNodes[index], its subtrees after it in depth-first
  /// order; `lo`, `hi` get its box. With `parallel`, large subtrees are built at once, into the places a
  /// serial build gives them.
  void build(std::uint32_t index, std::uint32_t begin, std::uint32_t end, const TriangleMesh& surface,
             std::vector<Keyed>& items, const NodeCounts& counts, bool parallel, std::array<float, 3>& lo,
             std::array<float, 3>& hi);
  Hit search(const Vec3& p, Hit best, double bestSq) const;
  std::vector<std::uint32_t> mOrder;                     ///< triangle indices, leaves contiguous
  std::vector<std::uint32_t> mPosition;                  ///< inverse of mOrder: where triangle t sits
  std::vector<std::array<std::uint32_t, 3>> mTriangles;  ///< the triangles, in the order of mOrder
  std::vector<Vec3> mVertices;  ///< the vertices the triangles use, in the order they first use them
  TrianglePoint closestOnTriangle(const Vec3& p, std::uint32_t position) const;
  std::vector<Node> mNodes;
};

/// The oracle of ClosestPointTree::firstHit: every triangle tried.
std::optional<RayHit> firstHitBruteForce(const TriangleMesh& surface, const Vec3& origin,
                                         const Vec3& direction, double minDistance = 0.0,
                                         std::uint32_t skip = std::numeric_limits<std::uint32_t>::max());

/// How thick the solid bounded by a closed, outward-wound surface is at each of its vertices: the least,
/// over the triangles around the vertex, of the distance from the triangle's centroid straight inward
/// (against its normal) to where that ray leaves the solid. A plate's or a beam's wall gets its
/// thickness, a ball its diameter. +∞ for a vertex whose triangles have no area or whose rays find no
/// other side (round-off at an edge). A ClosestPointTree answers the rays.
std::vector<double> wallThickness(const TriangleMesh& closedSurface);

/// Which side of a closed, consistently oriented surface a point lies on: the sign of (p − q) · n, q the
/// surface's closest point to p and n the angle-weighted pseudonormal of the face, edge or vertex that q
/// lies on (Bærentzen & Aanæs 2005), which is right wherever the closest point is, edges and corners
/// included. A ClosestPointTree search a point; the pseudonormal of the edge or corner found is made then,
/// from the triangles around it, so that building one costs the tree and a pass over the triangles.
/// Immutable once built: concurrent queries are safe.
class SurfaceSide {
 public:
  SurfaceSide() = default;
  /// Precondition: the surface is closed and its triangles wound outward (analyzeTopology); a triangle
  /// of zero area counts for no side.
  explicit SurfaceSide(const TriangleMesh& closedSurface);
  /// The distance from p to the surface, negative inside.
  double signedDistance(const Vec3& p) const;
  /// The same, the search started from triangle `near` (the one found for a nearby point, say;
  /// ClosestPointTree::kNoHint for none), which is then set to the triangle found: the same distance
  /// whatever the start (ClosestPointTree::closest).
  double signedDistance(const Vec3& p, std::uint32_t& near) const;
  bool inside(const Vec3& p) const { return signedDistance(p) < 0.0; }
  /// The closest-point tree it searches, for other queries on the same surface.
  const ClosestPointTree& tree() const { return mTree; }

 private:
  Vec3 faceNormal(std::uint32_t triangle) const;  ///< unit; 0 for a triangle of zero area
  ClosestPointTree mTree;
  TriangleMesh mSurface;
  std::vector<std::uint32_t> mFirst;     ///< per vertex, where its triangles start in mIncident
  std::vector<std::uint32_t> mIncident;  ///< the triangles around each vertex, vertex by vertex
};

/// The oracle of SurfaceSide: the generalized winding number of a closed surface about p (Jacobson et
/// al. 2013), the sum of its triangles' solid angles over 4π: 1 inside, 0 outside. Every triangle.
double windingNumber(const TriangleMesh& surface, const Vec3& p);

/// Where a point lies in a tet mesh: the tet that contains it and its barycentric weights, or, outside
/// the mesh, the tet owning the closest boundary face and the weights of that closest point. Either way
/// the four weights are ≥ 0 (to round-off) and sum to 1.
struct TetLocation {
  std::uint32_t tet = 0;
  std::array<double, 4> weights{};
  double distance = 0.0;  ///< 0 inside; else the distance to the mesh
  bool inside() const { return distance == 0.0; }
};

/// Point location in a tet mesh: a uniform grid of cells (about two per tet) listing the tets whose
/// bounding boxes overlap them, for points inside; a ClosestPointTree on the boundary faces, for points
/// outside. Among the tets containing a point (several, on a shared face or edge) the one where the point
/// is deepest wins, so the answer is the same as locateBruteForce's. Immutable once built.
class TetLocator {
 public:
  TetLocator() = default;
  /// Precondition: validateTetMesh(mesh) passed. Keeps a copy of what it needs.
  explicit TetLocator(const TetMesh& mesh);

  TetLocation locate(const Vec3& p) const;
  /// Carries the last boundary face found from one locate() to the next: points that follow each other
  /// on a surface are close, and so are their closest boundary faces. One per thread.
  struct Hint {
    std::uint32_t face = std::numeric_limits<std::uint32_t>::max();
    std::uint32_t tet = std::numeric_limits<std::uint32_t>::max();  ///< the last tet a point was inside
  };
  /// The same answer as locate(p), faster for a sequence of nearby points (outside the mesh, the
  /// closest point may be reported in another of the faces sharing it).
  TetLocation locate(const Vec3& p, Hint& hint) const;
  std::size_t tetCount() const { return mTets.size(); }
  /// The boundary faces, each wound outward, over the mesh's own node indices.
  const TriangleMesh& boundary() const { return mBoundarySurface; }
  const ClosestPointTree& boundaryTree() const { return mBoundary; }
  /// The tet each boundary face belongs to.
  const std::vector<std::uint32_t>& boundaryOwner() const { return mOwner; }

 private:
  friend TetLocation locateBruteForce(const TetLocator& locator, const Vec3& p);
  /// Barycentric weights of p in tet t: {1 − Σ, λ₁, λ₂, λ₃} with λ = inverse(edges) (p − a).
  std::array<double, 4> weightsIn(std::uint32_t t, const Vec3& p) const;
  TetLocation locate(const Vec3& p, Hint* hint) const;
  TetLocation outside(const Vec3& p, Hint* hint) const;

  std::vector<Vec3> mNodes;
  std::vector<TetMesh::Tet> mTets;
  /// Per tet: [B⁻¹ | a], B = [b − a, c − a, d − a], its barycentric coordinates λ₁, λ₂, λ₃ = B⁻¹ (p − a)
  /// from one record. (p − a first: exact enough wherever the mesh sits, far from the origin too.)
  std::vector<Eigen::Matrix<double, 3, 4>> mToWeights;
  Vec3 mOrigin = Vec3::Zero();
  Vec3 mInvCell = Vec3::Zero();
  std::array<int, 3> mDims{};
  std::vector<std::uint32_t> mCellBegin;  ///< CSR: cells + 1 offsets into mCellTets
  std::vector<std::uint32_t> mCellTets;
  TriangleMesh mBoundarySurface;
  ClosestPointTree mBoundary;
  std::vector<std::uint32_t> mOwner;
};

/// The oracle of TetLocator::locate: every tet tried, every boundary face measured.
TetLocation locateBruteForce(const TetLocator& locator, const Vec3& p);

}  // namespace shapedb::core
