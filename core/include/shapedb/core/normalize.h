#pragma once

#include <array>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// Thresholds under which the canonical frame is reported as undetermined.
struct NormalizeOptions {
  /// Two principal moments whose difference is below this fraction of the largest are "equal": the
  /// axes between them can turn freely in their plane (spheres, cubes, cylinders).
  double degeneracyTolerance = 0.02;
  /// An axis whose standardized third moment (skewness) is below this in magnitude has no reliable
  /// sign: the shape is (nearly) mirror-symmetric across the plane normal to it.
  double signTolerance = 0.02;
  /// Where two moments are equal, the in-plane axes are set by the strongest of the surface's angular
  /// harmonics of order 2 to 6 about the distinct axis, if its normalized magnitude reaches this.
  double harmonicTolerance = 0.05;
};

/// Which principal axes the moments leave undetermined.
enum class AxisDegeneracy {
  kNone,  ///< three distinct moments: axes determined up to sign
  kXY,    ///< smallest two moments equal: x and y free to turn about z
  kYZ,    ///< largest two moments equal: y and z free to turn about x
  kAll,   ///< all three equal (sphere- or cube-like): any rotation
};

/// The canonical frame of a shape (paper §3.1): unit volume, centre of mass at the origin, principal
/// axes on x (smallest moment), y, z = x × y. Plain value type.
struct Normalization {
  Mat4 canonicalFromMesh = Mat4::Identity();  ///< T: p' = s Rᵀ (p − c)
  Mat4 meshFromCanonical = Mat4::Identity();  ///< T⁻¹
  double scale = 1.0;                         ///< s = V^(-1/3), canonical units per metre
  Mat3 principalAxes = Mat3::Identity();      ///< R: columns x, y, z in the mesh frame, det +1
  Vec3 principalMoments = Vec3::Zero();       ///< kg m², ascending, of the mesh at its density
  Vec3 canonicalMoments = Vec3::Zero();       ///< principal moments of the unit-volume, unit-density shape
  /// Relative gaps (λy − λx)/λz and (λz − λy)/λz; the smaller is the frame's conditioning.
  std::array<double, 2> momentGaps{};
  AxisDegeneracy degeneracy = AxisDegeneracy::kNone;
  /// Standardized third moments ∫x³/(V σ³) along x and y after the sign rule: both ≥ 0.
  std::array<double, 2> skewness{};
  /// The sign rule could not decide axis x (index 0) or y (index 1): |skewness| < signTolerance.
  /// In a degenerate plane an in-plane axis is ambiguous unless planeSymmetry set it.
  std::array<bool, 2> signAmbiguous{};
  /// Degenerate pair (kXY, kYZ) only: m ≥ 2 when the in-plane axes were turned so that the surface's
  /// m-th angular harmonic about the distinct axis has phase 0 (a square bar: m = 4, a triangular
  /// prism: m = 3); the frame is then determined up to turns of 360°/m. 0: no harmonic is strong
  /// enough (cylinder-like), the in-plane axes are arbitrary.
  int planeSymmetry = 0;
  /// Degenerate pair only: the distinct axis (z for kXY, x for kYZ) has no reliable sign.
  bool distinctAxisAmbiguous = false;
  bool isApproximate = false;  ///< built on approximate mass properties

  /// min(momentGaps): 0 for a sphere, near 1 for a needle.
  double conditioning() const { return std::min(momentGaps[0], momentGaps[1]); }
  bool isDegenerate() const { return degeneracy != AxisDegeneracy::kNone; }
};

/// The canonical frame of `mesh` given its mass properties (computeMassProperties on the same mesh).
/// Sign rule: the third moment of the volume about the centre of mass is made positive along x and y;
/// z = x × y keeps the frame right-handed. Where two moments are equal, the distinct axis gets the sign
/// rule and the other two are set by the surface's angular harmonic (planeSymmetry). O(F); thread-safe
/// (pure function).
/// Errors: kInvalidArgument if the mass properties are not finite or positive.
Result<Normalization> normalize(const TriangleMesh& mesh, const MassProperties& massProperties,
                                const NormalizeOptions& options = {});

/// Short name for logs and JSON: "none", "xy", "yz", "all".
const char* toString(AxisDegeneracy degeneracy);

}  // namespace shapedb::core
