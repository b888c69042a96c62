// The link stage (link.h): barycentric weights inside, the closest boundary point outside, in the
// query's frame and units; deformSurface moves linked vertices with the tets.

#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/link.h>
#include <shapedb/core/spatial.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

TEST(Link, WeightsSumToOneAndReproduceInsideVertices) {
  std::mt19937_64 rng(3);
  const TetMesh mesh = test::makeTetGrid(5, 5, 5, 0.25, rng);
  const TetLocator locator(mesh);
  // A placement of scale 2, turned and moved: the "query" lives in another frame than the entry.
  Placement placement{test::randomRotation(rng), Vec3(1, -2, 3), 2.0};
  std::vector<Vec3> vertices;
  std::uniform_real_distribution<double> u(-0.5, 5.5);
  for (int i = 0; i < 5000; ++i)
    vertices.push_back(placement.toQuery(Vec3(u(rng), u(rng), u(rng))));
  const SurfaceLink link = linkSurface(locator, placement, vertices);
  ASSERT_EQ(link.locations.size(), vertices.size());
  TetMesh placed = mesh;
  for (Vec3& x : placed.nodes)
    x = placement.toQuery(x);
  std::size_t outside = 0;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const TetLocation& l = link.locations[i];
    ASSERT_NEAR(l.weights[0] + l.weights[1] + l.weights[2] + l.weights[3], 1.0, 1e-12);
    const double error = (test::interpolate(placed, l) - vertices[i]).norm();
    if (l.inside()) {
      ASSERT_LT(error, 1e-11);
    } else {
      ++outside;
      ASSERT_NEAR(error, l.distance, 1e-9) << "outside: tied to the closest point, distance in query units";
    }
  }
  EXPECT_EQ(outside, link.outsideCount);
  EXPECT_GT(outside, 0u);

  // A rigid translation of every node moves every linked vertex by the same amount.
  Eigen::VectorXd shift(3 * static_cast<Eigen::Index>(placed.nodeCount()));
  for (Eigen::Index i = 0; i < shift.size() / 3; ++i)
    shift.segment<3>(3 * i) = Vec3(0.1, 0.2, -0.3);
  std::vector<Vec3> moved;
  deformSurface(link, placed, shift, vertices, moved);
  for (std::size_t i = 0; i < vertices.size(); ++i)
    ASSERT_LT((moved[i] - vertices[i] - Vec3(0.1, 0.2, -0.3)).norm(), 1e-12);
}

}  // namespace
}  // namespace shapedb::core
