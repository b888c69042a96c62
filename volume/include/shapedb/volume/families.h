#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::volume {

/// The shape families of the database: the paper's six generic convex families (§6); shards and fragments
/// for fracture, the "scenario-based database" of its §7; and the non-convex families that real objects
/// resemble, whose lowest modes live in thin parts (a handle, a limb, a wall, a fin), which no convex
/// entry has. `kUser` is for the meshes `shapedb add` brings, `kLearned` for the objects a database learned
/// while it was queried (io/enrich.h). Stored by name (toString), so the order here is not part of the
/// file format.
enum class Family : std::uint8_t {
  kBox,
  kEllipsoid,
  kCylinder,
  kCone,
  kCapsule,
  kPrism,
  kShard,
  kFragment,
  kRing,
  kRod,
  kBeam,
  kHoled,
  kShell,
  kLimbed,
  kStone,
  kUnion,
  kUser,
  kLearned
};

/// The families a default build uses, in catalog order: all but kUser and kLearned.
std::span<const Family> generatedFamilies();
/// The convex families of databases built before the non-convex ones existed: box to fragment.
std::span<const Family> convexFamilies();
/// "box", "ellipsoid", "cylinder", "cone", "capsule", "prism", "shard", "fragment", "ring", "rod", "beam",
/// "holed", "shell", "limbed", "stone", "union", "user".
const char* toString(Family family);
std::optional<Family> parseFamily(std::string_view name);
/// A comma-separated list of family names ("box,cone"); "all" for generatedFamilies().
/// Errors: kInvalidArgument naming the unknown family, or for "user" (not generated) or duplicates, or
/// for a weight (parseFamilyMix reads those).
Result<std::vector<Family>> parseFamilies(std::string_view list);

/// The families of a catalog and each one's weight: its share of the entries relative to the others'
/// (a family of weight 2 gets twice the entries of one of weight 1).
struct FamilyMix {
  std::vector<Family> families;
  std::vector<unsigned> weights;  ///< as many as families, each in [1, kMaxFamilyWeight]
};
inline constexpr unsigned kMaxFamilyWeight = 100;

/// The default catalog's mix: every generated family, evenly (weight 1 each). Weighting fragments 4 and
/// shards 2 was measured (docs/architecture.md, "How many of each"): no better on fracture fragments,
/// and a convex fragment then won the correction's choice on a limbed real object.
FamilyMix defaultFamilyMix();
/// Whether `weights` can weigh `families` families: none (even), or one each in [1, kMaxFamilyWeight].
bool validFamilyWeights(std::size_t families, std::span<const unsigned> weights);
/// "box,fragment:3": family names, each with an optional weight (1 unless given); "all" for
/// defaultFamilyMix(). Errors as parseFamilies, and kInvalidArgument for a weight that is not a whole
/// number in [1, kMaxFamilyWeight].
Result<FamilyMix> parseFamilyMix(std::string_view list);
/// "box,fragment:3": the mix as parseFamilyMix reads it (weights of 1 left out; all of defaultFamilyMix()
/// as "all").
std::string toString(const FamilyMix& mix);

