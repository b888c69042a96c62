#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>

#include <shapedb/core/descriptor.h>

namespace shapedb::core {
namespace {

// Grids up to this many cells are put back in order through a table (reorientDescriptor).
constexpr std::size_t kReorderTableCells = 32768;

}  // namespace

Vec3 Descriptor::canonicalCentroid(std::size_t index) const {
  const std::array<int, 3> c = cellCoordinates(cells[index], gridSize);
  const Vec3 ijk(c[0], c[1], c[2]);
  const double lo = -0.5 * gridSize * cellSize;
  return Vec3::Constant(lo) + cellSize * (ijk + centroids[index]);
}

Status validateDescriptor(const Descriptor& d, const DescriptorOptions& options) {
  const auto fail = [](const std::string& what) {
    return Error{ErrorCode::kInvalidArgument, "descriptor: " + what};
  };
  if (d.kind != options.kind)
    return fail(std::string("is ") + toString(d.kind) + ", expected " + toString(options.kind));
  if (!d.moments.allFinite()) return fail("moments are not finite");
  if (d.kind == DescriptorKind::kMoment) return Ok{};
  if (options.gridSize < 2 || options.gridSize > kMaxGridSize)
    return fail("grid " + std::to_string(options.gridSize) + " is outside [2, " +
                std::to_string(kMaxGridSize) + "]");
  if (d.sampling != options.sampling || d.gridSize != options.gridSize)
    return fail("grid " + std::to_string(d.gridSize) + " with " + toString(d.sampling) +
                " sampling, expected " + std::to_string(options.gridSize) + " with " +
                toString(options.sampling));
  const auto cellCount = static_cast<std::uint64_t>(d.gridSize) * d.gridSize * d.gridSize;
  for (std::size_t i = 0; i < d.cells.size(); ++i) {
    if (d.cells[i] >= cellCount) return fail("cell " + std::to_string(d.cells[i]) + " is outside the grid");
    if (i > 0 && d.cells[i] <= d.cells[i - 1]) return fail("cells are not strictly ascending");
  }
  if (d.kind == DescriptorKind::kCentroidVoxel) {
    if (d.centroids.size() != d.cells.size())
      return fail(std::to_string(d.centroids.size()) + " centroids for " + std::to_string(d.cells.size()) +
                  " cells");
    for (const Vec3& c : d.centroids)
      if (!(c.array() >= 0.0).all() || !(c.array() <= 1.0).all())
        return fail("a centroid is outside its cell");
  }
  return Ok{};
}

double momentDistance(const Vec3& a, const Vec3& b) {
  return (a - b).squaredNorm();
}

namespace {

// Walks the two ascending cell lists once: calls both(ia, ib) for each cell filled in both, and
// returns the number filled in exactly one.
template <typename BothFn>
std::size_t mergeCells(const Descriptor& a, const Descriptor& b, BothFn&& both) {
  std::size_t ia = 0, ib = 0, exclusive = 0;
  while (ia < a.cells.size() && ib < b.cells.size()) {
    if (a.cells[ia] < b.cells[ib]) {
      ++exclusive, ++ia;
    } else if (b.cells[ib] < a.cells[ia]) {
      ++exclusive, ++ib;
    } else {
      both(ia++, ib++);
    }
  }
  return exclusive + (a.cells.size() - ia) + (b.cells.size() - ib);
}

}  // namespace

double voxelDistance(const Descriptor& a, const Descriptor& b) {
  assert(a.gridSize == b.gridSize);
  std::size_t common = 0;
  const std::size_t exclusive = mergeCells(a, b, [&](std::size_t, std::size_t) { ++common; });
  const std::size_t unionCount = exclusive + common;
  return unionCount == 0 ? 0.0 : static_cast<double>(exclusive) / static_cast<double>(unionCount);
}

double centroidVoxelDistance(const Descriptor& a, const Descriptor& b) {
  assert(a.gridSize == b.gridSize);
  const double invDiagonal = 1.0 / std::sqrt(3.0);
  double centroidTerms = 0.0;
  const std::size_t exclusive = mergeCells(a, b, [&](std::size_t ia, std::size_t ib) {
    centroidTerms += (a.centroids[ia] - b.centroids[ib]).norm() * invDiagonal;
  });
  // n_filled + n_eq = (exclusive + common) + common = n_a + n_b.
  const std::size_t denominator = a.cells.size() + b.cells.size();
  return denominator == 0 ? 0.0 : (static_cast<double>(exclusive) + centroidTerms) / denominator;
}

double descriptorDistance(const Descriptor& a, const Descriptor& b) {
  switch (a.kind) {
    case DescriptorKind::kMoment:
      return momentDistance(a.moments, b.moments);
    case DescriptorKind::kVoxel:
      return voxelDistance(a, b);
    case DescriptorKind::kCentroidVoxel:
      return centroidVoxelDistance(a, b);
  }
  return 0.0;
}

std::optional<Descriptor> reorientDescriptor(const Descriptor& d, const Mat3& rotation) {
  // Target axis a takes source axis source[a], reversed when reversed[a].
  std::array<int, 3> source{};
  std::array<bool, 3> reversed{};
  constexpr double kTolerance = 1e-12;
  for (int a = 0; a < 3; ++a) {
    int nonZero = 0;
    for (int b = 0; b < 3; ++b) {
      const double r = rotation(a, b);
      if (std::abs(r) <= kTolerance) continue;
      if (std::abs(std::abs(r) - 1.0) > kTolerance) return std::nullopt;
      source[static_cast<std::size_t>(a)] = b;
      reversed[static_cast<std::size_t>(a)] = r < 0.0;
      ++nonZero;
    }
    if (nonZero != 1) return std::nullopt;
  }
  if (source[0] == source[1] || source[1] == source[2] || source[0] == source[2]) return std::nullopt;

  Descriptor out = d;
  out.orientation = rotation * d.orientation;
  if (d.kind == DescriptorKind::kMoment) return out;
  const int n = d.gridSize;
  struct Cell {
    std::uint32_t linear;
    std::size_t from;
    Vec3 centroid;
  };
  std::vector<Cell> moved(d.cells.size());
  for (std::size_t i = 0; i < d.cells.size(); ++i) {
    const std::array<int, 3> ijk = cellCoordinates(d.cells[i], n);
    std::array<int, 3> to{};
    Vec3 centroid;
    for (std::size_t a = 0; a < 3; ++a) {
      const auto b = static_cast<std::size_t>(source[a]);
      const double c = d.centroids.empty() ? 0.5 : d.centroids[i][static_cast<Eigen::Index>(b)];
      to[a] = reversed[a] ? n - 1 - ijk[b] : ijk[b];
      centroid[static_cast<Eigen::Index>(a)] = reversed[a] ? 1.0 - c : c;
    }
    moved[i] = {linearCell(to[0], to[1], to[2], n), i, centroid};
  }
  // Back in ascending order: through a table of the grid's cells where it is small (a 10³ grid: a
  // thousand slots read once, cheaper than sorting the few hundred cells a surface fills), else sorted.
  const auto cellCount =
      static_cast<std::size_t>(n) * static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (cellCount <= kReorderTableCells) {
    constexpr auto kEmpty = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> at(cellCount, kEmpty);
    for (std::size_t i = 0; i < moved.size(); ++i)
      at[moved[i].linear] = static_cast<std::uint32_t>(i);
    std::vector<Cell> ordered;
    ordered.reserve(moved.size());
    for (std::uint32_t i : at)
      if (i != kEmpty) ordered.push_back(moved[i]);
    moved.swap(ordered);
  } else {
    std::sort(moved.begin(), moved.end(), [](const Cell& l, const Cell& r) { return l.linear < r.linear; });
  }
  for (std::size_t i = 0; i < moved.size(); ++i) {
    out.cells[i] = moved[i].linear;
    if (!d.centroids.empty()) out.centroids[i] = moved[i].centroid;
    if (!d.weights.empty()) out.weights[i] = d.weights[moved[i].from];
  }
  return out;
}

const char* toString(DescriptorKind kind) {
  switch (kind) {
    case DescriptorKind::kMoment:
      return "moment";
    case DescriptorKind::kVoxel:
      return "voxel";
    case DescriptorKind::kCentroidVoxel:
      return "centroid-voxel";
  }
  return "unknown";
}

const char* toString(Sampling sampling) {
  return sampling == Sampling::kArea ? "area" : "vertices";
}

std::optional<DescriptorKind> parseDescriptorKind(std::string_view name) {
  for (DescriptorKind kind :
       {DescriptorKind::kMoment, DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel})
    if (name == toString(kind)) return kind;
  return std::nullopt;
}

std::optional<Sampling> parseSampling(std::string_view name) {
  if (name == "area") return Sampling::kArea;
  if (name == "vertices") return Sampling::kVertices;
  return std::nullopt;
}

}  // namespace shapedb::core
