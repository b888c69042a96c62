#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>

#include <shapedb/core/primitives.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/families.h>

#include "polyhedron.h"

namespace shapedb::volume {
namespace {

using core::TriangleMesh;
using core::Vec3;
using detail::clip;
using detail::Polygon;
using detail::triangulate;

constexpr std::array kGenerated = {Family::kBox,     Family::kEllipsoid, Family::kCylinder, Family::kCone,
                                   Family::kCapsule, Family::kPrism,     Family::kShard};
constexpr double kMinRatio = 0.1;    ///< thinnest side over the largest
constexpr double kMaxLength = 10.0;  ///< longest axial length over the cross-section

/// Martin Roberts' R2 sequence: the plastic number's powers give the most even 2-D coverage of any
/// additive recurrence. Point i in [0, 1)².
std::array<double, 2> r2(std::uint32_t i) {
  constexpr double g = 1.32471795724474602596;
  const double n = static_cast<double>(i) + 1.0;
  return {std::fmod(0.5 + n / g, 1.0), std::fmod(0.5 + n / (g * g), 1.0)};
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
      Vec3 n(normal(rng), normal(rng), normal(rng));
      n.normalize();
      faces = clip(faces, n, 0.35 + 0.65 * unit(rng));
    }
    const Vec3 stretch(1.0, std::exp(std::log(0.2) * unit(rng)), std::exp(std::log(kMinRatio) * unit(rng)));
    TriangleMesh mesh = scaled(triangulate(faces), stretch);
    if (core::validateMesh(mesh).ok() && core::analyzeTopology(mesh).isClosed()) return mesh;
  }
}

}  // namespace

std::span<const Family> generatedFamilies() {
  return kGenerated;
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
    case Family::kUser:
      return "user";
  }
  return "?";
}

std::optional<Family> parseFamily(std::string_view name) {
  for (Family f : {Family::kBox, Family::kEllipsoid, Family::kCylinder, Family::kCone, Family::kCapsule,
                   Family::kPrism, Family::kShard, Family::kUser})
    if (name == toString(f)) return f;
  return std::nullopt;
}

Result<std::vector<Family>> parseFamilies(std::string_view list) {
  if (list == "all") return std::vector<Family>(kGenerated.begin(), kGenerated.end());
  std::vector<Family> families;
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    const std::string_view name = list.substr(0, comma);
    const std::optional<Family> f = parseFamily(name);
    if (!f || *f == Family::kUser)
      return Error{ErrorCode::kInvalidArgument,
                   "unknown family '" + std::string(name) +
                       "' (known: box, ellipsoid, cylinder, cone, capsule, prism, shard)"};
    if (std::find(families.begin(), families.end(), *f) != families.end())
      return Error{ErrorCode::kInvalidArgument, "family '" + std::string(name) + "' is listed twice"};
    families.push_back(*f);
    list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
  }
  if (families.empty()) return Error{ErrorCode::kInvalidArgument, "no family given"};
  return families;
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
    case Family::kShard:
    case Family::kUser:
      break;
  }
  return spec;
}

std::vector<ShapeSpec> buildCatalog(std::size_t entries, std::span<const Family> families) {
  std::vector<ShapeSpec> catalog;
  if (families.empty()) return catalog;
  catalog.reserve(entries);
  for (std::size_t f = 0; f < families.size(); ++f) {
    const std::size_t count = entries / families.size() + (f < entries % families.size() ? 1 : 0);
    for (std::size_t i = 0; i < count; ++i)
      catalog.push_back(familySpec(families[f], static_cast<std::uint32_t>(i)));
  }
  return catalog;
}

Result<TriangleMesh> makeFamilyShape(const ShapeSpec& spec, const ShapeResolution& resolution) {
  const double a = spec.params.x(), b = spec.params.y();
  const int segments = std::max(3, resolution.segments), stacks = std::max(2, resolution.stacks);
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
    case Family::kUser:
      break;
  }
  return Error{ErrorCode::kInvalidArgument, "user entries have no generator"};
}

}  // namespace shapedb::volume
