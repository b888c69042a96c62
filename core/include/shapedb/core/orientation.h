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
  /// Rotations tried when all three moments are equal (kAll): a near-uniform sample of SO(3).
  int sphereSamples = 72;
};

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

/// `count` near-uniform rotations (super-Fibonacci spiral, Alexa 2022), deterministic.
std::vector<Mat3> sampleRotations(int count);

}  // namespace shapedb::core
