#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <system_error>

#include <shapedb/core/primitives.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/families.h>

#include "family_shapes.h"
#include "polyhedron.h"
#include "random_draws.h"

namespace shapedb::volume {
namespace {

using core::TriangleMesh;
using core::Vec3;
using detail::clip;
using detail::Polygon;
using detail::triangulate;

constexpr std::array kGenerated = {Family::kBox,     Family::kEllipsoid, Family::kCylinder, Family::kCone,
                                   Family::kCapsule, Family::kPrism,     Family::kShard,    Family::kFragment,
                                   Family::kRing,    Family::kRod,       Family::kBeam,     Family::kHoled,
                                   Family::kShell,   Family::kLimbed,    Family::kStone,    Family::kUnion};
constexpr std::size_t kConvexCount = 8;  ///< box to fragment
constexpr double kMinRatio = 0.1;        ///< thinnest side over the largest
constexpr double kMaxLength = 10.0;      ///< longest axial length over the cross-section
// Fragments: the broken solid's thinnest side over its largest (a 40 × 30 × 2 cm plate is 0.05), and the
// number of Voronoi seeds it is broken with.
constexpr double kMinFragmentSourceRatio = 0.04;
constexpr double kMinPieces = 4.0, kMaxPieces = 100.0;

/// Martin Roberts' R2 sequence: the plastic number's powers give the most even 2-D coverage of any
/// additive recurrence. Point i in [0, 1)².
std::array<double, 2> r2(std::uint32_t i) {
  constexpr double g = 1.32471795724474602596;
  const double n = static_cast<double>(i) + 1.0;
  return {std::fmod(0.5 + n / g, 1.0), std::fmod(0.5 + n / (g * g), 1.0)};
}

/// t ∈ [0, 1] mapped log-uniformly onto [lo, hi].
double logLerp(double lo, double hi, double t) {
  return lo * std::exp(std::log(hi / lo) * t);
}

double uniformDraw(std::mt19937_64& rng) {
  return std::uniform_real_distribution<double>(0.0, 1.0)(rng);
}

/// The salts of the index streams: one for the parameters familySpec draws, another for the shape's own
/// details, so that neither repeats the other's numbers.
constexpr std::uint64_t kSpecSalt = 0xF4A6, kShapeSalt = 0x5A17;

/// How far a rod of radius r bent on a radius of 1 can go round before its ends meet: the ends' centres
/// 1.3 r apart along the chord each side, their inner rims clear.
double maxRodAngle(double r) {
  return 2.0 * std::numbers::pi - 2.0 * std::asin(std::min(1.0, 1.3 * r)) -
         2.0 * std::asin(std::min(1.0, 0.3 * r / (1.0 - r)));
}

TriangleMesh scaled(TriangleMesh mesh, const Vec3& s) {
  for (Vec3& p : mesh.vertices)
    p = p.cwiseProduct(s);
  return mesh;
}

/// A random convex shard from `seed`: a cube cut by random half-spaces, stretched. Redrawn (from the same
/// generator, so still deterministic) in the rare case that a cut leaves a sliver the mesh checks refuse.
TriangleMesh makeShard(std::uint64_t seed) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x5EED);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  for (;;) {
    std::vector<Polygon> faces;
    const TriangleMesh cube = core::makeBox(Vec3(2, 2, 2));
    // Start from the cube's six faces as quads (its triangles come in pairs sharing the diagonal).
    for (std::size_t f = 0; f < cube.triangles.size(); f += 2) {
      const auto& a = cube.triangles[f];
      const auto& b = cube.triangles[f + 1];
      faces.push_back({cube.vertices[a[0]], cube.vertices[a[1]], cube.vertices[a[2]], cube.vertices[b[2]]});
    }
    const int cuts = 6 + static_cast<int>(unit(rng) * 9.0);
    for (int c = 0; c < cuts; ++c) {
      const Vec3 n = detail::drawVector([&] { return normal(rng); }).normalized();
      faces = clip(faces, n, 0.35 + 0.65 * unit(rng));
    }
    const double thinnest = std::exp(std::log(kMinRatio) * unit(rng));  // drawn first, as GCC did
    const Vec3 stretch(1.0, std::exp(std::log(0.2) * unit(rng)), thinnest);
    TriangleMesh mesh = scaled(triangulate(faces), stretch);
    if (core::validateMesh(mesh).ok() && core::analyzeTopology(mesh).isClosed()) return mesh;
  }
}

