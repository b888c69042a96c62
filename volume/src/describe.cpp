#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tree/ValueAccessor.h>

#include <shapedb/volume/describe.h>
#include <shapedb/volume/openvdb_runtime.h>

namespace shapedb::volume {

using core::DescriptorKind;
using core::Mat3;
using core::Sampling;
using core::Vec3;

namespace {

// Per cell: (weight, Σ weight · position), weight an area in cell units² or a vertex count.
using Accumulator = openvdb::math::Vec4<double>;
using AccumulatorTree = openvdb::tree::Tree4<Accumulator, 5, 4, 3>::Type;

// Coordinates are snapped to this lattice, in cells, before binning (see the class comment).
constexpr double kSnap = 1048576.0;  // 2^20

// A convex polygon in cell coordinates. A triangle cut by the planes of one cell has at most 9 vertices.
struct Polygon {
  int size = 0;
  std::array<Vec3, 12> v;
  void push(const Vec3& p) {
    assert(size < static_cast<int>(v.size()));
    v[static_cast<std::size_t>(size++)] = p;
  }
};

// Splits `in` by the plane {p[axis] = plane} into the parts below and above it (Sutherland–Hodgman,
// both sides in one pass). A point on the plane belongs above, unless `onPlaneBelow`.
void splitPolygon(const Polygon& in, int axis, double plane, bool onPlaneBelow, Polygon& below,
                  Polygon& above) {
  below.size = above.size = 0;
  const auto isAbove = [&](const Vec3& p) { return onPlaneBelow ? p[axis] > plane : p[axis] >= plane; };
  const Vec3* prev = &in.v[static_cast<std::size_t>(in.size - 1)];
  bool prevAbove = isAbove(*prev);
  for (int i = 0; i < in.size; ++i) {
    const Vec3& cur = in.v[static_cast<std::size_t>(i)];
    const bool curAbove = isAbove(cur);
    if (curAbove != prevAbove) {
      const double t = (plane - (*prev)[axis]) / (cur[axis] - (*prev)[axis]);
      Vec3 x = *prev + t * (cur - *prev);
      x[axis] = plane;
      below.push(x);
      above.push(x);
    }
    (curAbove ? above : below).push(cur);
    prev = &cur;
    prevAbove = curAbove;
  }
}

// Element-wise; std::array's operator== becomes a call to memcmp, which dominated the profile.
inline bool sameCell(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

}  // namespace

struct Describer::Impl {
  using Leaf = AccumulatorTree::LeafNodeType;

  std::vector<Vec3> cellCoords;                 // the mesh's vertices in cell units, snapped
  std::vector<std::array<int, 3>> vertexCells;  // floor of each, clamped to the grid
  std::vector<std::uint8_t> onPlane;            // bit a: the vertex lies on an interior cell plane ⟂ axis a
  AccumulatorTree tree{Accumulator(0.0)};
  openvdb::tree::ValueAccessor<AccumulatorTree> accessor{tree};
  struct FilledCell {
    std::uint32_t linearIndex;
    openvdb::Coord ijk;
    Accumulator value;
  };
  std::vector<FilledCell> filled;
  int gridSize = 0;

  // Consecutive triangles of a mesh mostly land in the same cell: sum there first, then write the
  // sum to the grid through the last leaf touched.
  std::array<int, 3> pendingCell{-1, -1, -1};
  Accumulator pending{0.0};
  Leaf* leaf = nullptr;
  openvdb::Coord leafOrigin;

  // The cell of coordinate u along an axis for a surface whose normal has component `normal` there.
  // Surface lying on a cell plane belongs to the cell behind it (inside the solid): a box face on a
  // plane goes to the box's side, whichever way the box is flipped.
  int cellOf(double u, double normal) const {
    return std::clamp(static_cast<int>(normal > 0.0 ? std::ceil(u) - 1.0 : std::floor(u)), 0, gridSize - 1);
  }

  void flush() {
    if (pendingCell[0] < 0) return;
    const openvdb::Coord ijk(pendingCell[0], pendingCell[1], pendingCell[2]);
    const openvdb::Coord origin = ijk & ~(Leaf::DIM - 1);
    if (leaf == nullptr || origin != leafOrigin) {
      leaf = accessor.touchLeaf(ijk);
      leafOrigin = origin;
    }
    const openvdb::Index offset = Leaf::coordToOffset(ijk);
    leaf->setValueOn(offset, leaf->getValue(offset) + pending);
    pendingCell[0] = -1;
  }

