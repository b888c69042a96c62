#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <shapedb/core/chunks.h>
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
// x fastest, as core::linearCell: offset i + N (j + N k).
using DenseGrid = openvdb::tools::Dense<Accumulator, openvdb::tools::LayoutXYZ>;
using Cell = std::array<int, 3>;

// Coordinates are snapped to this lattice, in cells, before binning (see the class comment).
constexpr double kSnap = 1048576.0;  // 2^20

// A triangle crossing more cell planes than this is clipped as a polygon, slab by slab (linear in the
// planes); below it, split into triangles (no loops, no square roots, but up to 3^k pieces).
constexpr int kMaxTriangleSplits = 3;

constexpr double kThird = 1.0 / 3.0;  // a multiplication: division is the slowest step of a split

// A convex polygon in cell coordinates. A triangle cut by the planes of one cell has at most 9 vertices.
struct Polygon {
  int size = 0;
  std::array<Vec3, 12> v;
  void push(const Vec3& p) {
    assert(size < static_cast<int>(v.size()));
    v[static_cast<std::size_t>(size++)] = p;
  }
};

// Which side of the plane {p[axis] = plane} a point is on. A point on the plane belongs above, unless
// `onPlaneBelow`: surface lying on a cell plane goes to the cell behind it (inside the solid), so the
// side is chosen by the surface normal (see cellOf).
inline bool isAbove(const Vec3& p, int axis, double plane, bool onPlaneBelow) {
  return onPlaneBelow ? p[axis] > plane : p[axis] >= plane;
}

// The cell of coordinate u along an axis for a surface whose normal has component `normal` there, clamped
// to the grid (surface outside it counts in the border cells). Agrees with isAbove on every plane.
inline int cellOf(double u, double normal, int gridSize) {
  return std::clamp(static_cast<int>(normal > 0.0 ? std::ceil(u) - 1.0 : std::floor(u)), 0, gridSize - 1);
}

