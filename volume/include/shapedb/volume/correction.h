#pragma once
// The geometry correction, the second tier of a query's answer (docs/architecture.md, "Geometry
// correction"): the matched entry's tets morphed onto the query's own surface, and the modes computed
// again on them, started from the entry's. The nearest entry gives the query the entry's proportions and
// thin parts; the corrected data have the query's, at the entry's resolution.

#include <string>
#include <vector>

#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/morph.h>

namespace shapedb::volume {

struct CorrectionOptions {
  MorphOptions morph;
};

/// What the correction did and what it cost.
struct CorrectionReport {
  MorphReport morph;  ///< quality, moves, target coverage: in the entry's canonical frame (L = 1)
  /// The target's volume over the morphed tets': 1 where the morph reached all of the target; above 1
  /// where boundary nodes held back cut its edges and corners, or left out a part the entry has no tets
  /// for. The modes carry the target's whole mass all the same (MorphedEntry::pointMasses).
  double massScale = 1.0;
  /// The share of the morphed tets' volume that lies outside the target's surface (each tet by its
  /// centroid): material the morph carried across a gap the target has (between a figure's legs,
  /// through a knot's loop, over a cup's mouth), which ties apart what the target holds apart and
  /// stiffens the corrected modes. About 0 where the morph follows the target; on real objects a tenth
  /// or more went with corrected answers 12-690 % off (docs/architecture.md). 0, unknown, where the
  /// target bounds no solid (an open surface has no inside).
  double strayShare = 0.0;
  /// Of the mass the morph misses, the most that its placement by weight would give one node, over the
  /// node's own mass (MorphedEntry::pointMasses; a node is given at most kPointMassLimit): large where
  /// the missing mass is concentrated on a few light nodes, as at a sharp corner the tets do not reach.
  /// 0 where no mass is missing.
  double pointMassPeak = 0.0;
  /// Of the first mode computed with the lumped mass, the largest share of its kinetic energy that one
  /// node's lumped mass carried (0 with none lumped). Near 1, the mode is that node's own, on the little
  /// stiffness the morph left it, not the body's; past kLumpedModeLimit the modes were computed again
  /// with the missing mass spread over the tets (massSpread).
  double lumpedModeShare = 0.0;
  /// The modes carry the missing mass as density over the tets (ρ = massScale), not lumped at their
  /// boundary: lumped, a mode was one node's (lumpedModeShare).
  bool massSpread = false;
  int solves = 0;  ///< solves of the modes' recomputation (Lanczos, started from the entry's modes)
  /// Entries morphed to choose this one from (a query's candidates, io::QueryOptions::correctionCandidates);
  /// morphSeconds is all of their morphs', with the one preparation of the query's surface they share
  /// and the chosen one's missing mass.
  int morphs = 1;
  /// The entry morphed is one of a query's fallback entries (io::QueryOptions::correctionFallback), tried
  /// because the nearest matches' morphs left much of the query unfilled, not one of those matches;
  /// `morphs` counts them too.
  bool fallback = false;
  /// The modes were computed on a guess, while the last of a query's candidates (or of its fallback
  /// entries) was still being morphed: those of the morph that would answer then, which still did after
  /// the last (io::Database::query). The same modes as after the last morph, sooner.
  bool speculative = false;
  double morphSeconds = 0.0;
  double modesSeconds = 0.0;
};

/// A stray share (CorrectionReport::strayShare) above which a query warns that its corrected data are
/// unreliable: on the twelve real meshes of the benchmarks, the six corrected answers past it were 12-690 %
/// off in their first frequency; of the five under 1 %, four were within 5 % (the fifth, a tray its morph
/// held a third of, 43 % off: massScale tells that one).
inline constexpr double kStrayShareWarning = 0.1;

/// A mass scale (CorrectionReport::massScale) above which a query warns that its corrected data are
/// unreliable: the morphed tets hold less than four fifths of the target's volume, and the rest, a part
/// the entry has no tets for, is lumped at their boundary as mass without stiffness. On the twelve real
/// meshes of the benchmarks the three corrected answers past it (mass scales 1.5, 1.8 and 3.1) were 31-45 %
/// low; the others were at most 1.14, and so were all of 148 fracture fragments' (at most 1.08).
inline constexpr double kMassScaleWarning = 1.25;

/// The most mass the morph misses that one node of the morphed tets takes, as a multiple of its own mass
/// (unit density: a quarter of each tet it is a corner of). The missing mass goes to the boundary nodes
/// nearest where the target lies outside the tets; where a morph has pulled a sliver of tets out towards a
/// sharp corner, the whole corner's share lands on the sliver's tip, a node of next to no mass held by next
/// to no stiffness, which then rings on its own: a mode of the mesh that the object does not have, and the
/// first. A node whose mass grows by a factor 1 + R rings √(1 + R) times lower; a default entry is some
/// eight to ten tets across, so past R ≈ 16 (four times lower) such a node's own mode comes down among the
/// body's first. What a node cannot take goes to the others by the same weights; what none can, to every
/// node by its own mass. Measured (docs/architecture.md, "The mass the morph misses"): a regular
/// tetrahedron corrected from a fragment entry, whose tip node had taken 263 times its mass, rang −38 %,
/// and −1.5 % with the limit; of 148 fracture fragments and twelve real meshes, four answers changed.
inline constexpr double kPointMassLimit = 16.0;

/// A share of the first corrected mode's kinetic energy on one node's lumped mass (CorrectionReport::
/// lumpedModeShare) past which that mode is the node's, not the body's: a body's mode moves hundreds of
/// nodes. The morph can leave a node held by next to no stiffness (the tip of a sliver it pulled out); the
/// mass lumped there, even a few times its own, then rings on its own, as the first mode. A fragment of a
/// figure corrected on a union entry rang at a third of its frequency so, 99 % of the first mode's energy
/// on one node; with the missing mass (1.9 % of the whole) spread over the tets instead, within 1 %.
/// Over 160 corrections of fracture fragments and real meshes (docs/architecture.md) the first mode's
/// share was under 0.3 but for that one and one other (0.70). Only the first mode is checked: spreading
/// the mass where a higher mode was one node's (0.53 in a turbine blade's third) put the first
/// frequency 46 % high instead of 5 %.
inline constexpr double kLumpedModeLimit = 0.5;

/// What a query's answer says of a correction that may be far off (stray share over kStrayShareWarning,
/// mass scale over kMassScaleWarning), one sentence each; empty for one that is not.
std::vector<std::string> correctionWarnings(const CorrectionReport& report);

/// Whether morph `a` is a better one to compute the modes on than `b` (a query's candidates,
/// io::QueryOptions::correctionCandidates): one whose tets do not stray across a gap of the target
/// (strayShare ≤ kStrayShareWarning) before one whose do, whatever their distances; then the one that
/// reaches the target's surface best (the smaller morph.meanTargetDistance). Neither is better than an
/// equal.
bool betterMorph(const CorrectionReport& a, const CorrectionReport& b);

/// The corrected entry: PhysicalData in the entry's canonical frame as a database entry's (so that
/// core::adapt carries it to the query like any entry: the target's mass, unit Young's modulus), with the
/// morphed tets, the modes computed on them with the mass they lack lumped at their boundary
/// (MorphedEntry::pointMasses; the entry's Poisson ratio), their sound frequencies, and their mass
/// properties with that mass spread over them (the density report.massScale); the collision compound is
/// the entry's.
struct CorrectedEntry {
  core::PhysicalData physics;
  CorrectionReport report;
};

/// The correction's first half: `entry`'s tets morphed onto `target`; report has the morph, the mass
/// scale and morphSeconds. How well the result reaches the target
/// (report.morph.meanTargetDistance) is known here, before the modes cost anything: a query chooses among
/// its best matches by it.
struct MorphedEntry {
  core::TetMesh tetMesh;
  CorrectionReport report;
  /// Per node of tetMesh, the mass lumped there (unit density; ModalOptions::pointMasses): the target's
  /// volume the tets lack, shared among the boundary nodes next to where the target lies outside them, in
  /// proportion to the area there times how far outside (over MorphTarget's samples of the target), none
  /// more than kPointMassLimit times its own mass while the others can take the rest. Empty
  /// where the tets hold at least the target's volume (their density is then lowered to give its mass) or
  /// nothing of the target lies outside them.
  std::vector<double> pointMasses;
};

/// Morphs `entry`'s tets onto `target` (the query's surface carried into the entry's canonical frame:
/// unit volume, the entry's axes, core::Placement::toEntry), and finds where the mass they lack goes
/// (pointMasses, report.massScale). Thread-safe. Errors: kInvalidArgument (the entry's modes do not fit its
/// tets), morphTetMesh's (the morph would invert a tet: keep the entry's data).
Result<MorphedEntry> morphEntry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                const CorrectionOptions& options = {});
/// Whether morphEntry places the mass the morphed tets lack (MorphedEntry::pointMasses), or leaves it to
/// placeMissingMass: a query morphs several candidates and keeps one, and the choice does not need it (it
/// visits every vertex of the target, the largest part of a morph onto a scan of many triangles).
enum class MissingMass { kPlaced, kDeferred };

