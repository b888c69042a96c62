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

/// The shape families of the database (paper §6: six generic families; shards and fragments added for
/// fracture, the "scenario-based database" of the paper's §7), and
/// `kUser` for the meshes `shapedb add` brings.
enum class Family : std::uint8_t {
  kBox,
  kEllipsoid,
  kCylinder,
  kCone,
  kCapsule,
  kPrism,
  kShard,
  kFragment,
  kUser
};

/// The families a default build uses, in catalog order: all but kUser.
std::span<const Family> generatedFamilies();
/// "box", "ellipsoid", "cylinder", "cone", "capsule", "prism", "shard", "fragment", "user".
const char* toString(Family family);
std::optional<Family> parseFamily(std::string_view name);
/// A comma-separated list of family names ("box,cone"); "all" for generatedFamilies().
/// Errors: kInvalidArgument naming the unknown family, or for "user" (not generated) or duplicates.
Result<std::vector<Family>> parseFamilies(std::string_view list);

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
struct ShapeSpec {
  Family family = Family::kBox;
  std::uint32_t index = 0;                 ///< position in the family's sweep
  core::Vec3 params = core::Vec3::Zero();  ///< (a, c or b, 0); fragments (a, b, p); shards: zero
  /// "box-00017": unique within a database, stable across builds of any size.
  std::string name() const;
};

/// The index-th spec of a family's sweep.
ShapeSpec familySpec(Family family, std::uint32_t index);

/// About `entries` specs spread evenly over `families` (the first families take the remainder), in a
/// fixed order: family by family, each family's sweep from index 0.
std::vector<ShapeSpec> buildCatalog(std::size_t entries, std::span<const Family> families);

/// Surface resolution of curved families.
struct ShapeResolution {
  int segments = 24;  ///< around the axis (cylinder, cone, capsule, ellipsoid)
  int stacks = 12;    ///< pole to pole (ellipsoid); capsule caps get half each
};

/// The closed, outward-oriented surface mesh of a spec. Errors: kInvalidArgument for kUser.
Result<core::TriangleMesh> makeFamilyShape(const ShapeSpec& spec, const ShapeResolution& resolution = {});

}  // namespace shapedb::volume
