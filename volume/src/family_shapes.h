#pragma once

// The generators of the families that real objects resemble: rings, rods, beams, plates with holes,
// shells and stones (meshed directly, swept_shapes.cpp), limbed bodies and unions of primitives (built by
// constructive solid geometry on level sets: composite_shapes.cpp draws the terms, csg.cpp meshes them).
// Internal to volume: families.cpp owns the parameters (ShapeSpec) and calls these.

#include <cstdint>
#include <random>
#include <span>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::volume::detail {

/// The random stream of a family's entry: seeded by the index and a salt of the family's own, so that it
/// does not line up with the sweep's R2 parameters nor with another family's stream.
inline std::mt19937_64 entryStream(std::uint32_t index, std::uint64_t salt) {
  return std::mt19937_64(index * 0x9E3779B97F4A7C15ull + salt);
}

/// A torus about z: centre-line radius 1, an elliptic section of radial semi-axis `tube` < 1 and axial
/// semi-axis tube·`flatness`; `segments` around the section, twice that around the axis.
core::TriangleMesh makeRingShape(double tube, double flatness, int segments);

/// A round rod of radius `radius` bent along a circular arc of radius 1 through `angle` radians, after a
/// straight shank of length `shank` (0: an arc; a hook otherwise), closed by flat ends. Preconditions:
/// radius < 1; the ends and the shank keep clear of the arc (familySpec draws them so).
core::TriangleMesh makeRodShape(double angle, double radius, double shank, int segments);

/// The cross-sections of the beam family, extruded along z.
enum class BeamSection { kL, kT, kU, kH, kI };

/// A beam of `section` (flange width 1 along x, height `height` along y, walls `thickness`), length
/// `length` along z. Sharp edges; the ends are the section, triangulated by ear clipping.
core::TriangleMesh makeBeamShape(BeamSection section, double thickness, double height, double length);

/// A lumpy stone: the ellipsoid of semi-axes (1, a, b) with its radius modulated by random low-order
/// waves of relative amplitude at most `amplitude` < 0.5, drawn from `rng`; star-shaped about its centre
/// by construction (a positive radius along every direction). Its vertices are those of an icosahedron
/// subdivided `subdivisions` times (20 · 4^subdivisions triangles).
core::TriangleMesh makeStoneShape(double a, double b, double amplitude, int subdivisions,
                                  std::mt19937_64& rng);

/// The kinds of the shell family.
enum class ShellKind { kCup, kBowl, kTube, kOpenBox };

/// Plates and blocks with holes: the 2 × 2a × 2b box (b along z) pierced along z by `holes` round holes,
/// one in each of the first cells of a grid of about square cells (row by row), `fill` (< 1) of a cell
/// across; each cell's face an annulus of quads between its edges and its hole (or a fan), shared edges
/// subdivided alike, so the surface is conforming.
core::TriangleMesh makeHoledShape(double a, double b, int holes, double fill, int segments);

/// Thick-walled shells open to the outside: radius (or half-width along x) 1, half-height `height`, walls
/// `wall` thick (< 0.5, and < height for a bowl); an open box is `depth` (> 2 wall) deep along y. Cups,
/// bowls and tubes are surfaces of revolution (`segments` around), an open box is planar.
core::TriangleMesh makeShellShape(ShellKind kind, double height, double wall, double depth, int segments);

/// Limbed bodies: an ellipsoidal body of half-length 1 with `limbs` (2 to 6) capsule limbs of axis length
/// `length` and radius `radius`, a head and ears drawn from `rng`.
Result<core::TriangleMesh> makeLimbedShape(int limbs, double length, double radius, std::mt19937_64& rng,
                                           std::size_t maxTriangles);

/// The union of `count` (2 to 4) boxes, ellipsoids, cylinders and capsules drawn from `rng`, each centred
/// inside the one before it.
Result<core::TriangleMesh> makeUnionShape(int count, std::mt19937_64& rng, std::size_t maxTriangles);

/// One term of a constructive solid: a closed surface added to (or cut from) what the terms before it
/// made.
struct CsgTerm {
  core::TriangleMesh solid;
  bool subtract = false;
};

/// The solid of `terms` in order (the first is added), meshed from level sets whose voxel puts three across
/// `thinnest` (m, the thinnest wall or ligament) unless the surface would then be more than ~20,000 raw
/// triangles (48 to 240 voxels across the whole), then simplified toward `maxTriangles` within a voxel.
/// Errors: kNotClosed when the result is not one closed, manifold solid (the caller draws again),
/// kInvalidArgument for no terms.
Result<core::TriangleMesh> meshCsg(std::span<const CsgTerm> terms, double thinnest, std::size_t maxTriangles);

}  // namespace shapedb::volume::detail
