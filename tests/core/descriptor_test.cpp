#include <cmath>

#include <gtest/gtest.h>

#include <shapedb/core/descriptor.h>

namespace shapedb::core {
namespace {

Descriptor grid(DescriptorKind kind, std::vector<std::uint32_t> cells, std::vector<Vec3> centroids = {}) {
  Descriptor d;
  d.kind = kind;
  d.gridSize = 4;
  d.cellSize = 0.25;
  d.cells = std::move(cells);
  d.centroids =
      centroids.empty() ? std::vector<Vec3>(d.cells.size(), Vec3::Constant(0.5)) : std::move(centroids);
  d.weights.assign(d.cells.size(), 1.0);
  return d;
}

TEST(Similarity, MomentDistanceIsSquaredEuclidean) {
  EXPECT_DOUBLE_EQ(momentDistance(Vec3(1, 2, 3), Vec3(1, 2, 3)), 0.0);
  EXPECT_DOUBLE_EQ(momentDistance(Vec3(1, 2, 3), Vec3(2, 4, 3)), 5.0);  // eq. (4): 1 + 4
}

TEST(Similarity, VoxelDistanceIsMismatchesOverUnion) {
  const Descriptor a = grid(DescriptorKind::kVoxel, {0, 1, 2});
  const Descriptor b = grid(DescriptorKind::kVoxel, {1, 2, 3});
  // Cells 0 and 3 mismatch; the union is {0, 1, 2, 3}.
  EXPECT_DOUBLE_EQ(voxelDistance(a, b), 2.0 / 4.0);
  EXPECT_DOUBLE_EQ(voxelDistance(a, a), 0.0);
  EXPECT_DOUBLE_EQ(voxelDistance(a, grid(DescriptorKind::kVoxel, {5, 6})), 1.0);
  EXPECT_DOUBLE_EQ(voxelDistance(grid(DescriptorKind::kVoxel, {}), grid(DescriptorKind::kVoxel, {})), 0.0);
  EXPECT_DOUBLE_EQ(voxelDistance(a, b), voxelDistance(b, a));
}

TEST(Similarity, CentroidVoxelDistanceAddsCentroidTermsOverCountSum) {
  const Descriptor a =
      grid(DescriptorKind::kCentroidVoxel, {0, 1, 2}, {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0.5, 0.5, 0.5)});
  const Descriptor b =
      grid(DescriptorKind::kCentroidVoxel, {1, 2, 3}, {Vec3(1, 1, 1), Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0)});
  // Eq. (6): 2 mismatching cells, cell 1 at the full diagonal (term 1), cell 2 identical (term 0);
  // n_filled + n_eq = 4 + 2 = 6.
  EXPECT_NEAR(centroidVoxelDistance(a, b), (2.0 + 1.0 + 0.0) / 6.0, 1e-15);
  EXPECT_DOUBLE_EQ(centroidVoxelDistance(a, a), 0.0);
  EXPECT_DOUBLE_EQ(centroidVoxelDistance(a, grid(DescriptorKind::kCentroidVoxel, {7})), 1.0);
  EXPECT_DOUBLE_EQ(centroidVoxelDistance(a, b), centroidVoxelDistance(b, a));
}

TEST(Similarity, CanonicalCentroidIsInsideItsCell) {
  Descriptor d = grid(DescriptorKind::kCentroidVoxel, {1 + 4 * (2 + 4 * 3)}, {Vec3(0.5, 0.25, 1.0)});
  // Grid of 4 cells of 0.25 from −0.5: cell (1, 2, 3) spans [−0.25, 0] × [0, 0.25] × [0.25, 0.5].
  const Vec3 c = d.canonicalCentroid(0);
  EXPECT_NEAR(c.x(), -0.125, 1e-15);
  EXPECT_NEAR(c.y(), 0.0625, 1e-15);
  EXPECT_NEAR(c.z(), 0.5, 1e-15);
}

TEST(Similarity, NamesRoundTrip) {
  for (DescriptorKind kind :
       {DescriptorKind::kMoment, DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel})
    EXPECT_EQ(parseDescriptorKind(toString(kind)), kind);
  EXPECT_EQ(parseSampling("area"), Sampling::kArea);
  EXPECT_EQ(parseSampling("vertices"), Sampling::kVertices);
  EXPECT_FALSE(parseDescriptorKind("voxels").has_value());
  EXPECT_FALSE(parseSampling("").has_value());
}

}  // namespace
}  // namespace shapedb::core
