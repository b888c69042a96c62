#pragma once
// The fidelity report that comes with every match: how far the retrieved entry is from the query, in
// terms a user can judge (moments of inertia, surface distance), next to the descriptor's distance.
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

}  // namespace shapedb::core
