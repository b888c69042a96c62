#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>

#include "support/test_support.h"

namespace shapedb::core {
namespace {

constexpr double kPi = std::numbers::pi;

double relativeError(double value, double expected) {
  return std::abs(value - expected) / std::abs(expected);
}
double relativeError(const Mat3& value, const Mat3& expected) {
  return (value - expected).norm() / expected.norm();
}

MassProperties mustCompute(const TriangleMesh& mesh, const MassPropertiesOptions& options = {}) {
  Result<MassProperties> mp = computeMassProperties(mesh, options);
  EXPECT_TRUE(mp.ok()) << mp.error().message;
  return mp.ok() ? *mp : MassProperties{};
}

// The oracle: the textbook sum over tetrahedra (origin, a, b, c), each integrated on its own with Eigen
// expressions, no reference point, no symmetric shortcuts.
struct Reference {
  double volume;
  Vec3 centerOfMass;
  Mat3 inertia;
};
Reference referenceMassProperties(const TriangleMesh& mesh) {
  double volume = 0.0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const double tetVolume = a.dot(b.cross(c)) / 6.0;
    volume += tetVolume;
    first += tetVolume * (a + b + c) / 4.0;
    second +=
        tetVolume / 20.0 *
        (a * a.transpose() + b * b.transpose() + c * c.transpose() + (a + b + c) * (a + b + c).transpose());
  }
  const Vec3 com = first / volume;
  const Mat3 covariance = second - volume * com * com.transpose();
  return {volume, com, covariance.trace() * Mat3::Identity() - covariance};
}

TEST(MassProperties, AgreesWithTheTextbookSumOnRandomMeshes) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 200; ++trial) {
    const TriangleMesh mesh = transformed(test::makeLopsidedBlob({1.0, 1.4, 0.8}, 1 + trial % 3),
                                          test::randomSimilarity(rng, 2.0, 0.5, 2.0));
    const Reference expected = referenceMassProperties(mesh);
    const MassProperties mp = mustCompute(mesh);
    EXPECT_LT(relativeError(mp.volume, expected.volume), 1e-12);
    EXPECT_LT((mp.centerOfMass - expected.centerOfMass).norm(), 1e-12 * (1.0 + expected.centerOfMass.norm()));
    EXPECT_LT(relativeError(mp.inertia, expected.inertia), 1e-10);
  }
}