// Splits `in` by the plane {p[axis] = plane} into the parts below and above it (Sutherland–Hodgman,
// both sides in one pass), sides by isAbove.
void splitPolygon(const Polygon& in, int axis, double plane, bool onPlaneBelow, Polygon& below,
                  Polygon& above) {
  below.size = above.size = 0;
  const Vec3* prev = &in.v[static_cast<std::size_t>(in.size - 1)];
  bool prevAbove = isAbove(*prev, axis, plane, onPlaneBelow);
  for (int i = 0; i < in.size; ++i) {
    const Vec3& cur = in.v[static_cast<std::size_t>(i)];
    const bool curAbove = isAbove(cur, axis, plane, onPlaneBelow);
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

// Area (signed by `normal`, the triangle's unit normal) and first moment of a convex polygon, by its fan.
std::pair<double, Vec3> areaAndMoment(const Polygon& poly, const Vec3& normal) {
  double area = 0.0;
  Vec3 moment = Vec3::Zero();
  const Vec3& v0 = poly.v[0];
  for (int k = 1; k + 1 < poly.size; ++k) {
    const Vec3& v1 = poly.v[static_cast<std::size_t>(k)];
    const Vec3& v2 = poly.v[static_cast<std::size_t>(k + 1)];
    const double a = 0.5 * normal.dot((v1 - v0).cross(v2 - v0));
    area += a;
    moment += a * kThird * (v0 + v1 + v2);
  }
  return {area, moment};
}

// Element-wise; std::array's operator== becomes a call to memcmp, which dominated the profile.
inline bool sameCell(const Cell& a, const Cell& b) {
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

}  // namespace

// The mesh's vertices in the candidate frame, in cell units, snapped; shared by the describer and by
// describeReference, so that both bin the very same coordinates.
struct SnappedVertices {
  std::vector<Vec3> coords;           // cell units: the grid is [0, N)³
  std::vector<Cell> cells;            // floor of each, clamped to the grid
  std::vector<std::uint8_t> onPlane;  // bit a: the vertex lies on an interior cell plane ⟂ axis a
  int gridSize = 0;
  double cellSize = 0.0;  // canonical units

  Status prepare(const core::TriangleMesh& mesh, const core::Normalization& normalization,
                 const Mat3& orientation, int n);
};

Status SnappedVertices::prepare(const core::TriangleMesh& mesh, const core::Normalization& normalization,
                                const Mat3& orientation, int n) {
  const std::size_t vertexCount = mesh.vertices.size();
  // The largest index first (a loop the compiler vectorizes), the culprit only if there is one.
  std::uint32_t largest = 0;
  for (const auto& t : mesh.triangles)
    largest = std::max({largest, t[0], t[1], t[2]});
  if (!mesh.triangles.empty() && largest >= vertexCount)
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      for (std::uint32_t v : mesh.triangles[t])
        if (v >= vertexCount)
          return Error{ErrorCode::kIndexOutOfRange, "triangle " + std::to_string(t) + " refers to vertex " +
                                                        std::to_string(v) + " of " +
                                                        std::to_string(vertexCount)};
  // Vertices into the candidate frame; the grid's side is the largest extent there (§4.2).
  const Mat3 linear = orientation * normalization.canonicalFromMesh.topLeftCorner<3, 3>();
  const Vec3 offset = orientation * normalization.canonicalFromMesh.topRightCorner<3, 1>();
  coords.resize(vertexCount);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t i = 0; i < vertexCount; ++i) {
    const Vec3 p = linear * mesh.vertices[i] + offset;
    if (!p.allFinite())
      return Error{ErrorCode::kNonFinite,
                   "vertex " + std::to_string(i) + " is not finite in the canonical frame"};
    coords[i] = p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double side = (hi - lo).maxCoeff();
  if (!(std::isfinite(side) && side > 0.0))
    return Error{ErrorCode::kInvalidArgument, "the normalized mesh has no extent"};
  gridSize = n;
  cellSize = side / n;
  const double gridMin = -0.5 * side, toSnapped = kSnap / cellSize;
  cells.resize(vertexCount);
  onPlane.resize(vertexCount);
  for (std::size_t i = 0; i < vertexCount; ++i) {
    Vec3& u = coords[i];
    std::uint8_t planes = 0;
    for (int axis = 0; axis < 3; ++axis) {
      u[axis] = std::nearbyint((u[axis] - gridMin) * toSnapped) / kSnap;
      const double cell = std::floor(u[axis]);
      cells[i][static_cast<std::size_t>(axis)] = std::clamp(static_cast<int>(cell), 0, n - 1);
      if (u[axis] == cell && cell > 0.0 && cell < n)
        planes = static_cast<std::uint8_t>(planes | (1u << axis));
    }
    onPlane[i] = planes;
  }
  return Ok{};
}

namespace {

// The descriptor from per-cell sums: `cells` ascending, `sums` beside them.
core::Descriptor finishDescriptor(const core::DescriptorOptions& options,
                                  const core::Normalization& normalization, const Mat3& orientation,
                                  const SnappedVertices& grid,
                                  const std::vector<std::pair<std::uint32_t, Accumulator>>& sums) {
  core::Descriptor out;
  out.kind = options.kind;
  out.sampling = options.sampling;
  out.moments = normalization.canonicalMoments;
  out.orientation = orientation;
  out.gridSize = grid.gridSize;
  out.cellSize = grid.cellSize;
  const double minWeight = options.sampling == Sampling::kArea ? options.minCellArea : 1.0;
  const double weightToCanonical = options.sampling == Sampling::kArea ? grid.cellSize * grid.cellSize : 1.0;
  out.cells.reserve(sums.size());
  out.centroids.reserve(sums.size());
  out.weights.reserve(sums.size());
  for (const auto& [cell, value] : sums) {
    const double weight = value[0];
    if (!(weight >= minWeight) || weight <= 0.0) continue;
    const Cell ijk = core::cellCoordinates(cell, grid.gridSize);
    const Vec3 cellOrigin(ijk[0], ijk[1], ijk[2]);
    // Centroid in the cell's unit cube; surface outside the grid was binned into border cells.
    const Vec3 centroid =
        (Vec3(value[1], value[2], value[3]) / weight - cellOrigin).cwiseMax(0.0).cwiseMin(1.0);
    out.cells.push_back(cell);
    out.centroids.push_back(centroid);
    out.weights.push_back(weight * weightToCanonical);
  }
  return out;
}

// Per-cell sums of weight and first moment on an N³ grid, all zero between uses, with a bit per cell
// written: read out in linear order without a sort, and only the cells written cleared.
class CellSums {
 public:
  void prepare(int n) {
    if (!mDense || mDense->bbox().dim().x() != n) {
      mDense = std::make_unique<DenseGrid>(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)),
                                           Accumulator(0.0));
      mWritten.assign((mDense->valueCount() + 63) / 64, 0);
    }
    static_assert(sizeof(Accumulator) == 4 * sizeof(double));
    mSums = reinterpret_cast<double*>(mDense->data());
    mGridSize = n;
  }

  void add(const Cell& cell, double weight, const Vec3& weightedPosition) {
    const std::uint32_t index = core::linearCell(cell[0], cell[1], cell[2], mGridSize);
    if (index != mPendingCell) {
      flush();
      mPendingCell = index;
    }
    mPending += Eigen::Vector4d(weight, weightedPosition.x(), weightedPosition.y(), weightedPosition.z());
  }

  void flush() {
    if (mPendingCell == kNoCell) return;
    write(mPendingCell, mPending);
    mPendingCell = kNoCell;
    mPending.setZero();
  }

  // Calls f(cell, sums) for every written cell in linear order, and clears it.
  template <typename F>
  void drain(F&& f) {
    flush();
    for (std::size_t w = 0; w < mWritten.size(); ++w) {
      for (std::uint64_t bits = mWritten[w]; bits != 0; bits &= bits - 1) {
        const auto index =
            static_cast<std::uint32_t>(64 * w + static_cast<std::size_t>(std::countr_zero(bits)));
        double* sum = mSums + 4 * std::size_t{index};
        f(index, Eigen::Vector4d(sum[0], sum[1], sum[2], sum[3]));
        std::fill(sum, sum + 4, 0.0);
      }
      mWritten[w] = 0;
    }
  }

  // Adds `other`'s sums into these, cell by cell, and clears `other`.
  void absorb(CellSums& other) {
    flush();
    other.drain([&](std::uint32_t cell, const Eigen::Vector4d& sum) { write(cell, sum); });
  }

 private:
  void write(std::uint32_t cell, const Eigen::Vector4d& sum) {
    Eigen::Map<Eigen::Vector4d>(mSums + 4 * std::size_t{cell}) += sum;
    mWritten[cell / 64] |= std::uint64_t{1} << (cell % 64);
  }

  // Consecutive pieces mostly land in the same cell: their sum is kept apart and written to the grid
  // (and its bit set) when the cell changes.
  static constexpr std::uint32_t kNoCell = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t mPendingCell = kNoCell;
  Eigen::Vector4d mPending = Eigen::Vector4d::Zero();
  std::unique_ptr<DenseGrid> mDense;
  double* mSums = nullptr;  // mDense's values as (weight, Σ weight·x, Σ weight·y, Σ weight·z) per cell
  std::vector<std::uint64_t> mWritten;
  int mGridSize = 0;
};

// Bins the surface of triangles into one CellSums, exactly.
struct Binner {
  const SnappedVertices& grid;
  CellSums& sums;

  void add(const Cell& cell, double weight, const Vec3& weightedPosition) {
    sums.add(cell, weight, weightedPosition);
  }

  int cellOf(double u, double normal) const { return volume::cellOf(u, normal, grid.gridSize); }

  // Narrows [lo, hi] to the cells `points` span, on the axes where the range is more than one cell.
  template <std::size_t K>
  void narrow(const std::array<const Vec3*, K>& points, const Vec3& normal, Cell& lo, Cell& hi) const {
    for (int axis = 0; axis < 3; ++axis) {
      const auto i = static_cast<std::size_t>(axis);
      if (lo[i] == hi[i]) continue;
      double min = (*points[0])[axis], max = min;
      for (std::size_t k = 1; k < K; ++k) {
        min = std::min(min, (*points[k])[axis]);
        max = std::max(max, (*points[k])[axis]);
      }
      const int first = std::clamp(cellOf(min, normal[axis]), lo[i], hi[i]);
      hi[i] = std::clamp(cellOf(max, normal[axis]), first, hi[i]);
      lo[i] = first;
    }
  }

  // A piece of a surface triangle (corners a, b, c in cell units, its area and first moment, the cells
  // [lo, hi] it spans per axis) binned exactly: split by the first cell plane it crosses into the
  // triangle on the lone vertex's side and the quadrilateral of the rest. With t₁, t₂ the fractions of
  // the lone vertex's two edges on its side of the plane, the lone triangle's area is A·t₁·t₂ and the
  // rest's A − A·t₁·t₂; the rest, if it crosses more planes, is split on as its two triangles, of areas
  // A·(1 − t₁) and A·t₁·(1 − t₂). No square root past the whole triangle's area. `normal`: the
  // triangle's normal, of any length (its signs decide the side of points on a plane, as in cellOf).
  void addPiece(const Vec3& a, const Vec3& b, const Vec3& c, double area, const Vec3& moment, const Cell& lo,
                const Cell& hi, const Vec3& normal) {
    int axis = 0;
    while (axis < 3 && lo[static_cast<std::size_t>(axis)] == hi[static_cast<std::size_t>(axis)])
      ++axis;
    if (axis == 3) {
      add(lo, area, moment);
      return;
    }
    const auto i = static_cast<std::size_t>(axis);
    const double plane = lo[i] + 1;
    const bool onPlaneBelow = normal[axis] > 0.0;
    const std::array<const Vec3*, 3> v = {&a, &b, &c};
    const std::array<bool, 3> above = {isAbove(a, axis, plane, onPlaneBelow),
                                       isAbove(b, axis, plane, onPlaneBelow),
                                       isAbove(c, axis, plane, onPlaneBelow)};
    // The lone vertex: the one whose side differs from both others (lo < hi: the sides differ).
    const std::size_t lone = above[0] != above[1] ? (above[0] != above[2] ? 0 : 1) : 2;
    const Vec3& l = *v[lone];
    const Vec3& m = *v[(lone + 1) % 3];
    const Vec3& n = *v[(lone + 2) % 3];
    // t₁ = d / (m − l), t₂ = d / (n − l) along the axis, with one division.
    const double d = plane - l[axis], dm = m[axis] - l[axis], dn = n[axis] - l[axis];
    const double r = d / (dm * dn), t1 = r * dn, t2 = r * dm;
    Vec3 x1 = l + t1 * (m - l), x2 = l + t2 * (n - l);
    x1[axis] = x2[axis] = plane;
    const double loneArea = area * t1 * t2, restArea = area - loneArea;
    const Vec3 loneMoment = loneArea * kThird * (l + x1 + x2);
    // One plane crossed and no other (most cut triangles): one cell each side.
    Cell next = lo;
    ++next[i];
    if (sameCell(next, hi)) {
      const bool loneAbove = above[lone];
      if (loneArea > 0.0) add(loneAbove ? hi : lo, loneArea, loneMoment);
      if (restArea > 0.0) add(loneAbove ? lo : hi, restArea, moment - loneMoment);
      return;
    }

    // Each side's cells: along the split axis the slab below the plane, or the slabs above it.
    const auto side = [&](bool isAboveSide, Cell& sLo, Cell& sHi) {
      sLo = lo;
      sHi = hi;
      (isAboveSide ? sLo : sHi)[i] = lo[i] + (isAboveSide ? 1 : 0);
    };
    if (loneArea > 0.0) {
      Cell sLo, sHi;
      side(above[lone], sLo, sHi);
      narrow(std::array<const Vec3*, 3>{&l, &x1, &x2}, normal, sLo, sHi);
      addPiece(l, x1, x2, loneArea, loneMoment, sLo, sHi, normal);
    }
    if (restArea > 0.0) {
      Cell sLo, sHi;
      side(!above[lone], sLo, sHi);
      narrow(std::array<const Vec3*, 4>{&x1, &m, &n, &x2}, normal, sLo, sHi);
      if (sameCell(sLo, sHi)) {
        add(sLo, restArea, moment - loneMoment);
        return;
      }
      const double first = area * (1.0 - t1), second = area * t1 * (1.0 - t2);
      if (first > 0.0) {
        Cell fLo = sLo, fHi = sHi;
        narrow(std::array<const Vec3*, 3>{&x1, &m, &n}, normal, fLo, fHi);
        addPiece(x1, m, n, first, first * kThird * (x1 + m + n), fLo, fHi, normal);
      }
      if (second > 0.0) {
        Cell fLo = sLo, fHi = sHi;
        narrow(std::array<const Vec3*, 3>{&x1, &n, &x2}, normal, fLo, fHi);
        addPiece(x1, n, x2, second, second * kThird * (x1 + n + x2), fLo, fHi, normal);
      }
    }
  }

  // The part of a large triangle's polygon in each cell, slab by slab: x, then y, then z.
  void clipAxis(const Polygon& poly, int axis, Cell cell, const Vec3& normal) {
    if (axis == 3) {
      const auto [area, moment] = areaAndMoment(poly, normal);
      if (area > 0.0) add(cell, area, moment);
      return;
    }
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < poly.size; ++k) {
      lo = std::min(lo, poly.v[static_cast<std::size_t>(k)][axis]);
      hi = std::max(hi, poly.v[static_cast<std::size_t>(k)][axis]);
    }
    const auto a = static_cast<std::size_t>(axis);
    const int first = cellOf(lo, normal[axis]), last = cellOf(hi, normal[axis]);
    if (first == last) {
      cell[a] = first;
      clipAxis(poly, axis + 1, cell, normal);
      return;
    }
    // Peel off one slab at a time; the remainder alternates between two buffers.
    Polygon below, buffers[2];
    const Polygon* rest = &poly;
    for (int k = first; k < last; ++k) {
      Polygon& above = buffers[k & 1];
      splitPolygon(*rest, axis, k + 1, normal[axis] > 0.0, below, above);
      cell[a] = k;
      if (below.size >= 3) clipAxis(below, axis + 1, cell, normal);
      rest = &above;
    }
    cell[a] = last;
    if (rest->size >= 3) clipAxis(*rest, axis + 1, cell, normal);
  }

  void addTriangle(std::uint32_t ia, std::uint32_t ib, std::uint32_t ic) {
    const Vec3& a = grid.coords[ia];
    const Vec3& b = grid.coords[ib];
    const Vec3& c = grid.coords[ic];
    const Vec3 cross = (b - a).cross(c - a);
    const double twiceArea = cross.norm();
    if (!(twiceArea > 0.0)) return;
    const double area = 0.5 * twiceArea;
    const Vec3 moment = area * kThird * (a + b + c);
    // Most triangles of a fine mesh lie inside one cell.
    const Cell& cellA = grid.cells[ia];
    const bool touchesPlane = (grid.onPlane[ia] | grid.onPlane[ib] | grid.onPlane[ic]) != 0;
    if (!touchesPlane && sameCell(cellA, grid.cells[ib]) && sameCell(cellA, grid.cells[ic])) {
      add(cellA, area, moment);
      return;
    }
    // Only the normal's signs matter to the splits; the polygon clipper needs it unit.
    Cell lo, hi;
    int crossings = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto i = static_cast<std::size_t>(axis);
      if (touchesPlane) {
        // A vertex on a plane: its cell depends on the side the surface lies (cellOf).
        lo[i] = cellOf(std::min({a[axis], b[axis], c[axis]}), cross[axis]);
        hi[i] = cellOf(std::max({a[axis], b[axis], c[axis]}), cross[axis]);
      } else {
        lo[i] = std::min({cellA[i], grid.cells[ib][i], grid.cells[ic][i]});
        hi[i] = std::max({cellA[i], grid.cells[ib][i], grid.cells[ic][i]});
      }
      crossings += hi[i] - lo[i];
    }
    if (crossings <= kMaxTriangleSplits) {
      addPiece(a, b, c, area, moment, lo, hi, cross);
    } else {
      Polygon triangle;
      triangle.push(a);
      triangle.push(b);
      triangle.push(c);
      clipAxis(triangle, 0, lo, cross / twiceArea);
    }
  }
};

