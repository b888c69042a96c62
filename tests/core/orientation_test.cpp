#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <shapedb/core/orientation.h>

#include "support/test_support.h"

namespace shapedb::core {
namespace {

void expectProperRotations(const std::vector<Mat3>& rotations) {
  ASSERT_FALSE(rotations.empty());
  EXPECT_TRUE(rotations.front().isIdentity(0.0));
  for (const Mat3& r : rotations) {
    EXPECT_TRUE((r.transpose() * r).isIdentity(1e-12));
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
  for (std::size_t i = 0; i < rotations.size(); ++i)
    for (std::size_t j = i + 1; j < rotations.size(); ++j)
      EXPECT_GT((rotations[i] - rotations[j]).norm(), 1e-6) << i << " and " << j << " coincide";
}

TEST(Orientation, DeterminedFrameHasOneCandidate) {
  Normalization n;
  expectProperRotations(orientationCandidates(n));
  EXPECT_EQ(orientationCandidates(n).size(), 1u);
}

TEST(Orientation, AmbiguousSignsAddTheFlips) {
  Normalization n;
  n.signAmbiguous = {true, false};
  EXPECT_EQ(orientationCandidates(n).size(), 2u);
  n.signAmbiguous = {true, true};
  const std::vector<Mat3> all = orientationCandidates(n);
  expectProperRotations(all);
  EXPECT_EQ(all.size(), 4u);  // the four diagonal rotations: identity, and π about x, y, z
  for (const Mat3& r : all)
    EXPECT_TRUE(r.isDiagonal(0.0));
}

TEST(Orientation, DegeneratePlaneTurnsAboutTheDistinctAxis) {
  Normalization n;
  n.degeneracy = AxisDegeneracy::kYZ;
  OrientationOptions options;
  options.planeSteps = 8;
  const std::vector<Mat3> turns = orientationCandidates(n, options);
  expectProperRotations(turns);
  EXPECT_EQ(turns.size(), 8u);  // x's sign is determined
  for (const Mat3& r : turns)
    EXPECT_TRUE(r.col(0).isApprox(Vec3::UnitX()));
  n.distinctAxisAmbiguous = true;
  EXPECT_EQ(orientationCandidates(n, options).size(), 16u);
  n.degeneracy = AxisDegeneracy::kXY;
  const std::vector<Mat3> aboutZ = orientationCandidates(n, options);
  expectProperRotations(aboutZ);
  EXPECT_EQ(aboutZ.size(), 16u);
  for (const Mat3& r : aboutZ)
    EXPECT_NEAR(std::abs(r(2, 2)), 1.0, 1e-12);
}

TEST(Orientation, HarmonicSetsThePlaneUpToItsSymmetry) {
  Normalization n;
  n.degeneracy = AxisDegeneracy::kYZ;
  n.planeSymmetry = 4;  // a square bar: quarter turns
  const std::vector<Mat3> turns = orientationCandidates(n);
  expectProperRotations(turns);
  ASSERT_EQ(turns.size(), 4u);
  EXPECT_TRUE(turns[1].isApprox(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix()));
  n.distinctAxisAmbiguous = true;
  EXPECT_EQ(orientationCandidates(n).size(), 8u);
}

TEST(Orientation, SphereLikeShapesSampleAllRotations) {
  Normalization n;
  n.degeneracy = AxisDegeneracy::kAll;
  const std::vector<Mat3> samples = orientationCandidates(n);
  expectProperRotations(samples);
  ASSERT_EQ(samples.size(), 72u);
  EXPECT_EQ(samples.front(), Mat3::Identity());
  // Whole cosets of the cube's rotations: each sample turned by a signed permutation is another sample,
  // so a query describes its surface three times, not 72 (Describer::describeCandidates).
  for (const Mat3& s : samples)
    for (const Mat3& g :
         {Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal()),
          Mat3(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()).toRotationMatrix()),
          Mat3(Eigen::AngleAxisd(2 * std::numbers::pi / 3, Vec3::Ones().normalized()).toRotationMatrix())}) {
      const Mat3 turned = g * s;
      EXPECT_TRUE(std::any_of(samples.begin(), samples.end(),
                              [&](const Mat3& t) { return (t - turned).cwiseAbs().maxCoeff() < 1e-12; }));
    }
  // Near-uniform: every random rotation is within 50° of some sample (the 72 rotations of a generic
  // near-uniform sample, a super-Fibonacci spiral, leave gaps of 58°).
  std::mt19937_64 rng(17);
  double worst = 1.0;
  for (int probe = 0; probe < 5000; ++probe) {
    const Mat3 p = test::randomRotation(rng);
    double best = 0.0;
    for (const Mat3& s : samples)
      best = std::max(best, ((s.transpose() * p).trace() - 1.0) / 2.0);
    EXPECT_GT(best, std::cos(50.0 / 180.0 * std::numbers::pi));
    worst = std::min(worst, best);
  }
  std::cout << "  72 samples: farthest of 5,000 random rotations is "
            << std::acos(worst) * 180.0 / std::numbers::pi << "° from a sample\n";
  OrientationOptions options;
  options.sphereCosets = 1;
  EXPECT_EQ(orientationCandidates(n, options).size(), 24u);
  options.enabled = false;
  EXPECT_EQ(orientationCandidates(n, options).size(), 1u);
}

}  // namespace
}  // namespace shapedb::core
