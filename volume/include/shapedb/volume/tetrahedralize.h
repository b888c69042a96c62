#pragma once

#include <string>
#include <vector>

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

/// TetGen's quality switches (its manual, §4.2) and how to run it.
struct TetrahedralizeOptions {
  /// Maximum radius-edge ratio of a tet ('q'); TetGen refines until every tet meets it. ≥ 1.1, or 0 for
  /// no quality bound (TetGen's refinement can fail to end near sharp input angles, a slender cone's tip).
  double maxRadiusEdgeRatio = 1.5;
  /// Maximum tet volume ('a') as a fraction of the solid's volume: about 1/maxVolumeFraction tets at
  /// least. 0: no volume bound.
  double maxVolumeFraction = 1.0 / 600.0;
  /// Tets across thin walls. The volume bound alone puts one tet, or none inside, across a wall thinner
  /// than its tets (a beam's flange, a plate, a limb), and such a wall bends too stiffly. With a fraction
  /// f > 0, a tet is also split while its volume is over that of a regular tet of edge f·t, t the solid's
  /// thickness (core::wallThickness, the least at the corners of the surface triangle closest to the
  /// tet's centroid): about 1/f tets across the wall. Only where f·t is under the edge of a regular tet of
  /// the volume bound's volume, and never under a third of that edge: no wall gets more than 27 times the
  /// tets per volume, and a solid with no wall that thin is meshed exactly as without. Needs a volume
  /// bound. 0: no such bound.
  double wallEdgeFraction = 0.0;
  /// Run TetGen in a child process, so that a crash or a hang in it (TetGen 1.5 segfaults on some bad
  /// input and aborts on others) becomes an error instead of taking the caller down. Off only for meshes
  /// the caller made itself and for measuring the cost of the guard.
  bool guarded = true;
  /// Guarded only: the child is killed after this long and the call fails.
  double timeoutSeconds = 30.0;
  /// When TetGen fails: a guarded run is repeated once in a fresh worker, then the quality bound is
  /// loosened to 2.5 and then dropped (10 s timeout each). TetGen's refinement can abort, hang or return
  /// a flat tet near sharp input angles.
  bool relaxOnFailure = true;
};

/// The switches string TetGen gets: "pq1.5a0.00166Qz" and the like; with "M" when `mergeFacets` is off
/// (see tetrahedralize).
std::string tetgenSwitches(const TetrahedralizeOptions& options, double volume, bool mergeFacets = true);

/// The wall bound (see wallEdgeFraction) of a solid of this volume: per triangle of `surface`, the largest
/// volume of a tet closest to it, +∞ where the wall is thick enough for the volume bound's tets; empty
/// when the bound is off or no wall is that thin.
std::vector<double> wallVolumeBounds(const core::TriangleMesh& surface, const TetrahedralizeOptions& options,
                                     double volume);

/// A quality tetrahedral mesh of the solid bounded by `surface` (TetGen: a constrained Delaunay
/// tetrahedralization of the surface as a piecewise linear complex, refined to the quality bounds). The
/// tets fill the surface exactly: their boundary lies on the input faces, so their volume integrals
/// equal the surface integrals to round-off; a run whose tets do not (volume or centroid off by more than
/// 1e-9: TetGen merged nearly coplanar facets) is repeated with merging off. With relaxOnFailure, where
/// every run fails and the surface has caps (faces whose corner lies within 1e-4 of the opposite edge's
/// length from it, around which TetGen's refinement runs away until its tets fall apart), the surface with
/// them flipped away (core::flipThinFaces) is meshed the same way instead: the tets then fill that surface,
/// which has the same vertices, lies within the caps' heights of the given one, and holds its volume
/// within 1e-6.
///
/// The input is validated first (finite, indices in range, no degenerate face, closed, consistently and
/// outward oriented, positive volume): TetGen is never handed a mesh it is known to choke on. Errors: the
/// validation's; kSelfIntersecting if TetGen failed and the surface crosses itself (the message names two
/// triangles that cross, where, and what TetGen did: it refuses such a surface, or crashes on it);
/// otherwise kParse if TetGen refuses the input, kIo if the guarded child crashed or timed out (the
/// message says which signal). Thread-safe.
Result<core::TetMesh> tetrahedralize(const core::TriangleMesh& surface,
                                     const TetrahedralizeOptions& options = {});

/// Removes the tets with no volume to speak of (at or under core::flatTetVolume, which validateTetMesh
/// refuses) and the nodes left without a tet. tetrahedralize does it to TetGen's output; a
/// mesh moved to another frame needs it again, since round-off can flatten a tet that was just above
/// the bound.
void dropFlatTets(core::TetMesh& mesh);

/// Starts the calling thread's TetGen process now, if it has none running: tetrahedralize runs TetGen in
/// one per thread, forked at the thread's first call (and again after a crash or a timeout). A fork
/// holds up every page fault of the process's other threads while it copies the memory map, and leaves
/// their pages copy-on-write, so that each page they write next faults once more. A thread that will
/// mesh while a real-time thread runs (the haptic loop's enrichment: io::Enricher) starts its worker
/// first, before the loop does. Errors: kIo (no process could be started; tetrahedralize then tries
/// again). Thread-safe (each thread its own).
Status startTetGenWorker();

namespace testing {
/// Fault injection, for tests: the guarded worker of each of the next `count` TetGen requests (in any
/// thread of this process) is killed before it gets the request, as a crash or a hang of the worker
/// itself would leave it.
void killNextTetGenWorkers(int count);
/// The TetGen workers this process has forked so far (any thread).
int tetGenWorkersStarted();
}  // namespace testing

}  // namespace shapedb::volume