// Area sampling of large meshes runs in core::Chunks of triangles, in parallel, each into its own sums,
// added in chunk order: the descriptor does not depend on the threads. Grids up to this many cells a
// side only (each chunk's sums are N³).
constexpr int kMaxChunkedGrid = 32;

}  // namespace

struct Describer::Impl {
  SnappedVertices grid;
  std::vector<CellSums> chunks;  // chunks[0] holds the result
  std::vector<std::pair<std::uint32_t, Accumulator>> filled;
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
  if (mOptions.kind == DescriptorKind::kMoment) {
    core::Descriptor out;
    out.kind = mOptions.kind;
    out.sampling = mOptions.sampling;
    out.moments = normalization.canonicalMoments;
    out.orientation = orientation;
    return out;
  }
  Impl& s = *mImpl;
  const int n = mOptions.gridSize;
  if (Status ok = s.grid.prepare(mesh, normalization, orientation, n); !ok) return ok.error();

  // Accumulate weight and first moment per cell.
  const core::Chunks chunks = mOptions.sampling == Sampling::kArea && n <= kMaxChunkedGrid
                                  ? core::Chunks(mesh.triangles.size())
                                  : core::Chunks(0);
  if (s.chunks.size() < chunks.count) s.chunks.resize(chunks.count);
  for (std::size_t c = 0; c < chunks.count; ++c)
    s.chunks[c].prepare(n);
  if (mOptions.sampling == Sampling::kVertices) {
    for (std::size_t i = 0; i < s.grid.coords.size(); ++i)
      s.chunks[0].add(s.grid.cells[i], 1.0, s.grid.coords[i]);
  } else if (chunks.count == 1) {
    Binner binner{s.grid, s.chunks[0]};
    for (const auto& t : mesh.triangles)
      binner.addTriangle(t[0], t[1], t[2]);
  } else {
    chunks.run([&](std::size_t c, std::size_t begin, std::size_t end) {
      Binner binner{s.grid, s.chunks[c]};
      for (std::size_t t = begin; t < end; ++t)
        binner.addTriangle(mesh.triangles[t][0], mesh.triangles[t][1], mesh.triangles[t][2]);
    });
    for (std::size_t c = 1; c < chunks.count; ++c)
      s.chunks[0].absorb(s.chunks[c]);
  }