  void add(const std::array<int, 3>& cell, double weight, const Vec3& weightedPosition) {
    if (!sameCell(cell, pendingCell)) {
      flush();
      pendingCell = cell;
      pending = Accumulator(0.0);
    }
    pending += Accumulator(weight, weightedPosition.x(), weightedPosition.y(), weightedPosition.z());
  }

  // The part of a triangle's plane polygon in each cell, axis by axis: x slabs, then y, then z.
  // `normal` is the triangle's unit normal, to sign the fan areas.
  void clipAxis(const Polygon& poly, int axis, std::array<int, 3> cell, const Vec3& normal) {
    if (axis == 3) {
      double area = 0.0;
      Vec3 moment = Vec3::Zero();
      const Vec3& v0 = poly.v[0];
      for (int k = 1; k + 1 < poly.size; ++k) {
        const Vec3& v1 = poly.v[static_cast<std::size_t>(k)];
        const Vec3& v2 = poly.v[static_cast<std::size_t>(k + 1)];
        const double a = 0.5 * normal.dot((v1 - v0).cross(v2 - v0));
        area += a;
        moment += a * (v0 + v1 + v2) / 3.0;
      }
      if (area > 0.0) add(cell, area, moment);
      return;
    }
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int i = 0; i < poly.size; ++i) {
      lo = std::min(lo, poly.v[static_cast<std::size_t>(i)][axis]);
      hi = std::max(hi, poly.v[static_cast<std::size_t>(i)][axis]);
    }
    const int first = cellOf(lo, normal[axis]), last = cellOf(hi, normal[axis]);
    if (first == last) {
      cell[static_cast<std::size_t>(axis)] = first;
      clipAxis(poly, axis + 1, cell, normal);
      return;
    }
    // Peel off one slab at a time; the remainder alternates between two buffers.
    Polygon below, buffers[2];
    const Polygon* rest = &poly;
    for (int i = first; i < last; ++i) {
      Polygon& above = buffers[i & 1];
      splitPolygon(*rest, axis, i + 1, normal[axis] > 0.0, below, above);
      cell[static_cast<std::size_t>(axis)] = i;
      if (below.size >= 3) clipAxis(below, axis + 1, cell, normal);
      rest = &above;
    }
    cell[static_cast<std::size_t>(axis)] = last;
    if (rest->size >= 3) clipAxis(*rest, axis + 1, cell, normal);
  }

  // A triangle that one cell plane cuts in two: the piece on the side of the lone vertex is a
  // triangle whose area is A·t₁·t₂ (t the fractions of its two edges); the other piece is the rest.
  void splitOnce(const std::array<const Vec3*, 3>& v, int axis, int below, const Vec3& normal, double area,
                 const Vec3& moment, std::array<int, 3> cell) {
    const double plane = below + 1;
    const bool onPlaneBelow = normal[axis] > 0.0;
    std::array<bool, 3> above;
    for (std::size_t i = 0; i < 3; ++i)
      above[i] = onPlaneBelow ? (*v[i])[axis] > plane : (*v[i])[axis] >= plane;
    // The lone vertex: the one whose side differs from both others.
    const std::size_t lone = above[0] != above[1] ? (above[0] != above[2] ? 0 : 1) : 2;
    const Vec3& l = *v[lone];
    const Vec3& m = *v[(lone + 1) % 3];
    const Vec3& n = *v[(lone + 2) % 3];
    const double t1 = (plane - l[axis]) / (m[axis] - l[axis]), t2 = (plane - l[axis]) / (n[axis] - l[axis]);
    const double loneArea = area * t1 * t2;
    Vec3 x1 = l + t1 * (m - l), x2 = l + t2 * (n - l);
    x1[axis] = x2[axis] = plane;
    const Vec3 loneMoment = loneArea * (l + x1 + x2) / 3.0;
    std::array<int, 3> otherCell = cell;
    cell[static_cast<std::size_t>(axis)] = above[lone] ? below + 1 : below;
    otherCell[static_cast<std::size_t>(axis)] = above[lone] ? below : below + 1;
    if (loneArea > 0.0) add(cell, loneArea, loneMoment);
    if (area - loneArea > 0.0) add(otherCell, area - loneArea, moment - loneMoment);
  }