TEST(MassProperties, UnitTetrahedronMatchesClosedForm) {
  // Vertices 0, e1, e2, e3 at unit density: V = 1/6, c = (1/4)³, Iₓₓ = 1/80, Iₓᵧ = +1/480 about c.
  const MassProperties mp = mustCompute(makeTetrahedron({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}));
  EXPECT_NEAR(mp.volume, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(mp.mass, 1.0 / 6.0, 1e-15);
  EXPECT_TRUE(mp.centerOfMass.isApprox(Vec3::Constant(0.25), 1e-14));
  Mat3 expected = Mat3::Constant(1.0 / 480.0);
  expected.diagonal().setConstant(1.0 / 80.0);
  EXPECT_LT(relativeError(mp.inertia, expected), 1e-13);
  EXPECT_NEAR(mp.area, 1.5 + std::sqrt(3.0) / 2.0, 1e-14);
  EXPECT_FALSE(mp.isApproximate);
}

TEST(MassProperties, RotatedTranslatedBoxMatchesClosedForm) {
  std::mt19937_64 rng(7);
  const double a = 1.3, b = 0.4, c = 2.9, density = 2700.0;
  const double m = density * a * b * c;
  const Mat3 local =
      Vec3(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12).asDiagonal();
  for (int trial = 0; trial < 20; ++trial) {
    Mat4 t = Mat4::Identity();
    const Mat3 r = test::randomRotation(rng);
    t.topLeftCorner<3, 3>() = r;
    t.topRightCorner<3, 1>() = Vec3(3.0, -40.0, 1e3 * trial);
    const MassProperties mp = mustCompute(transformed(makeBox({a, b, c}), t), {.density = density});
    // Coordinates up to 2·10⁴ carry rounding of ~4·10⁻¹², hence the bounds.
    EXPECT_LT(relativeError(mp.volume, a * b * c), 1e-10);
    EXPECT_LT(relativeError(mp.mass, m), 1e-10);
    EXPECT_LT((mp.centerOfMass - t.topRightCorner<3, 1>()).norm(), 1e-9 * (1.0 + 1e3 * trial));
    EXPECT_LT(relativeError(mp.inertia, r * local * r.transpose()), 1e-9);
    EXPECT_LT(relativeError(mp.area, 2 * (a * b + b * c + a * c)), 1e-12);
  }
}

// A large mesh is integrated in chunks in parallel: still exact (a box subdivided to 12,288 triangles is
// the box), and the same to the bit on one thread as on many.
TEST(MassProperties, ChunkedIntegralsOfALargeMeshAreExactAndThreadIndependent) {
  std::mt19937_64 rng(8);
  const double a = 1.3, b = 0.4, c = 2.9;
  TriangleMesh box = makeBox({a, b, c});
  for (int i = 0; i < 5; ++i)
    box = subdivideMidpoint(box);
  ASSERT_EQ(box.triangleCount(), 12288u);
  Mat4 t = Mat4::Identity();
  const Mat3 r = test::randomRotation(rng);
  t.topLeftCorner<3, 3>() = r;
  t.topRightCorner<3, 1>() = Vec3(3.0, -4.0, 5.0);
  const TriangleMesh mesh = transformed(box, t);
  const MassProperties many = mustCompute(mesh);
  const Mat3 local = Vec3(a * b * c * (b * b + c * c) / 12, a * b * c * (a * a + c * c) / 12,
                          a * b * c * (a * a + b * b) / 12)
                         .asDiagonal();
  EXPECT_LT(relativeError(many.volume, a * b * c), 1e-12);
  EXPECT_LT((many.centerOfMass - t.topRightCorner<3, 1>()).norm(), 1e-12);
  EXPECT_LT(relativeError(many.inertia, r * local * r.transpose()), 1e-12);
  MassProperties one;
  {
    const tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = mustCompute(mesh);
  }
  EXPECT_EQ(one.volume, many.volume);
  EXPECT_EQ(one.centerOfMass, many.centerOfMass);
  EXPECT_EQ(one.inertia, many.inertia);
  EXPECT_EQ(one.area, many.area);
}

TEST(MassProperties, FarFromTheOriginKeepsItsPrecision) {
  const TriangleMesh blob = test::makeLopsidedBlob({1.0, 1.7, 0.6}, 3);
  Mat4 far = Mat4::Identity();
  far.topRightCorner<3, 1>() = Vec3(1e6, -2e6, 5e5);
  const MassProperties near = mustCompute(blob);
  const MassProperties moved = mustCompute(transformed(blob, far));
  EXPECT_LT(relativeError(moved.volume, near.volume), 1e-9);
  EXPECT_LT(relativeError(moved.inertia, near.inertia), 1e-9);
  EXPECT_LT((moved.centerOfMass - far.topRightCorner<3, 1>() - near.centerOfMass).norm(), 1e-9);
}

TEST(MassProperties, TessellatedSphereConvergesToClosedForm) {
  const double r = 1.7, volume = 4.0 / 3.0 * kPi * r * r * r, moment = 0.4 * volume * r * r;
  double previousVolumeError = 1.0, previousInertiaError = 1.0;
  for (int level = 1; level <= 6; ++level) {
    const MassProperties mp = mustCompute(makeIcosphere(r, level));
    const double ve = relativeError(mp.volume, volume);
    const double ie = relativeError(mp.inertia, Mat3(Vec3::Constant(moment).asDiagonal()));
    EXPECT_LT(ve, previousVolumeError) << "level " << level;
    EXPECT_LT(ie, previousInertiaError) << "level " << level;
    EXPECT_LT(mp.centerOfMass.norm(), 1e-12);
    previousVolumeError = ve;
    previousInertiaError = ie;
  }
  EXPECT_LT(previousVolumeError, 1e-3);
  EXPECT_LT(previousInertiaError, 2e-3);
}

TEST(MassProperties, TessellatedCylinderConvergesToClosedForm) {
  const double r = 0.5, h = 2.0, volume = kPi * r * r * h;
  const Mat3 inertia =
      Vec3(volume * (3 * r * r + h * h) / 12, volume * (3 * r * r + h * h) / 12, volume * r * r / 2)
          .asDiagonal();
  double previous = 1.0;
  for (int segments = 8; segments <= 1024; segments *= 2) {
    const MassProperties mp = mustCompute(makeCylinder(r, h, segments));
    const double error = std::max(relativeError(mp.volume, volume), relativeError(mp.inertia, inertia));
    EXPECT_LT(error, previous) << segments << " segments";
    previous = error;
  }
  EXPECT_LT(previous, 1e-4);
}

TEST(MassProperties, EllipsoidConvergesToClosedForm) {
  const Vec3 r(0.5, 1.0, 2.0);
  const double volume = 4.0 / 3.0 * kPi * r.prod();
  const Mat3 inertia =
      (volume / 5.0 *
       Vec3(r.y() * r.y() + r.z() * r.z(), r.x() * r.x() + r.z() * r.z(), r.x() * r.x() + r.y() * r.y()))
          .asDiagonal();
  const MassProperties mp = mustCompute(makeUvEllipsoid(r, 256, 128));
  EXPECT_LT(relativeError(mp.volume, volume), 1e-3);
  EXPECT_LT(relativeError(mp.inertia, inertia), 1e-3);
}

TEST(MassProperties, DensityScalesMassAndInertia) {
  const TriangleMesh blob = test::makeLopsidedBlob({1, 2, 3}, 2);
  const MassProperties unit = mustCompute(blob);
  const MassProperties steel = mustCompute(blob, {.density = 7850.0});
  EXPECT_LT(relativeError(steel.mass, 7850.0 * unit.mass), 1e-14);
  EXPECT_LT(relativeError(steel.inertia, 7850.0 * unit.inertia), 1e-14);
  EXPECT_EQ(steel.volume, unit.volume);
}

TEST(MassProperties, InsideOutIsReportedAndFlippedOnlyWhenAsked) {
  const TriangleMesh box = makeBox({1, 2, 3});
  const Result<MassProperties> refused = computeMassProperties(flipped(box));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kInsideOut);
  const MassProperties mp = mustCompute(flipped(box), {.flipInsideOut = true});
  EXPECT_TRUE(mp.wasFlipped);
  EXPECT_NEAR(mp.volume, 6.0, 1e-12);
  EXPECT_LT(relativeError(mp.inertia, mustCompute(box).inertia), 1e-14);
}

