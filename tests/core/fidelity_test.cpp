// How closely a match fits its query (core/fidelity.h): nothing for the same shape, more for another.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/fidelity.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/spatial.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

TEST(Fidelity, ZeroForTheSameShapeAndGrowsWithTheDifference) {
  std::mt19937_64 rng(9);
  // The same unit cube as entry (tets) and as query (surface), the query turned, moved and scaled.
  TetMesh tets = test::makeTetGrid(3, 3, 3, 0.0, rng);
  for (Vec3& x : tets.nodes)
    x = (x - Vec3::Constant(1.5)) / 3.0;
  const TetLocator locator(tets);
  const MassProperties entryMass = computeTetMassProperties(tets);
  const double L = 2.0;
  const Mat3 R = test::randomRotation(rng);
  Normalization q;
  q.scale = 1.0 / L;
  q.principalAxes = R;
  q.meshFromCanonical.topRightCorner<3, 1>() = Vec3(1, 2, 3);
  q.canonicalMoments = Vec3::Constant(1.0 / 6.0);
  const Placement placement = placementOf(q, Mat3::Identity());
  TriangleMesh query = locator.boundary();
  for (Vec3& v : query.vertices)
    v = placement.toQuery(v);
  const Fidelity same = assessFidelity(query, ClosestPointTree(query), q, locator, entryMass, placement, 0.0);
  EXPECT_LT(same.maxDeviation, 1e-12);
  EXPECT_LT(same.maxMomentError, 1e-12);
  EXPECT_EQ(same.samples, 2048);

  // Stretch the query by 10 % along one axis: deviations of a few per cent of L, moments off.
  TriangleMesh stretched = query;
  for (Vec3& v : stretched.vertices)
    v = Vec3(1, 2, 3) + R * (Vec3(1.1, 1.0, 1.0).asDiagonal() * (R.transpose() * (v - Vec3(1, 2, 3))));
  q.canonicalMoments = Vec3(1.0, 1.0, 1.0);  // any different moments
  const Fidelity off =
      assessFidelity(stretched, ClosestPointTree(stretched), q, locator, entryMass, placement, 0.3);
  EXPECT_GT(off.meanDeviation, 0.005);
  EXPECT_NEAR(off.maxDeviation, 0.05, 0.01) << "the stretched faces stand 0.1 L / 2 off the entry's";
  EXPECT_GT(off.maxMomentError, 0.5);
  EXPECT_DOUBLE_EQ(off.descriptorDistance, 0.3);
}

}  // namespace
}  // namespace shapedb::core