/// The convex solids fragments are broken from, semi-axes (1, a, b): a box, or an ellipsoid or elliptic
/// cylinder along z as the box cut by tangent planes (planar polygon faces throughout: a triangulated
/// curved surface, clipped, leaves fan slivers that TetGen crashes on).
enum class FragmentSolid { kBox, kEllipsoid, kCylinder };

std::vector<Polygon> fragmentSolid(FragmentSolid kind, const Vec3& half) {
  std::vector<Polygon> faces = detail::boxFaces(-half, half);
  const auto cutTangent = [&](const Vec3& unitPoint) {  // the tangent plane at half ⊙ unitPoint
    const Vec3 n = unitPoint.cwiseQuotient(half);
    faces = clip(faces, n, n.dot(unitPoint.cwiseProduct(half)));
  };
  if (kind == FragmentSolid::kEllipsoid) {
    constexpr int kPlanes = 96;  // a Fibonacci sphere of directions
    for (int i = 0; i < kPlanes; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / kPlanes, r = std::sqrt(1.0 - z * z);
      const double phi = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
      cutTangent(Vec3(r * std::cos(phi), r * std::sin(phi), z));
    }
  } else if (kind == FragmentSolid::kCylinder) {
    constexpr int kPlanes = 24;
    for (int i = 0; i < kPlanes; ++i) {
      const double phi = 2.0 * std::numbers::pi * (i + 0.5) / kPlanes;
      cutTangent(Vec3(std::cos(phi), std::sin(phi), 0.0));
    }
  }
  return faces;
}

bool insideFragmentSolid(FragmentSolid kind, const Vec3& half, const Vec3& p) {
  const Vec3 u = p.cwiseQuotient(half);
  switch (kind) {
    case FragmentSolid::kBox:
      return true;  // drawn in the box
    case FragmentSolid::kEllipsoid:
      return u.squaredNorm() <= 1.0;
    case FragmentSolid::kCylinder:
      return u.head<2>().squaredNorm() <= 1.0;
  }
  return false;
}

/// A fragment as fracture makes it: the Voronoi cell of the first of `pieces` seeds drawn uniformly inside
/// a convex solid (by index mod 3: box, ellipsoid, cylinder; the plates, slabs, bars, balls and discs that
/// get broken), clipped to the solid. Cells of seeds near the surface keep part of it; the others are cut
/// on every side. Redrawn from the same generator, as shards are, when a cell is a sliver the mesh checks
/// refuse.
TriangleMesh makeFragment(const ShapeSpec& spec) {
  std::mt19937_64 rng(spec.index * 0xD1B54A32D192ED03ull + 0xF4A9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Vec3 half(1.0, spec.params.x(), spec.params.y());
  const int pieces = static_cast<int>(spec.params.z());
  const auto kind = static_cast<FragmentSolid>(spec.index % 3);
  const std::vector<Polygon> solid = fragmentSolid(kind, half);
  for (;;) {
    std::vector<Vec3> seeds;
    while (static_cast<int>(seeds.size()) < pieces) {
      const Vec3 p = detail::drawVector([&] { return 2.0 * unit(rng) - 1.0; }).cwiseProduct(half);
      if (insideFragmentSolid(kind, half, p)) seeds.push_back(p);
    }
    const std::vector<Polygon> cell = detail::voronoiCell(solid, seeds, 0);
    if (cell.size() < 4) continue;
    TriangleMesh mesh = triangulate(cell);
    if (core::validateMesh(mesh).ok() && core::analyzeTopology(mesh).isClosed()) return mesh;
  }
}

}  // namespace

std::span<const Family> generatedFamilies() {
  return kGenerated;
}

std::span<const Family> convexFamilies() {
  return std::span<const Family>(kGenerated).first(kConvexCount);
}