TEST(MassProperties, OpenOrNonManifoldIsAnErrorUnlessApproximationAsked) {
  TriangleMesh open = makeIcosphere(1.0, 3);
  open.triangles.pop_back();
  const Result<MassProperties> refused = computeMassProperties(open);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kNotClosed);

  const MassProperties approx = mustCompute(open, {.allowApproximate = true});
  EXPECT_TRUE(approx.isApproximate);
  // One missing triangle of 1280: the estimate is close to the sphere, but marked approximate.
  EXPECT_LT(relativeError(approx.volume, 4.0 / 3.0 * kPi), 0.02);
  EXPECT_LT(approx.centerOfMass.norm(), 0.01);
  const double shellMoment = 2.0 / 3.0 * approx.mass;  // a thin spherical shell of the same mass
  EXPECT_LT(relativeError(approx.inertia(0, 0), shellMoment), 0.05);
}

TEST(MassProperties, ExactOnAClosedMeshEvenWhenApproximationAllowed) {
  const TriangleMesh box = makeBox({1, 2, 3});
  const MassProperties mp = mustCompute(box, {.allowApproximate = true});
  EXPECT_FALSE(mp.isApproximate);
  EXPECT_NEAR(mp.volume, 6.0, 1e-12);
}

TEST(MassProperties, FlatClosedSurfaceHasNoVolume) {
  const TriangleMesh flat = makeTetrahedron({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0});
  const Result<MassProperties> mp = computeMassProperties(flat);
  ASSERT_FALSE(mp.ok());
  EXPECT_EQ(mp.error().code, ErrorCode::kZeroVolume);
}

TEST(MassProperties, RejectsBadDensity) {
  for (double density :
       {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const Result<MassProperties> mp = computeMassProperties(makeBox({1, 1, 1}), {.density = density});
    ASSERT_FALSE(mp.ok());
    EXPECT_EQ(mp.error().code, ErrorCode::kInvalidArgument);
  }
}

}  // namespace
}  // namespace shapedb::core