  void addTriangle(std::uint32_t ia, std::uint32_t ib, std::uint32_t ic) {
    const Vec3& a = cellCoords[ia];
    const Vec3& b = cellCoords[ib];
    const Vec3& c = cellCoords[ic];
    const Vec3 cross = (b - a).cross(c - a);
    const double twiceArea = cross.norm();
    if (!(twiceArea > 0.0)) return;
    const double area = 0.5 * twiceArea;
    const Vec3 moment = area * (a + b + c) / 3.0;
    // Most triangles of a fine mesh lie inside one cell.
    const std::array<int, 3>& cellA = vertexCells[ia];
    if (sameCell(cellA, vertexCells[ib]) && sameCell(cellA, vertexCells[ic]) &&
        (onPlane[ia] | onPlane[ib] | onPlane[ic]) == 0) {
      add(cellA, area, moment);
      return;
    }
    const Vec3 normal = cross / twiceArea;
    std::array<int, 3> lo, hi;
    int cut = 0, axisCut = -1;
    const bool touchesPlane = (onPlane[ia] | onPlane[ib] | onPlane[ic]) != 0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto i = static_cast<std::size_t>(axis);
      if (touchesPlane) {
        // A vertex on a plane: its cell depends on the side the surface lies (cellOf).
        lo[i] = cellOf(std::min({a[axis], b[axis], c[axis]}), normal[axis]);
        hi[i] = cellOf(std::max({a[axis], b[axis], c[axis]}), normal[axis]);
      } else {
        lo[i] = std::min({cellA[i], vertexCells[ib][i], vertexCells[ic][i]});
        hi[i] = std::max({cellA[i], vertexCells[ib][i], vertexCells[ic][i]});
      }
      if (hi[i] != lo[i]) {
        cut += hi[i] - lo[i];
        axisCut = axis;
      }
    }
    if (cut == 0) {
      add(lo, area, moment);
    } else if (cut == 1) {
      splitOnce({&a, &b, &c}, axisCut, lo[static_cast<std::size_t>(axisCut)], normal, area, moment, lo);
    } else {
      Polygon triangle;
      triangle.push(a);
      triangle.push(b);
      triangle.push(c);
      clipAxis(triangle, 0, lo, normal);
    }
  }
};

Describer::Describer(const core::DescriptorOptions& options)
    : mOptions(options), mImpl(std::make_unique<Impl>()) {
  initializeOpenVdb();
}
Describer::~Describer() = default;
Describer::Describer(Describer&&) noexcept = default;
Describer& Describer::operator=(Describer&&) noexcept = default;

Status validateDescriptorOptions(const core::DescriptorOptions& options) {
  if (options.gridSize < 2 || options.gridSize > core::kMaxGridSize)
    return Error{ErrorCode::kInvalidArgument, "grid size " + std::to_string(options.gridSize) +
                                                  " is outside [2, " + std::to_string(core::kMaxGridSize) +
                                                  "]"};
  if (!(options.minCellArea >= 0.0 && options.minCellArea < 1.0))
    return Error{ErrorCode::kInvalidArgument, "minimum cell area must be in [0, 1)"};
  return Ok{};
}

