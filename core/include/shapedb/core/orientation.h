#pragma once

#include <vector>

#include <shapedb/core/normalize.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// How many orientations a query tries where its canonical frame is undetermined.
struct OrientationOptions {
  bool enabled = true;  ///< false: the canonical frame only
  /// Rotations tried about the distinct axis when two principal moments are equal (kXY, kYZ) and no
  /// harmonic set the in-plane axes (Normalization::planeSymmetry = 0): every 360°/planeSteps. With
  /// planeSymmetry = m, the m turns of 360°/m. Each also with the distinct axis reversed when its sign
  /// is undetermined.
  int planeSteps = 24;
  /// Where all three moments are equal (kAll), the rotations tried are this many cosets of the cube's
  /// 24 rotations, 1 to kMaxSphereCosets (sphereCandidates): the default 72 rotations of SO(3).
  int sphereCosets = 3;
};

inline constexpr int kMaxSphereCosets = 3;

/// The rotations candidateFromCanonical that a query tries (paper §3.1 leaves them open, one of its weak
/// points: docs/architecture.md, "The second stage"), identity first, then:
/// - each axis flip the sign rule left ambiguous (rotations by π about y, x, or z, keeping det +1);
/// - within a degenerate eigenspace, rotations about the distinct axis (kXY, kYZ) or a sample of all
///   rotations (kAll).
/// Each candidate is a proper rotation of the canonical frame that the normalization could equally have
/// chosen for a copy of the shape.
/// Deterministic; proper rotations only (a mirror image is another shape). Thread-safe.
std::vector<Mat3> orientationCandidates(const Normalization& normalization,
                                        const OrientationOptions& options = {});

/// The rotations a sphere-like shape tries: g · b for each of the cube's 24 rotations g (the signed
/// permutations of the axes with determinant +1) and each of the first `cosets` (1 to kMaxSphereCosets)
/// base rotations b, the identity first. A shape's descriptor in the frame g · b is its descriptor in the
/// frame b with the cells renumbered (core::reorientDescriptor), so the query describes its surface once a
/// coset. The bases were chosen to spread the 72 rotations of three cosets evenly: every rotation lies within
/// about 48° of one of them (the 72 of a super-Fibonacci spiral, a generic near-uniform sample: 58°).
/// Deterministic.
std::vector<Mat3> sphereCandidates(int cosets);

}  // namespace shapedb::core
