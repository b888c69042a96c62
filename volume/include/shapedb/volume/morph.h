#pragma once
// Morphing a tet mesh onto another surface: the geometry correction's first half (docs/architecture.md,
// "Geometry correction"). A database entry's tets have the entry's proportions and thin parts; carried
// onto the query's own surface they have the query's, and modes computed on them are the query's to
// within what the entry's resolution can hold.

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::volume {

namespace detail {
struct MorphPlanState;
}

class MorphPlan;

/// How morphTetMesh moves the nodes.
struct MorphOptions {
  /// First stretch the whole mesh along x, y and z until its second moments equal the target's (an affine
  /// map: every tet stays positive), so that the projection only has the non-affine rest to do.
  bool prestretch = true;
  /// Rounds of elastic registration before the final projection: each fits the mesh, as an elastic body,
  /// to the target both ways (its boundary nodes to their closest target points, the target's points to
  /// their closest boundary points), with a fit weight that grows round by round from stiff to close.
  /// The second direction is what carries the boundary into the target's protrusions (a limb the entry
  /// lacks), where closest points alone would never go. 0: projection only.
  int registrationRounds = 8;
  /// The boundary's displacement is carried into the interior in one increment or, where that would push a
  /// tet under minQuality, in this many (the mesh-motion stiffness assembled again before each).
  int maxIncrements = 8;
  /// Worst mean-ratio quality a morphed tet may have (1: regular, 0: flat), or half the mesh's own worst
  /// if that is lower. Below it a tet is nearly inverted, and its stiffness garbage: the morph goes no
  /// further than this bound allows.
  double minQuality = 0.02;
  /// What the morphs of the same tets share, kept from one to the next (MorphPlan); none where null.
  MorphPlan* plan = nullptr;
};

/// What the morph did, in the mesh's units.
struct MorphReport {
  core::Vec3 stretch = core::Vec3::Ones();  ///< the prestretch along x, y, z
  double entryWorstQuality = 0.0;           ///< worst mean-ratio quality of a tet before the morph
  double worstQuality = 0.0;                ///< after it
  double maxBoundaryMove = 0.0;             ///< largest move of a boundary node, prestretch included
  double meanBoundaryMove = 0.0;
  /// Mean distance from the target's surface to the morphed boundary (over MorphTarget's samples, by their
  /// areas): how much of the target the morphed mesh does not reach (a handle the entry has no material
  /// for, say).
  double meanTargetDistance = 0.0;
  int increments = 0;  ///< increments of the final projection
  /// The share of the final projection onto the target that was taken, weighted by area (1: the whole
  /// boundary lies on the target). Less where the whole would have crushed a tet against a sharp edge of
  /// the target: there the boundary nodes of those tets take ½, ¼, ⅛ or none of their move, and lie off
  /// the target by the rest (see meanTargetDistance).
  double projected = 0.0;
};

struct MorphResult {
  core::TetMesh mesh;  ///< the input's tets over moved nodes, every tet positive
  MorphReport report;
};

/// Mean-ratio quality of a tet: 12 (3|V|)^(2/3) / Σ (edge length)², 1 for the regular tet, 0 for a flat
/// one; negative volumes give negative values.
double tetQuality(const core::TetMesh& mesh, std::size_t t);

/// A surface to morph onto, prepared once: checked, its closest-point tree and side test built, its mass
/// properties and vertex areas computed, all in the frame it is given in. A morph sees it through an
/// orthogonal map into the tet mesh's frame (View): the points the morph asks about are carried into the
/// target's frame and the answers back, so that one preparation serves every entry a query morphs, each in
/// its own orientation (each used to build two trees over its own copy of the surface: a fifth of a
/// corrected query's time on a scan of 100,000 triangles). Immutable once prepared: concurrent morphs are
/// safe.
class MorphTarget {
 public:
  /// Errors: kInvalidArgument (the surface fails core::validateMesh).
  static Result<MorphTarget> prepare(core::TriangleMesh surface);

  const core::TriangleMesh& surface() const { return mSurface; }
  /// At unit density; empty where the surface bounds no solid (open, or wound inward), which has no
  /// volume, no moments and no inside.
  const std::optional<core::MassProperties>& massProperties() const { return mMass; }
  /// The surface as points that each stand for a part of its area, what the morph measures the target
  /// by (its fit's correspondences from the target's side, how closely the morph reaches it, where its
  /// missing mass goes): the vertices, each with a third of the area of its triangles, and where a triangle
  /// holds more than 1/kSampledArea of the surface's area, the points of a regular subdivision of it into
  /// n² triangles of at most that area, each with a third of the area of its small triangles (the
  /// triangle's corners then keep a third of one small triangle's). A surface of small triangles (a scan, a
  /// fragment) is its vertices, as before there were samples; a low-poly one (a tetrahedron, a box of
  /// twelve triangles, a game prop) is sampled over its faces as well, not only at its corners, where the
  /// mass its morph misses used to go all at once. The areas sum to the surface's.
  std::size_t sampleCount() const { return mSamples.size(); }
  const std::vector<double>& sampleAreas() const { return mSampleAreas; }
  /// Triangles over 1/kSampledArea of the surface's area are subdivided for the samples. A hundredth
  /// leaves meshes of hundreds of triangles or more as they were; a thousandth also subdivided fragments'
  /// flat cuts, and their corrected answers came out a point lower (docs/architecture.md, "Low-poly
  /// surfaces").
  static constexpr double kSampledArea = 100.0;

  /// The target as a mesh in another frame sees it: `frame` (orthogonal) carries a point of the target's
  /// frame into the mesh's. Holds the target by reference.
  class View {
   public:
    View(const MorphTarget& target, const core::Mat3& frame) : mTarget(&target), mFrame(frame) {}
    const MorphTarget& target() const { return *mTarget; }
    std::size_t sampleCount() const { return mTarget->mSamples.size(); }
    /// Sample i (MorphTarget::sampleAreas), in the mesh's frame.
    core::Vec3 sample(std::size_t i) const { return mFrame * mTarget->mSamples[i]; }
    core::Vec3 closestPoint(const core::Vec3& p) const;
    /// The same, the search started from the target's triangle `near` (the one found for a nearby point,
    /// or for this point before it moved; kNoHint for none), which is then set to the triangle found: the
    /// same point whatever the start, found sooner from a good one.
    core::Vec3 closestPoint(const core::Vec3& p, std::uint32_t& near) const;
    /// Whether p lies inside the surface. Precondition: massProperties() (the surface bounds a solid).
    bool inside(const core::Vec3& p) const { return mTarget->mSide.inside(mFrame.transpose() * p); }
    /// The same, started from and setting `near` as closestPoint does.
    bool inside(const core::Vec3& p, std::uint32_t& near) const {
      return mTarget->mSide.signedDistance(mFrame.transpose() * p, near) < 0.0;
    }
    /// ∫ (x − c)(x − c)ᵀ dV about the centre of mass, in the mesh's frame. Precondition: massProperties().
    core::Mat3 covariance() const;

   private:
    const MorphTarget* mTarget;
    core::Mat3 mFrame;
  };
  /// No triangle to start a search from (View::closestPoint, View::inside): the target's tree's.
  static constexpr std::uint32_t kNoHint = core::ClosestPointTree::kNoHint;
  /// In the target's own frame.
  View view() const { return View(*this, core::Mat3::Identity()); }

 private:
  MorphTarget() = default;
  const core::ClosestPointTree& tree() const { return mMass ? mSide.tree() : mTree; }
  core::TriangleMesh mSurface;
  std::optional<core::MassProperties> mMass;
  std::vector<core::Vec3> mSamples;  ///< the vertices first, in order, then the subdivisions' points
  std::vector<double> mSampleAreas;
  core::SurfaceSide mSide;       ///< built where the surface bounds a solid; its tree serves the searches
  core::ClosestPointTree mTree;  ///< built only where it does not
};

/// Moves `mesh`'s boundary nodes onto `target` (a closed surface in the same frame and of about the same
/// size and orientation: a query carried into its matched entry's canonical frame) and its inner nodes
/// with them: prestretch; elastic registration; then every boundary node onto its closest target point,
/// that last displacement extended into the interior as the displacement of an elastic body whose small
/// tets are the stiffest (they deform least), in increments. Deterministic and thread-safe.
/// Errors: kInvalidArgument (the mesh fails validateTetMesh, the target is empty or not finite, options
/// out of range); kDegenerateFace when no part of the morph keeps every tet above minQuality (the message
/// gives the quality reached): the caller keeps the unmorphed data.
Result<MorphResult> morphTetMesh(const core::TetMesh& mesh, const core::TriangleMesh& target,
                                 const MorphOptions& options = {});

/// The same onto a prepared target, as `target` sees it (the same result as morphing onto a copy of the
/// target's surface carried into the mesh's frame, to round-off; its test compares the two).
Result<MorphResult> morphTetMesh(const core::TetMesh& mesh, const MorphTarget::View& target,
                                 const MorphOptions& options = {});

/// What morphTetMesh works out from a tet mesh's connectivity alone, whatever its nodes' positions: its
/// boundary, the layout of the mesh-motion stiffness and of the interior's system, and the symbolic
/// analysis of the registration's system. A query morphs the tets of the same database entries again and
/// again: given in MorphOptions::plan, a plan keeps the first morph's and the later morphs of the same tets
/// start from it (the same morph, to the bit, without a tenth of its time). It serves the connectivity it
/// was first used with; a morph of other tets ignores it and leaves it as it is. Thread-safe: concurrent
/// morphs may share one.
class MorphPlan {
 public:
  MorphPlan();
  ~MorphPlan();
  MorphPlan(const MorphPlan&) = delete;
  MorphPlan& operator=(const MorphPlan&) = delete;
  /// Whether a morph has left its layout here.
  bool ready() const;

 private:
  friend Result<MorphResult> morphTetMesh(const core::TetMesh&, const MorphTarget::View&,
                                          const MorphOptions&);
  std::unique_ptr<detail::MorphPlanState> mState;
};

}  // namespace shapedb::volume
