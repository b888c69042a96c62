#include <algorithm>
#include <array>
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

std::vector<Mat3> sphereCandidates(int cosets) {
  // Found by minimizing, over pairs of rotations, the largest angle from random rotations to the nearest
  // of the three cosets (quaternions w, x, y, z).
  const std::array<Eigen::Quaterniond, kMaxSphereCosets> bases = {
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond(-0.575699, -0.632761, -0.034341, 0.516725).normalized(),
      Eigen::Quaterniond(-0.048573, 0.499023, 0.637373, -0.585126).normalized(),
  };
  std::vector<Mat3> cube;  // the identity first
  std::array<int, 3> axes = {0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Mat3 g = Mat3::Zero();
      for (int row = 0; row < 3; ++row)
        g(row, axes[static_cast<std::size_t>(row)]) = ((signs >> row) & 1) != 0 ? -1.0 : 1.0;
      if (g.determinant() > 0.0) cube.push_back(g);
    }
  } while (std::next_permutation(axes.begin(), axes.end()));
  std::vector<Mat3> out;
  for (int c = 0; c < std::clamp(cosets, 1, kMaxSphereCosets); ++c)
    for (const Mat3& g : cube)
      out.push_back(g * bases[static_cast<std::size_t>(c)].toRotationMatrix());
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
      out = sphereCandidates(options.sphereCosets);
      break;
  }
  return out;
}

}  // namespace shapedb::core
