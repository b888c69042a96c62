// Simplification: fewer triangles, the same closed solid within the stated distance.

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/simplify.h>

namespace shapedb::volume {
namespace {

TEST(Simplify, AFineSphereComesDownToTheTargetWithinTheErrorBound) {
  const core::TriangleMesh sphere = core::makeIcosphere(1.0, 5);  // 20,480 triangles
  SimplifyOptions options;
  options.maxTriangles = 2000;
  options.maxError = 0.01;
  Result<core::TriangleMesh> r = simplify(sphere, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_LE(r->triangles.size(), 2000u);
  EXPECT_GE(r->triangles.size(), 1000u);
  EXPECT_TRUE(core::requireClosedOriented(core::analyzeTopology(*r)).ok());
  // Every kept vertex lies near the original surface, and every original vertex near the new one.
  const core::ClosestPointTree original(sphere), simplified(*r);
  double worst = 0.0;
  for (const core::Vec3& p : r->vertices)
    worst = std::max(worst, (original.closest(p).closest.point - p).norm());
  for (const core::Vec3& p : sphere.vertices)
    worst = std::max(worst, (simplified.closest(p).closest.point - p).norm());
  EXPECT_LT(worst, 2.0 * options.maxError);
  const auto before = core::computeMassProperties(sphere), after = core::computeMassProperties(*r);
  ASSERT_TRUE(before.ok() && after.ok());
  EXPECT_NEAR(after->volume / before->volume, 1.0, 0.01);
}

TEST(Simplify, TheErrorBoundStopsItBeforeTheTarget) {
  // A tight bound on a curved surface: most collapses are refused.
  const core::TriangleMesh sphere = core::makeIcosphere(1.0, 4);  // 5,120 triangles
  SimplifyOptions options;
  options.maxTriangles = 100;
  options.maxError = 1e-4;
  Result<core::TriangleMesh> r = simplify(sphere, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_GT(r->triangles.size(), 1000u);
}

TEST(Simplify, ASmallMeshIsUnchangedAndBadInputIsAnError) {
  const core::TriangleMesh box = core::makeBox({1, 2, 3});
  Result<core::TriangleMesh> same = simplify(box);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->vertices, box.vertices);
  EXPECT_EQ(same->triangles, box.triangles);
  core::TriangleMesh open = core::makeIcosphere(1.0, 3);
  open.triangles.pop_back();
  EXPECT_EQ(simplify(open).error().code, ErrorCode::kNotClosed);
  SimplifyOptions none;
  none.maxError = 0.0;
  EXPECT_EQ(simplify(box, none).error().code, ErrorCode::kInvalidArgument);
}

// What add and enrich mesh: a surface over the limit simplified within 1e-3 of its size ∛V (whatever its
// scale), one at or under it, or with no limit, as given (none: the mesh itself, not a copy).
TEST(SurfaceForEntry, SimplifiesOnlyOverTheLimitWithinAThousandthOfTheSize) {
  for (const double radius : {1.0, 0.002}) {
    SCOPED_TRACE(radius);
    const core::TriangleMesh sphere = core::makeIcosphere(radius, 4);  // 5,120 triangles
    Result<std::optional<core::TriangleMesh>> r = surfaceForEntry(sphere, 3000);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_TRUE(r->has_value());
    const core::TriangleMesh& simplified = **r;
    EXPECT_LE(simplified.triangles.size(), 3000u);
    const double size = std::cbrt(core::computeMassProperties(sphere)->volume);
    const core::ClosestPointTree original(sphere);
    for (const core::Vec3& p : simplified.vertices)
      EXPECT_LT((original.closest(p).closest.point - p).norm(), 2e-3 * size);
    for (const std::size_t limit : {std::size_t{0}, std::size_t{5120}}) {
      // None: the mesh itself is meshed, as given.
      Result<std::optional<core::TriangleMesh>> same = surfaceForEntry(sphere, limit);
      ASSERT_TRUE(same.ok());
      EXPECT_FALSE(same->has_value());
    }
  }
}

}  // namespace
}  // namespace shapedb::volume