const char* toString(Family family) {
  switch (family) {
    case Family::kBox:
      return "box";
    case Family::kEllipsoid:
      return "ellipsoid";
    case Family::kCylinder:
      return "cylinder";
    case Family::kCone:
      return "cone";
    case Family::kCapsule:
      return "capsule";
    case Family::kPrism:
      return "prism";
    case Family::kShard:
      return "shard";
    case Family::kFragment:
      return "fragment";
    case Family::kRing:
      return "ring";
    case Family::kRod:
      return "rod";
    case Family::kBeam:
      return "beam";
    case Family::kHoled:
      return "holed";
    case Family::kShell:
      return "shell";
    case Family::kLimbed:
      return "limbed";
    case Family::kStone:
      return "stone";
    case Family::kUnion:
      return "union";
    case Family::kUser:
      return "user";
    case Family::kLearned:
      return "learned";
  }
  return "?";
}

std::optional<Family> parseFamily(std::string_view name) {
  if (name == toString(Family::kUser)) return Family::kUser;
  if (name == toString(Family::kLearned)) return Family::kLearned;
  for (Family f : kGenerated)
    if (name == toString(f)) return f;
  return std::nullopt;
}

FamilyMix defaultFamilyMix() {
  FamilyMix mix;
  mix.families.assign(kGenerated.begin(), kGenerated.end());
  mix.weights.assign(kGenerated.size(), 1);
  return mix;
}

Result<FamilyMix> parseFamilyMix(std::string_view list) {
  if (list == "all") return defaultFamilyMix();
  FamilyMix mix;
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    const std::string_view item = list.substr(0, comma);
    const std::size_t colon = item.find(':');
    const std::string_view name = item.substr(0, colon);
    const std::optional<Family> f = parseFamily(name);
    if (!f || *f == Family::kUser || *f == Family::kLearned) {
      std::string known;
      for (Family g : kGenerated)
        known += (known.empty() ? "" : ", ") + std::string(toString(g));
      return Error{ErrorCode::kInvalidArgument,
                   "unknown family '" + std::string(name) + "' (known: " + known + ")"};
    }
    if (std::find(mix.families.begin(), mix.families.end(), *f) != mix.families.end())
      return Error{ErrorCode::kInvalidArgument, "family '" + std::string(name) + "' is listed twice"};
    unsigned weight = 1;
    if (colon != std::string_view::npos) {
      const std::string_view digits = item.substr(colon + 1);
      const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), weight);
      if (ec != std::errc{} || end != digits.data() + digits.size() || weight < 1 ||
          weight > kMaxFamilyWeight)
        return Error{ErrorCode::kInvalidArgument,
                     "the weight of '" + std::string(name) + "' must be a whole number from 1 to " +
                         std::to_string(kMaxFamilyWeight) + ", not '" + std::string(digits) + "'"};
    }
    mix.families.push_back(*f);
    mix.weights.push_back(weight);
    list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
  }
  if (mix.families.empty()) return Error{ErrorCode::kInvalidArgument, "no family given"};
  return mix;
}

Result<std::vector<Family>> parseFamilies(std::string_view list) {
  if (list.find(':') != std::string_view::npos)
    return Error{ErrorCode::kInvalidArgument,
                 "a family list here takes no weights ('" + std::string(list) + "')"};
  auto mix = parseFamilyMix(list);
  if (!mix) return mix.error();
  return std::move(mix->families);
}

bool validFamilyWeights(std::size_t families, std::span<const unsigned> weights) {
  return weights.empty() || (weights.size() == families && std::ranges::all_of(weights, [](unsigned w) {
                               return w >= 1 && w <= kMaxFamilyWeight;
                             }));
}

std::string toString(const FamilyMix& mix) {
  const FamilyMix all = defaultFamilyMix();
  if (mix.families == all.families && mix.weights == all.weights) return "all";
  std::string text;
  for (std::size_t f = 0; f < mix.families.size(); ++f) {
    if (!text.empty()) text += ',';
    text += toString(mix.families[f]);
    if (f < mix.weights.size() && mix.weights[f] != 1) {
      text += ':';
      text += std::to_string(mix.weights[f]);
    }
  }
  return text;
}

std::string ShapeSpec::name() const {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%s-%05u", toString(family), index);
  return buffer;
}