/// The same onto a prepared target, as `target` sees it: a query's candidates share one preparation of
/// its surface, each through its own orientation. report.morphSeconds leaves the preparation out.
Result<MorphedEntry> morphEntry(const core::PhysicalData& entry, const MorphTarget::View& target,
                                const CorrectionOptions& options = {},
                                MissingMass missing = MissingMass::kPlaced);

/// The mass `morphed` (morphEntry onto `target`, with MissingMass::kDeferred) lacks, placed as morphEntry
/// places it: after this, `morphed` is what morphEntry would have returned.
void placeMissingMass(MorphedEntry& morphed, const MorphTarget::View& target);

/// The options the modes of `morphed` are computed with: `modal`'s (the database's: count, elements,
/// Poisson ratio) with E = ρ = 1 and morphed.pointMasses, or ρ = report.massScale where there are none.
ModalOptions morphedModalOptions(const MorphedEntry& morphed, const ModalOptions& modal);

/// The correction's second half: the modes of `morphed` (morphEntry of this `entry`) computed with
/// morphedModalOptions(morphed, modal), seeded by the entry's modes; the entry's collision compound and
/// damping. Where the first mode is one node's lumped mass ringing on its own (report.lumpedModeShare
/// over kLumpedModeLimit), the modes are computed again with the missing mass spread over the tets as
/// density (report.massSpread). Thread-safe. Errors: computeModesFrom's.
Result<CorrectedEntry> correctMorphed(const core::PhysicalData& entry, MorphedEntry morphed,
                                      const ModalOptions& modal);

/// Both halves: morphEntry, then correctMorphed.
Result<CorrectedEntry> correctGeometry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                       const ModalOptions& modal, const CorrectionOptions& options = {});

}  // namespace shapedb::volume
