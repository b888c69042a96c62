#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>

#include "support/test_support.h"

namespace shapedb::core {
namespace {

struct Canonical {
  MassProperties massProperties;
  Normalization normalization;
  TriangleMesh mesh;  // the input mapped by T
};

Canonical canonicalize(const TriangleMesh& mesh, double density = 1.0) {
  Result<MassProperties> mp = computeMassProperties(mesh, {.density = density});
  EXPECT_TRUE(mp.ok()) << mp.error().message;
  Result<Normalization> n = normalize(mesh, *mp);
  EXPECT_TRUE(n.ok()) << n.error().message;
  return {*mp, *n, transformed(mesh, n->canonicalFromMesh)};
}

// Shapes with three well separated principal moments and no mirror symmetry.
std::vector<std::pair<std::string, TriangleMesh>> asymmetricShapes() {
  return {{"blob", test::makeLopsidedBlob({1.0, 1.6, 0.7}, 3)},
          {"flat blob", test::makeLopsidedBlob({2.0, 1.1, 0.3}, 2)},
          {"generic tetrahedron",
           makeTetrahedron({0, 0, 0}, {2.0, 0.1, 0.2}, {0.3, 1.1, -0.1}, {0.2, 0.4, 0.6})}};
}

TEST(Normalize, CanonicalFrameHasUnitVolumeCentredDiagonalAscendingInertia) {
  for (const auto& [name, mesh] : asymmetricShapes()) {
    SCOPED_TRACE(name);
    const Canonical c = canonicalize(mesh, 800.0);
    const Result<MassProperties> mp = computeMassProperties(c.mesh);
    ASSERT_TRUE(mp.ok());
    EXPECT_NEAR(mp->volume, 1.0, 1e-12);
    EXPECT_LT(mp->centerOfMass.norm(), 1e-12);
    EXPECT_LT((mp->inertia - Mat3(mp->inertia.diagonal().asDiagonal())).norm(), 1e-12);
    EXPECT_LT(mp->inertia(0, 0), mp->inertia(1, 1));
    EXPECT_LT(mp->inertia(1, 1), mp->inertia(2, 2));
    EXPECT_LT((mp->inertia.diagonal() - c.normalization.canonicalMoments).norm(), 1e-12);
    // Right-handed rotation, and the sign rule holds in the canonical frame.
    EXPECT_NEAR(c.normalization.principalAxes.determinant(), 1.0, 1e-12);
    const Result<Normalization> again = normalize(c.mesh, *mp);
    ASSERT_TRUE(again.ok());
    EXPECT_TRUE(again->principalAxes.isIdentity(1e-9)) << again->principalAxes;
    EXPECT_GT(c.normalization.skewness[0], 0.02);
    EXPECT_GT(c.normalization.skewness[1], 0.02);
    EXPECT_FALSE(c.normalization.isDegenerate());
  }
}

TEST(Normalize, TransformTimesInverseIsIdentity) {
  for (const auto& [name, mesh] : asymmetricShapes()) {
    const Canonical c = canonicalize(mesh);
    EXPECT_TRUE((c.normalization.canonicalFromMesh * c.normalization.meshFromCanonical).isIdentity(1e-12))
        << name;
    EXPECT_TRUE((c.normalization.meshFromCanonical * c.normalization.canonicalFromMesh).isIdentity(1e-12))
        << name;
  }
}

TEST(Normalize, SameCanonicalMeshUnderThousandRandomSimilarities) {
  std::mt19937_64 rng(20261122);
  for (const auto& [name, mesh] : asymmetricShapes()) {
    SCOPED_TRACE(name);
    const Canonical reference = canonicalize(mesh);
    double worst = 0.0;
    for (int trial = 0; trial < 1000; ++trial) {
      const Mat4 t = test::randomSimilarity(rng);
      const Canonical moved = canonicalize(transformed(mesh, t));
      ASSERT_FALSE(moved.normalization.signAmbiguous[0] || moved.normalization.signAmbiguous[1]);
      worst = std::max(worst, test::maxVertexDifference(moved.mesh, reference.mesh));
    }
    EXPECT_LT(worst, 1e-9);
  }
}

TEST(Normalize, SphereAndCubeAreFlaggedFullyDegenerate) {
  for (const TriangleMesh& mesh : {makeIcosphere(1.0, 3), makeBox({2, 2, 2})}) {
    const Canonical c = canonicalize(mesh);
    EXPECT_EQ(c.normalization.degeneracy, AxisDegeneracy::kAll);
    EXPECT_LT(c.normalization.conditioning(), 1e-3);
  }
}

TEST(Normalize, CylindersAreFlaggedOnTheirEqualPair) {
  // Long: the axis carries the smallest moment, the two others are equal.
  EXPECT_EQ(canonicalize(makeCylinder(0.5, 4.0, 64)).normalization.degeneracy, AxisDegeneracy::kYZ);
  // Flat: the axis carries the largest moment.
  EXPECT_EQ(canonicalize(makeCylinder(2.0, 0.5, 64)).normalization.degeneracy, AxisDegeneracy::kXY);
}

// Prisms of n-gon section have equal moments in the section plane; an angular harmonic of order m, a
// multiple of n (≤ 6), sets the in-plane axes, so a moved copy gets the same canonical mesh up to a turn
// of 360°/m about the distinct axis (and a reversal of that axis, the prism being mirror-symmetric).
TEST(Normalize, PrismSectionHarmonicFixesTheDegeneratePlane) {
  std::mt19937_64 rng(8);
  for (int sides : {3, 4, 5, 6}) {
    for (double height : {4.0, 0.3}) {  // long (kYZ) and flat (kXY)
      SCOPED_TRACE(std::to_string(sides) + " sides, height " + std::to_string(height));
      const TriangleMesh prism = makeCylinder(1.0, height, sides);
      const Canonical reference = canonicalize(prism);
      ASSERT_TRUE(reference.normalization.isDegenerate());
      const int m = reference.normalization.planeSymmetry;
      ASSERT_GT(m, 0);
      EXPECT_EQ(m % sides, 0);
      for (int trial = 0; trial < 20; ++trial) {
        const Canonical moved = canonicalize(transformed(prism, test::randomSimilarity(rng)));
        EXPECT_EQ(moved.normalization.planeSymmetry, m);
        // Some turn by a multiple of 360°/n about the distinct axis (or that and a reversal) maps the
        // moved canonical mesh onto the reference's, vertex for vertex.
        const Vec3 axis =
            reference.normalization.degeneracy == AxisDegeneracy::kYZ ? Vec3::UnitX() : Vec3::UnitZ();
        const Vec3 across = axis == Vec3::UnitX() ? Vec3::UnitY() : Vec3::UnitX();  // the first in-plane axis
        double best = 1e9;
        for (int reversed = 0; reversed < 2; ++reversed)
          for (int j = 0; j < m; ++j) {
            Mat3 r = Eigen::AngleAxisd(2.0 * 3.141592653589793 * j / m, axis).toRotationMatrix();
            if (reversed) r = r * Eigen::AngleAxisd(3.141592653589793, across).toRotationMatrix();
            Mat4 turn = Mat4::Identity();
            turn.topLeftCorner<3, 3>() = r;
            best = std::min(best, test::maxVertexDifference(transformed(moved.mesh, turn), reference.mesh));
          }
        EXPECT_LT(best, 1e-9);
      }
    }
  }
  EXPECT_EQ(canonicalize(makeCylinder(1.0, 4.0, 64)).normalization.planeSymmetry, 0);  // round: no harmonic
}

TEST(Normalize, MirrorSymmetricBoxHasAmbiguousSigns) {
  const Canonical c = canonicalize(makeBox({1, 2, 3}));
  EXPECT_EQ(c.normalization.degeneracy, AxisDegeneracy::kNone);
  EXPECT_TRUE(c.normalization.signAmbiguous[0]);
  EXPECT_TRUE(c.normalization.signAmbiguous[1]);
  // The x axis is along the longest side (smallest moment).
  EXPECT_NEAR(std::abs(c.normalization.principalAxes(2, 0)), 1.0, 1e-12);
}

TEST(Normalize, NearlyEqualMomentsAreFlaggedWithTheirConditioning) {
  // Moments ∝ (b²+c², a²+c², a²+b²): gaps of 0.3% and 0.75%.
  const TriangleMesh box = makeBox({1.0, 1.003, 1.006});
  const Canonical c = canonicalize(box);
  EXPECT_EQ(c.normalization.degeneracy, AxisDegeneracy::kAll);
  EXPECT_GT(c.normalization.conditioning(), 0.002);
  EXPECT_LT(c.normalization.conditioning(), 0.004);
  const Result<Normalization> strict = normalize(box, c.massProperties, {.degeneracyTolerance = 1e-3});
  EXPECT_FALSE(strict->isDegenerate());
}

TEST(Normalize, ApproximateInputGivesApproximateFrame) {
  TriangleMesh open = test::makeLopsidedBlob({1.0, 1.6, 0.7}, 3);
  open.triangles.pop_back();
  const Result<MassProperties> mp = computeMassProperties(open, {.allowApproximate = true});
  ASSERT_TRUE(mp.ok());
  const Result<Normalization> n = normalize(open, *mp);
  ASSERT_TRUE(n.ok());
  EXPECT_TRUE(n->isApproximate);
  // The approximate frame still points roughly where the exact one does.
  const Canonical exact = canonicalize(test::makeLopsidedBlob({1.0, 1.6, 0.7}, 3));
  EXPECT_GT(std::abs(n->principalAxes.col(0).dot(exact.normalization.principalAxes.col(0))), 0.95);
}

TEST(Normalize, RejectsNonFiniteMassProperties) {
  MassProperties bad;
  bad.volume = std::numeric_limits<double>::quiet_NaN();
  bad.density = 1.0;
  EXPECT_EQ(normalize(makeBox({1, 1, 1}), bad).error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace shapedb::core