ShapeSpec familySpec(Family family, std::uint32_t index) {
  ShapeSpec spec;
  spec.family = family;
  spec.index = index;
  const auto [u, v] = r2(index);
  switch (family) {
    case Family::kBox:
    case Family::kEllipsoid: {
      const double a = std::exp(std::log(kMinRatio) * u), b = std::exp(std::log(kMinRatio) * v);
      spec.params = Vec3(std::max(a, b), std::min(a, b), 0.0);
      break;
    }
    case Family::kCylinder:
    case Family::kCone:
    case Family::kCapsule:
    case Family::kPrism:
      spec.params =
          Vec3(std::exp(std::log(kMinRatio) * u), std::exp(std::log(kMaxLength) * (2.0 * v - 1.0)), 0.0);
      break;
    case Family::kFragment: {
      // Log-uniform proportions of the broken solid (folded, a ≥ b) and pieces; the count from the
      // index's own stream, so that it does not line up with the R2 proportions.
      const double s = std::exp(std::log(kMinFragmentSourceRatio) * u),
                   t = std::exp(std::log(kMinFragmentSourceRatio) * v);
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      const double w = uniformDraw(rng);
      spec.params = Vec3(std::max(s, t), std::min(s, t),
                         std::floor(kMinPieces * std::exp(std::log(kMaxPieces / kMinPieces) * w)));
      break;
    }
    case Family::kRing:
      spec.params = Vec3(logLerp(0.12, 0.6, u), logLerp(0.4, 1.0, v), 0.0);
      break;
    case Family::kRod: {
      const double r = logLerp(0.07, 0.3, v);
      const double angle = 0.5 + (maxRodAngle(r) - 0.5) * u;
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      const bool hook = angle <= std::numbers::pi && uniformDraw(rng) < 0.5;
      spec.params = Vec3(angle, r, hook ? 0.5 + 2.0 * uniformDraw(rng) : 0.0);
      break;
    }
    case Family::kBeam: {
      // Heights by section: legs of an L and a U up to as tall as wide; T and H about square; I taller.
      static constexpr std::array<std::array<double, 2>, 5> kHeights = {
          {{0.4, 1.0}, {0.5, 1.2}, {0.4, 1.0}, {0.7, 1.1}, {1.3, 2.2}}};
      const auto section = index % 5;
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      const double h =
          kHeights[section][0] + (kHeights[section][1] - kHeights[section][0]) * uniformDraw(rng);
      const double t = std::min(logLerp(0.1, 0.3, u), section == 0 ? 0.6 * h : h / 3.5);
      spec.params = Vec3(t, logLerp(0.3, 4.0, v), h);
      break;
    }
    case Family::kHoled: {
      const double a = logLerp(0.3, 1.0, u);
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      spec.params = Vec3(a, std::min(a, logLerp(0.08, 0.5, v)), 1.0 + std::floor(6.0 * uniformDraw(rng)));
      break;
    }
    case Family::kShell: {
      const double h = logLerp(0.3, 2.0, u);
      const double w = std::clamp(logLerp(0.1, 0.3, v), 0.06 * std::max(1.0, h), 0.4 * h);
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      spec.params = Vec3(h, w, index % 4 == 3 ? 0.5 + 0.5 * uniformDraw(rng) : 0.0);
      break;
    }
    case Family::kLimbed: {
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      spec.params = Vec3(2.0 + std::floor(5.0 * uniformDraw(rng)), 0.5 + 1.3 * u, logLerp(0.09, 0.22, v));
      break;
    }
    case Family::kStone: {
      const double a = logLerp(0.45, 1.0, u), b = logLerp(0.3, 1.0, v);
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      spec.params = Vec3(std::max(a, b), std::min(a, b), 0.08 + 0.22 * uniformDraw(rng));
      break;
    }
    case Family::kUnion: {
      std::mt19937_64 rng = detail::entryStream(index, kSpecSalt);
      spec.params = Vec3(2.0 + std::floor(3.0 * uniformDraw(rng)), 0.0, 0.0);
      break;
    }
    case Family::kShard:
    case Family::kUser:
    case Family::kLearned:
      break;
  }
  return spec;
}

