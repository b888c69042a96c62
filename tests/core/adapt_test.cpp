#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/adapt.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

TEST(Adapt, ScalesMassFrequenciesAndModesAndPlacesTheTets) {
  std::mt19937_64 rng(5);
  PhysicalData entry;
  entry.tetMesh = test::makeTetGrid(2, 2, 2, 0.1, rng);
  for (Vec3& x : entry.tetMesh.nodes)
    x = (x - Vec3::Constant(1.0)) / 2.0;  // unit volume, centred
  entry.massProperties = computeTetMassProperties(entry.tetMesh);
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(entry.tetMesh.nodeCount());
  entry.modes.poissonRatio = 0.3;
  entry.modes.eigenvalues.resize(3);
  entry.modes.eigenvalues << 2.0, 5.0, 9.0;
  entry.modes.shapes = Eigen::MatrixXd::Random(n, 3);
  entry.collision.shapes.push_back(
      {CollisionShape::Type::kCapsule, Vec3(0.1, 0, 0), Mat3::Identity(), Vec3::Zero(), 0.2, 0.3});

  // The query: the same cube, scaled by 3 (L = 3), turned and moved.
  const double L = 3.0;
  Normalization q;
  q.scale = 1.0 / L;
  q.principalAxes = test::randomRotation(rng);
  q.meshFromCanonical.topLeftCorner<3, 3>() = L * q.principalAxes;
  q.meshFromCanonical.topRightCorner<3, 1>() = Vec3(4, 5, 6);
  MassProperties qm;
  qm.density = 1.0;
  qm.volume = L * L * L;
  qm.mass = qm.volume;
  qm.inertia = Mat3::Identity() * std::pow(L, 5) / 6.0;
  const Mat3 orientation = Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitY()).toRotationMatrix();

  Material steel = *materialPreset("Steel");
  auto a = adapt(entry, q, qm, orientation, steel, {2.0, 1e-6});
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_TRUE(a->warnings.empty());
  EXPECT_NEAR(a->massProperties.mass, 7850.0 * 27.0, 1e-6);
  EXPECT_NEAR(a->entryMassProperties.mass, 7850.0 * 27.0, 1e-6);
  EXPECT_LT((a->entryMassProperties.centerOfMass - Vec3(4, 5, 6)).norm(), 1e-9);
  const Eigen::VectorXd expected = entry.modes.frequenciesHz() * std::sqrt(200e9 / 7850.0) / L;
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(a->frequenciesHz()[i] / expected[i], 1.0, 1e-12);
  // Placement: node i sits at c + L R Oᵀ e.
  const Mat3 A = q.principalAxes * orientation.transpose();
  for (std::size_t i = 0; i < entry.tetMesh.nodeCount(); ++i)
    ASSERT_LT((a->tetMesh.nodes[i] - (Vec3(4, 5, 6) + L * A * entry.tetMesh.nodes[i])).norm(), 1e-12);
  // Tet mass properties of the placed mesh at steel's density equal the scaled entry's.
  const MassProperties placed = computeTetMassProperties(a->tetMesh, steel.density);
  EXPECT_NEAR(placed.mass / a->entryMassProperties.mass, 1.0, 1e-12);
  EXPECT_LT((placed.inertia - a->entryMassProperties.inertia).norm() / placed.inertia.norm(), 1e-12);
  // Mode shapes: rotated node by node, scaled by 1/sqrt(ρL³).
  const double s = 1.0 / std::sqrt(steel.density * L * L * L);
  for (Eigen::Index i = 0; i < n / 3; ++i)
    ASSERT_LT((a->modeShapes.block<3, 3>(3 * i, 0) - s * A * entry.modes.shapes.block<3, 3>(3 * i, 0)).norm(),
              1e-12);
  // Collision: centre placed, sizes scaled.
  const CollisionShape& c = a->collision.shapes[0];
  EXPECT_LT((c.center - (Vec3(4, 5, 6) + L * A * Vec3(0.1, 0, 0))).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.radius, 0.6);
  EXPECT_DOUBLE_EQ(c.halfLength, 0.9);

  Material rubber = *materialPreset("rubber");
  auto r = adapt(entry, q, qm, orientation, rubber, {});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->warnings.size(), 1u) << "rubber's Poisson ratio is not the database's";
  EXPECT_FALSE(materialPreset("unobtainium"));
  EXPECT_FALSE(adapt(entry, q, qm, orientation, Material{"bad", -1.0, 1.0, 0.3}, {}));
}

}  // namespace
}  // namespace shapedb::core