  s.filled.clear();
  s.chunks[0].drain([&](std::uint32_t cell, const Eigen::Vector4d& sum) {
    s.filled.emplace_back(cell, Accumulator(sum[0], sum[1], sum[2], sum[3]));
  });
  return finishDescriptor(mOptions, normalization, orientation, s.grid, s.filled);
}

Result<std::vector<core::Descriptor>> Describer::describeCandidates(
    const core::TriangleMesh& mesh, const core::Normalization& normalization,
    const core::OrientationOptions& orientation) {
  std::vector<core::Descriptor> out;
  const std::vector<Mat3> rotations = mOptions.kind == DescriptorKind::kMoment
                                          ? std::vector<Mat3>{Mat3::Identity()}
                                          : core::orientationCandidates(normalization, orientation);
  out.reserve(rotations.size());
  // With area sampling, a candidate that differs from one described before by a rotation that only
  // permutes or reverses axes is that one's grid reindexed: the sign flips of a generic shape and the
  // quarter turns of a square section are the canonical grid's, and of a round shape's 24 turns of 15°
  // (48 with its axis reversed) only the six turns of 0-75° are described, the others being quarter
  // turns and reversals of those.
  std::vector<std::size_t> described;  // the candidates described from the surface
  for (const Mat3& rotation : rotations) {
    std::optional<core::Descriptor> reindexed;
    if (mOptions.sampling == Sampling::kArea)
      for (std::size_t k : described)
        if ((reindexed = core::reorientDescriptor(out[k], rotation * out[k].orientation.transpose()))) break;
    if (reindexed) {
      reindexed->orientation = rotation;  // the candidate's own, not the product's round-off
      out.push_back(std::move(*reindexed));
      continue;
    }
    Result<core::Descriptor> d = describe(mesh, normalization, rotation);
    if (!d) return d.error();
    described.push_back(out.size());
    out.push_back(std::move(d).value());
  }
  return out;
}

