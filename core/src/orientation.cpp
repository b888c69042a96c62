#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include <shapedb/core/orientation.h>

namespace shapedb::core {
namespace {

Mat3 rotationAbout(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

// Rotations by π about x, y and z: each reverses the two other axes.
const Mat3 kFlipYZ = Vec3(1.0, -1.0, -1.0).asDiagonal();
const Mat3 kFlipXZ = Vec3(-1.0, 1.0, -1.0).asDiagonal();
const Mat3 kFlipXY = Vec3(-1.0, -1.0, 1.0).asDiagonal();

}  // namespace

std::vector<Mat3> sampleRotations(int count) {
  // Super-Fibonacci spirals: quaternions from two irrational rotation numbers.
  const double phi = std::sqrt(2.0);
  const double psi = 1.533751168755204288118041;
  std::vector<Mat3> out;
  out.reserve(static_cast<std::size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    const double s = i + 0.5;
    const double r = std::sqrt(s / count), R = std::sqrt(1.0 - s / count);
    const double alpha = 2.0 * std::numbers::pi * s / phi, beta = 2.0 * std::numbers::pi * s / psi;
    const Eigen::Quaterniond q(R * std::cos(beta), r * std::sin(alpha), r * std::cos(alpha),
                               R * std::sin(beta));
    out.push_back(q.normalized().toRotationMatrix());
  }
  return out;
}

std::vector<Mat3> orientationCandidates(const Normalization& normalization,
                                        const OrientationOptions& options) {
  std::vector<Mat3> out = {Mat3::Identity()};
  if (!options.enabled) return out;
  const bool flipX = normalization.signAmbiguous[0], flipY = normalization.signAmbiguous[1];
  // In a degenerate plane the harmonic (if any) leaves planeSymmetry turns open, else planeSteps.
  const int steps =
      normalization.planeSymmetry > 0 ? normalization.planeSymmetry : std::max(options.planeSteps, 1);
  const bool reverse = normalization.distinctAxisAmbiguous;
  const auto aroundAxis = [&](const Vec3& axis, bool reverseAxis, const Mat3& reversal) {
    for (int reversed = 0; reversed <= (reverseAxis ? 1 : 0); ++reversed)
      for (int j = 0; j < steps; ++j) {
        if (reversed == 0 && j == 0) continue;
        const Mat3 turn = rotationAbout(axis, 2.0 * std::numbers::pi * j / steps);
        out.push_back(reversed ? Mat3(turn * reversal) : turn);
      }
  };
  switch (normalization.degeneracy) {
    case AxisDegeneracy::kNone:
      if (flipX) out.push_back(kFlipXZ);
      if (flipY) out.push_back(kFlipYZ);
      if (flipX && flipY) out.push_back(kFlipXY);
      break;
    case AxisDegeneracy::kXY:
      aroundAxis(Vec3::UnitZ(), reverse, kFlipYZ);
      break;
    case AxisDegeneracy::kYZ:
      aroundAxis(Vec3::UnitX(), reverse, kFlipXZ);
      break;
    case AxisDegeneracy::kAll:
      for (const Mat3& rotation : sampleRotations(options.sphereSamples))
        out.push_back(rotation);
      break;
  }
  return out;
}

}  // namespace shapedb::core