Result<core::Descriptor> Describer::describe(const core::TriangleMesh& mesh,
                                             const core::Normalization& normalization,
                                             const Mat3& orientation) {
  if (Status valid = validateDescriptorOptions(mOptions); !valid) return valid.error();
  core::Descriptor out;
  out.kind = mOptions.kind;
  out.sampling = mOptions.sampling;
  out.moments = normalization.canonicalMoments;
  out.orientation = orientation;
  if (mOptions.kind == DescriptorKind::kMoment) return out;

  // Vertices into the candidate frame; the grid's side is the largest extent there (§4.2).
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::uint32_t v : mesh.triangles[t])
      if (v >= mesh.vertices.size())
        return Error{ErrorCode::kIndexOutOfRange, "triangle " + std::to_string(t) + " refers to vertex " +
                                                      std::to_string(v) + " of " +
                                                      std::to_string(mesh.vertices.size())};
  Impl& s = *mImpl;
  const Mat3 linear = orientation * normalization.canonicalFromMesh.topLeftCorner<3, 3>();
  const Vec3 offset = orientation * normalization.canonicalFromMesh.topRightCorner<3, 1>();
  s.cellCoords.resize(mesh.vertices.size());
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3 p = linear * mesh.vertices[i] + offset;
    if (!p.allFinite())
      return Error{ErrorCode::kNonFinite,
                   "vertex " + std::to_string(i) + " is not finite in the canonical frame"};
    s.cellCoords[i] = p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double side = (hi - lo).maxCoeff();
  if (!(std::isfinite(side) && side > 0.0))
    return Error{ErrorCode::kInvalidArgument, "the normalized mesh has no extent"};
  const int n = mOptions.gridSize;
  const double cellSize = side / n, gridMin = -0.5 * side;
  s.gridSize = n;
  s.vertexCells.resize(mesh.vertices.size());
  s.onPlane.resize(mesh.vertices.size());
  const double toSnapped = kSnap / cellSize;
  for (std::size_t i = 0; i < s.cellCoords.size(); ++i) {
    Vec3& u = s.cellCoords[i];
    std::uint8_t planes = 0;
    for (int axis = 0; axis < 3; ++axis) {
      u[axis] = std::nearbyint((u[axis] - gridMin) * toSnapped) / kSnap;
      const double cell = std::floor(u[axis]);
      s.vertexCells[i][static_cast<std::size_t>(axis)] = std::clamp(static_cast<int>(cell), 0, n - 1);
      if (u[axis] == cell && cell > 0.0 && cell < n)
        planes = static_cast<std::uint8_t>(planes | (1u << axis));
    }
    s.onPlane[i] = planes;
  }

  // Accumulate weight and first moment per cell.
  if (mOptions.sampling == Sampling::kVertices) {
    for (std::size_t i = 0; i < s.cellCoords.size(); ++i)
      s.add(s.vertexCells[i], 1.0, s.cellCoords[i]);
  } else {
    for (const auto& t : mesh.triangles)
      s.addTriangle(t[0], t[1], t[2]);
  }
  s.flush();
  s.leaf = nullptr;

  // Read the active cells out in linear order, and leave the grid empty (nodes kept) for next time.
  s.filled.clear();
  for (auto it = s.tree.cbeginValueOn(); it; ++it) {
    const openvdb::Coord ijk = it.getCoord();
    s.filled.push_back({core::linearCell(ijk.x(), ijk.y(), ijk.z(), n), ijk, *it});
  }
  for (const Impl::FilledCell& cell : s.filled)
    s.accessor.setValueOff(cell.ijk, Accumulator(0.0));
  std::sort(s.filled.begin(), s.filled.end(), [](const Impl::FilledCell& a, const Impl::FilledCell& b) {
    return a.linearIndex < b.linearIndex;
  });

  const double minWeight = mOptions.sampling == Sampling::kArea ? mOptions.minCellArea : 1.0;
  const double weightToCanonical = mOptions.sampling == Sampling::kArea ? cellSize * cellSize : 1.0;
  out.gridSize = n;
  out.cellSize = cellSize;
  out.cells.reserve(s.filled.size());
  out.centroids.reserve(s.filled.size());
  out.weights.reserve(s.filled.size());
  for (const Impl::FilledCell& cell : s.filled) {
    const Accumulator& value = cell.value;
    const double weight = value[0];
    if (!(weight >= minWeight) || weight <= 0.0) continue;
    const Vec3 cellOrigin(cell.ijk.x(), cell.ijk.y(), cell.ijk.z());
    // Centroid in the cell's unit cube; surface outside the grid was binned into border cells.
    const Vec3 centroid =
        (Vec3(value[1], value[2], value[3]) / weight - cellOrigin).cwiseMax(0.0).cwiseMin(1.0);
    out.cells.push_back(cell.linearIndex);
    out.centroids.push_back(centroid);
    out.weights.push_back(weight * weightToCanonical);
  }
  return out;
}

Result<std::vector<core::Descriptor>> Describer::describeCandidates(
    const core::TriangleMesh& mesh, const core::Normalization& normalization,
    const core::OrientationOptions& orientation) {
  std::vector<core::Descriptor> out;
  const std::vector<Mat3> rotations = mOptions.kind == DescriptorKind::kMoment
                                          ? std::vector<Mat3>{Mat3::Identity()}
                                          : core::orientationCandidates(normalization, orientation);
  out.reserve(rotations.size());
  for (const Mat3& rotation : rotations) {
    // With area sampling, a candidate that only permutes or reverses axes (the sign flips of a
    // generic shape, the quarter turns of a square section) is the canonical grid reindexed.
    if (!out.empty() && mOptions.sampling == Sampling::kArea)
      if (std::optional<core::Descriptor> d = core::reorientDescriptor(out.front(), rotation)) {
        out.push_back(std::move(*d));
        continue;
      }
    Result<core::Descriptor> d = describe(mesh, normalization, rotation);
    if (!d) return d.error();
    out.push_back(std::move(d).value());
  }
  return out;
}

Result<core::Descriptor> describe(const core::TriangleMesh& mesh, const core::Normalization& normalization,
                                  const core::DescriptorOptions& options) {
  Describer describer(options);
  return describer.describe(mesh, normalization);
}

}  // namespace shapedb::volume
