#pragma once
// The fidelity report that comes with every match: how far the retrieved entry is from the query, in
// terms a user can judge (moments of inertia, surface distance), next to the descriptor's distance.
#include <functional>
#include <vector>

#include <shapedb/core/adapt.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/result.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

struct FidelityOptions {
  int samples = 1024;  ///< points sampled on each surface (area-uniform, deterministic)
};

struct Fidelity {
  double descriptorDistance = 0.0;  ///< the match's own distance (eq. 4, 5 or 6)
  /// Principal moments of the unit-volume shapes, ascending: the query's (exact, from its surface) and
  /// the entry's (from its tets); relative difference (entry − query) / query per moment.
  Vec3 queryMoments = Vec3::Zero();
  Vec3 entryMoments = Vec3::Zero();
  Vec3 momentError = Vec3::Zero();
  double maxMomentError = 0.0;  ///< max |momentError|
  /// Two-sided surface deviation between the query and the placed entry (its tet mesh's boundary), from
  /// `samples` points on each, relative to the query's size L = V^(1/3).
  double meanDeviation = 0.0;
  double maxDeviation = 0.0;
  int samples = 0;
};

/// `count` points spread over the surface by area: stratified over the cumulative area, placed within
/// each triangle by the R2 sequence. Deterministic.
std::vector<Vec3> sampleSurface(const TriangleMesh& mesh, int count);

/// The fidelity of a match. `queryTree` is built on the query's surface (its frame); `entry` locates
/// in the entry's canonical tet mesh; `placement` puts that frame into the query's.
Fidelity assessFidelity(const TriangleMesh& query, const ClosestPointTree& queryTree,
                        const Normalization& normalization, const TetLocator& entry,
                        const MassProperties& entryMass, const Placement& placement,
                        double descriptorDistance, const FidelityOptions& options = {});

/// A solid known by an inside test and a box that holds it.
struct SampledSolid {
  std::function<bool(const Vec3&)> contains;
  Bounds bounds;
};

/// How two solids overlap, sampled at the centres of one regular grid over the union of their boxes.
struct VolumeOverlap {
  double iou = 0.0;                     ///< |A ∩ B| / |A ∪ B|
  double coverage = 0.0;                ///< |A ∩ B| / |A|: how much of A is inside B
  double overshoot = 0.0;               ///< |B \ A| / |A|: how much of B lies outside A, relative to A
  double volumeA = 0.0, volumeB = 0.0;  ///< as sampled, m³
  long samples = 0;                     ///< grid points evaluated
};

/// Samples A and B on a grid of cubic cells, `resolution` cells along the longest side of the union of
/// their boxes (8 to 512). Deterministic; parallel (TBB) over slices. A solid with no sample inside it
/// gives zero volume, and the ratios relative to A are then 0.
VolumeOverlap sampleOverlap(const SampledSolid& a, const SampledSolid& b, int resolution = 64);

/// The box that holds every shape of a compound (its shapes' own boxes, rotations included).
Bounds compoundBounds(const CollisionCompound& compound);

/// The compound as a SampledSolid (a point is inside when any shape contains it); it refers to
/// `compound`, which must outlive it.
SampledSolid sampledSolid(const CollisionCompound& compound);

/// The solid ellipsoid and the solid box with the same mass and principal moments as a body (the
/// inertia-equivalent primitives of precomputed sound banks, Zheng & James 2010): semi-axes, resp. half
/// extents, along its principal axes, ascending moments first. From I₁ = m(b² + c²)/5 for the ellipsoid
/// and I₁ = m(b² + c²)/3 for the box: a² = k (I₂ + I₃ − I₁) / 2m, k = 5 resp. 3. A sum that round-off
/// makes negative (a flat body) is taken as zero.
Vec3 inertiaEquivalentEllipsoid(const Vec3& principalMoments, double mass);
Vec3 inertiaEquivalentBox(const Vec3& principalMoments, double mass);

}  // namespace shapedb::core
