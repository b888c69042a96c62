#pragma once
// Generated shapes and descriptors for tests and benchmarks: random closed meshes, the pipeline from a
// mesh to its descriptor, and jittered copies of descriptors to fill large indexes cheaply.

#include <random>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::test {

/// A uniformly distributed random rotation (unit quaternion from four normal deviates).
core::Mat3 randomRotation(std::mt19937_64& rng);

/// A closed blob with three distinct principal moments, skewed along every axis: an icosphere tapered
/// along x and y (pear-shaped), bumped, and stretched by `radii`. No symmetry at all.
core::TriangleMesh makeLopsidedBlob(const core::Vec3& radii, int subdivisions);

/// A torus about z, `major` from its axis to the tube's centre, the tube `minor` in radius, `rings` ×
/// `segments` quads each split in two: closed, genus one, wound outward, with saddles where no convex
/// shape has them.
core::TriangleMesh makeTorus(double major, double minor, int rings, int segments);

/// A random closed, outward-oriented shape: a star-shaped bumpy blob (icosphere with a random radial
/// wave, stretched by random radii), a box, an ellipsoid or a cylinder of random proportions.
/// Deterministic for a given generator state.
core::TriangleMesh makeRandomShape(std::mt19937_64& rng, int subdivisions = 3);

/// Descriptor options of the given kind, sampling and grid size.
core::DescriptorOptions descriptorOptions(core::DescriptorKind kind,
                                          core::Sampling sampling = core::Sampling::kArea, int gridSize = 10);

/// mass properties → normalize → describe, the query pipeline up to the descriptor.
struct DescribedMesh {
  core::Normalization normalization;
  core::Descriptor descriptor;
};
Result<DescribedMesh> describeMesh(const core::TriangleMesh& mesh, const core::DescriptorOptions& options);

/// A copy of `d` with about `flips` cells next to the surface switched (filled ↔ empty), every centroid
/// moved by up to ±centroidNoise of a cell per axis and the moments scaled by e^N(0, centroidNoise/2):
/// a plausible nearby shape. Moment descriptors: the moments scaled by 1 + N(0, centroidNoise).
core::Descriptor jitterDescriptor(const core::Descriptor& d, std::mt19937_64& rng, int flips,
                                  double centroidNoise);

}  // namespace shapedb::test