/// One generated shape: its family and where it sits in the family's sweep. Deterministic: the same spec
/// always gives the same mesh.
///
/// The sweep is a two-dimensional low-discrepancy (R2) sequence over the family's shape parameters, so any
/// count covers the parameter domain evenly and a larger sweep extends a smaller one. Parameters:
/// - box, ellipsoid: sides (or semi-axes) 1 ≥ a ≥ b ≥ 0.1, log-uniform (both symmetries folded);
/// - cylinder, cone, capsule, prism: along z, cross-section aspect a ∈ [0.1, 1] (y over x), length over
///   cross-section size c ∈ [0.1, 10], both log-uniform;
/// - shard: the seed of a random convex polyhedron (a cube cut by 6–14 random half-spaces, then
///   stretched), params unused;
/// - fragment: what fracture breaks off a solid: the Voronoi cell of one of p random seeds inside a box,
///   an ellipsoid or an elliptic cylinder (by index mod 3) of semi-axes 1 ≥ a ≥ b ≥ 0.04, clipped to it;
///   a and b log-uniform as for boxes, p log-uniform in [4, 100), the seeds from the index.
/// The non-convex families sweep what sets their lowest modes (sizes are relative: normalization takes the
/// scale away), log-uniform unless said. Their thinnest parts stop at about a tenth of their length: an
/// entry's tets, and so its build time, grow as the inverse square of its thinness.
/// - ring (handles, rings, washers): a torus of centre-line radius 1, section radius r ∈ [0.12, 0.6],
///   section flattened along the axis to f ∈ [0.4, 1] of that; params (r, f, 0);
/// - rod (bent rods, arcs, hooks): a round rod of radius r ∈ [0.07, 0.3] bent through θ (uniform, 0.5 rad
///   to as far as its ends stay clear) on a radius of 1; arcs up to π get a straight shank s ∈ [0.5, 2.5]
///   (a hook) half the time; params (θ, r, s);
/// - beam (brackets and beams): L, T, U, H and I sections by index mod 5, flange width 1, walls
///   t ∈ [0.1, 0.3], length c ∈ [0.3, 4], height h from the index's stream; params (t, c, h);
/// - holed (plates and blocks with holes): a 2 × 2a × 2b box, a ∈ [0.3, 1], b ∈ [0.08, 0.5] (at most a),
///   pierced through b by n ∈ [1, 6] round holes on a grid, each 0.35 to 0.7 of its cell across;
///   params (a, b, n);
/// - shell (cups, bowls, tubes, boxes open on one side, by index mod 4): radius 1, half-height
///   h ∈ [0.3, 2], walls w ∈ [0.1, 0.3] (and at least 0.06·max(1, h) and at most 0.4 h), an open
///   box d ∈ [0.5, 1] (uniform) deep; params (h, w, d or 0);
/// - limbed (animals, figures): an ellipsoidal body of half-length 1 with n ∈ [2, 6] limbs of length
///   l ∈ [0.5, 1.8] (uniform) and radius r ∈ [0.09, 0.22], maybe a head and ears; params (n, l, r);
/// - stone (lumpy stones): an ellipsoid (1, a, b), 1 ≥ a ≥ b ≥ 0.3, a ≥ 0.45, its radius modulated by
///   smooth random waves of total amplitude m ∈ [0.08, 0.3] (uniform), on a subdivided icosahedron
///   (ShapeResolution::stoneSubdivisions); params (a, b, m);
/// - union (unions of primitives): n ∈ [2, 4] boxes, ellipsoids, cylinders and capsules of random
///   proportions, orientations and overlaps; params (n, 0, 0).
/// The drawn details (hole positions, limb placement, waves, primitives) come from the index's stream.
struct ShapeSpec {
  Family family = Family::kBox;
  std::uint32_t index = 0;                 ///< position in the family's sweep
  core::Vec3 params = core::Vec3::Zero();  ///< (a, c or b, 0); fragments (a, b, p); shards: zero; above
  /// "box-00017": unique within a database, stable across builds of any size.
  std::string name() const;
};

/// The index-th spec of a family's sweep.
ShapeSpec familySpec(Family family, std::uint32_t index);

/// `entries` specs shared out over `families` in proportion to their `weights` (empty: evenly), in a
/// fixed order: family by family, each family's sweep from index 0. Each family gets the whole part of
/// its share; what is left goes one entry each to the largest fractions, the first family first among
/// equals (so an even catalog gives the remainder to the first families, as it always did).
std::vector<ShapeSpec> buildCatalog(std::size_t entries, std::span<const Family> families,
                                    std::span<const unsigned> weights = {});

/// Surface resolution of curved families.
struct ShapeResolution {
  int segments = 24;  ///< around the axis (cylinder, cone, capsule, ellipsoid; a ring's or rod's section)
  int stacks = 12;    ///< pole to pole (ellipsoid); capsule caps get half each
  /// Triangles of a limbed body's level-set surface per segment (of at least 16: its limbs need them).
  int trianglesPerSegment = 20;
  /// Triangles of a union's level-set surface per segment, at least 100 in all. TetGen meshes a union
  /// from its surface inward, about ten tets a surface triangle at the quadratic build's bounds: 12 a
  /// segment (the quadratic catalog's; 144 triangles at 12 segments) gave six unions a third fewer tets
  /// than 20, their frequencies still within 2.1 % of the same surfaces meshed three times finer
  /// (docs/accuracy.md).
  int unionTrianglesPerSegment = 20;
  /// Subdivisions of the icosahedron a stone is made from (1: 80 triangles; 2: 320; each level four
  /// times the last; validStoneSubdivisions). Its waves are smooth, and 80 triangles keep a stone's
  /// frequencies within 1 % of its meshing three times finer for half the tets of 320 (docs/accuracy.md).
  int stoneSubdivisions = 2;
};

/// The range of ShapeResolution::stoneSubdivisions: 80 to 20,480 triangles.
inline constexpr int kMinStoneSubdivisions = 1, kMaxStoneSubdivisions = 4;
inline bool validStoneSubdivisions(int subdivisions) {
  return subdivisions >= kMinStoneSubdivisions && subdivisions <= kMaxStoneSubdivisions;
}

/// The closed, outward-oriented surface mesh of a spec: one connected solid, which TetGen meshes.
/// Deterministic. The families made from level sets (limbed, union) take milliseconds to
/// tenths of a second; the others microseconds. Errors: kInvalidArgument for kUser; kNotClosed (or
/// kSelfIntersecting) if a level-set family's sixteen draws for an index all fail to come out as one
/// closed piece whose surface does not pass through itself (never seen; one draw in 400 needed a second).
Result<core::TriangleMesh> makeFamilyShape(const ShapeSpec& spec, const ShapeResolution& resolution = {});

}  // namespace shapedb::volume
