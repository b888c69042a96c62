#include <cassert>
#include <cmath>

#include <shapedb/core/descriptor.h>

namespace shapedb::core {

Vec3 Descriptor::canonicalCentroid(std::size_t index) const {
  const std::uint32_t cell = cells[index];
  const std::uint32_t n = static_cast<std::uint32_t>(gridSize);
  const Vec3 ijk(cell % n, (cell / n) % n, cell / (n * n));
  const double lo = -0.5 * gridSize * cellSize;
  return Vec3::Constant(lo) + cellSize * (ijk + centroids[index]);
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
