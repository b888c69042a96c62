#include <cassert>
#include <cmath>
#include <string>

#include <shapedb/core/descriptor.h>

namespace shapedb::core {

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