std::vector<ShapeSpec> buildCatalog(std::size_t entries, std::span<const Family> families,
                                    std::span<const unsigned> weights) {
  std::vector<ShapeSpec> catalog;
  if (families.empty()) return catalog;
  const auto weightOf = [&](std::size_t f) -> std::size_t { return weights.empty() ? 1 : weights[f]; };
  std::size_t total = 0;
  for (std::size_t f = 0; f < families.size(); ++f)
    total += weightOf(f);
  // Largest remainders: each family's whole share, then one more to the largest fractions (the share's
  // remainder over the total weight), the earlier family first among equals.
  std::vector<std::size_t> counts(families.size()), order(families.size());
  std::size_t given = 0;
  for (std::size_t f = 0; f < families.size(); ++f) {
    counts[f] = entries / total * weightOf(f) + entries % total * weightOf(f) / total;
    given += counts[f];
  }
  const auto fraction = [&](std::size_t f) { return entries % total * weightOf(f) % total; };
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return fraction(x) > fraction(y); });
  for (std::size_t k = 0; given < entries; ++k, ++given)
    ++counts[order[k]];
  catalog.reserve(entries);
  for (std::size_t f = 0; f < families.size(); ++f)
    for (std::size_t i = 0; i < counts[f]; ++i)
      catalog.push_back(familySpec(families[f], static_cast<std::uint32_t>(i)));
  return catalog;
}

Result<TriangleMesh> makeFamilyShape(const ShapeSpec& spec, const ShapeResolution& resolution) {
  const double a = spec.params.x(), b = spec.params.y();
  const int segments = std::max(3, resolution.segments), stacks = std::max(2, resolution.stacks);
  const auto unionTriangles =
      static_cast<std::size_t>(std::max(100, segments * resolution.unionTrianglesPerSegment));
  // Thin walls and limbs, which a correction bends into other shapes, keep the resolution of 16
  // segments at least (docs/accuracy.md: at 12, shells' median error passed 2 % and limbs' worst 5 %).
  constexpr int kThinSegments = 16;
  const int thinSegments = std::max(segments, kThinSegments);
  std::mt19937_64 rng = detail::entryStream(spec.index, kShapeSalt);
  switch (spec.family) {
    case Family::kBox:
      return core::makeBox(Vec3(1.0, a, b));
    case Family::kEllipsoid:
      return core::makeUvEllipsoid(Vec3(1.0, a, b), segments, stacks);
    case Family::kCylinder:  // radius 1 (x) by a (y), length 2c
      return scaled(core::makeCylinder(1.0, 2.0 * b, segments), Vec3(1.0, a, 1.0));
    case Family::kCone:
      return scaled(core::makeCone(1.0, 2.0 * b, segments), Vec3(1.0, a, 1.0));
    case Family::kCapsule:  // the whole length, caps included, is 2c: segment 2(c − 1) when c > 1
      return scaled(core::makeCapsule(1.0, std::max(0.0, 2.0 * (b - 1.0)), segments, std::max(1, stacks / 2)),
                    Vec3(1.0, a, std::min(1.0, b)));
    case Family::kPrism:
      return core::makeTriangularPrism(2.0, 2.0 * a, 2.0 * b);
    case Family::kShard:
      return makeShard(spec.index);
    case Family::kFragment:
      return makeFragment(spec);
    case Family::kRing:
      return detail::makeRingShape(a, b, segments);
    case Family::kRod:
      return detail::makeRodShape(a, b, spec.params.z(), segments);
    case Family::kBeam:
      return detail::makeBeamShape(static_cast<detail::BeamSection>(spec.index % 5), a, spec.params.z(), b);
    case Family::kStone:
      return detail::makeStoneShape(
          a, b, spec.params.z(),
          std::clamp(resolution.stoneSubdivisions, kMinStoneSubdivisions, kMaxStoneSubdivisions), rng);
    case Family::kHoled:
      return detail::makeHoledShape(a, b, static_cast<int>(spec.params.z()), 0.35 + 0.35 * uniformDraw(rng),
                                    segments);
    case Family::kShell:
      return detail::makeShellShape(static_cast<detail::ShellKind>(spec.index % 4), a, b, spec.params.z(),
                                    thinSegments);
    case Family::kLimbed:
      return detail::makeLimbedShape(static_cast<int>(a), b, spec.params.z(), rng,
                                     static_cast<std::size_t>(thinSegments * resolution.trianglesPerSegment));
    case Family::kUnion:
      return detail::makeUnionShape(static_cast<int>(a), rng, unionTriangles);
    case Family::kUser:
    case Family::kLearned:
      break;
  }
  return Error{ErrorCode::kInvalidArgument, "user and learned entries have no generator"};
}

}  // namespace shapedb::volume