Result<core::Descriptor> describe(const core::TriangleMesh& mesh, const core::Normalization& normalization,
                                  const core::DescriptorOptions& options) {
  Describer describer(options);
  return describer.describe(mesh, normalization);
}

Result<core::Descriptor> describeReference(const core::TriangleMesh& mesh,
                                           const core::Normalization& normalization,
                                           const core::DescriptorOptions& options, const Mat3& orientation) {
  if (Status valid = validateDescriptorOptions(options); !valid) return valid.error();
  if (options.kind == DescriptorKind::kMoment || options.sampling != Sampling::kArea)
    return Error{ErrorCode::kInvalidArgument, "the reference describes voxel kinds by area only"};
  SnappedVertices grid;
  if (Status ok = grid.prepare(mesh, normalization, orientation, options.gridSize); !ok) return ok.error();
  const int n = options.gridSize;
  std::map<std::uint32_t, Accumulator> sums;
  for (const auto& t : mesh.triangles) {
    Polygon triangle;
    for (std::uint32_t v : t)
      triangle.push(grid.coords[v]);
    const Vec3 cross = (triangle.v[1] - triangle.v[0]).cross(triangle.v[2] - triangle.v[0]);
    if (!(cross.norm() > 0.0)) continue;
    const Vec3 normal = cross.normalized();
    Cell lo, hi;
    for (int axis = 0; axis < 3; ++axis) {
      const auto i = static_cast<std::size_t>(axis);
      lo[i] =
          cellOf(std::min({triangle.v[0][axis], triangle.v[1][axis], triangle.v[2][axis]}), normal[axis], n);
      hi[i] =
          cellOf(std::max({triangle.v[0][axis], triangle.v[1][axis], triangle.v[2][axis]}), normal[axis], n);
    }
    // Every cell of the range on its own: the triangle cut by the cell's interior planes (the border cells
    // reach out to infinity), kept on the cell's side of each.
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const Cell cell = {i, j, k};
          // The kept part alternates between two buffers (the cut-off part is dropped).
          Polygon kept[2], dropped;
          const Polygon* piece = &triangle;
          int next = 0;
          const auto keep = [&](int axis, double plane, bool keepAbove) {
            Polygon& out = kept[next];
            next ^= 1;
            const bool onPlaneBelow = normal[axis] > 0.0;
            splitPolygon(*piece, axis, plane, onPlaneBelow, keepAbove ? dropped : out,
                         keepAbove ? out : dropped);
            piece = &out;
          };
          for (int axis = 0; axis < 3 && piece->size >= 3; ++axis) {
            const int c = cell[static_cast<std::size_t>(axis)];
            if (c > 0) keep(axis, c, /*keepAbove=*/true);
            if (c < n - 1 && piece->size >= 3) keep(axis, c + 1, /*keepAbove=*/false);
          }
          if (piece->size < 3) continue;
          const auto [area, moment] = areaAndMoment(*piece, normal);
          if (area > 0.0)
            sums.try_emplace(core::linearCell(i, j, k, n), Accumulator(0.0)).first->second +=
                Accumulator(area, moment.x(), moment.y(), moment.z());
        }
  }
  const std::vector<std::pair<std::uint32_t, Accumulator>> filled(sums.begin(), sums.end());
  return finishDescriptor(options, normalization, orientation, grid, filled);
}

}  // namespace shapedb::volume
