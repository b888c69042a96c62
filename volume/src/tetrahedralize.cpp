// What tetrahedralize asks TetGen and how it checks the answer; the process that runs TetGen is
// tetgen_worker.cpp's.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/tetrahedralize.h>

#include "tetgen_worker.h"

namespace shapedb::volume {

using core::TetMesh;
using core::TriangleMesh;

std::string tetgenSwitches(const TetrahedralizeOptions& options, double volume, bool mergeFacets) {
  // p: the input is a piecewise linear complex; q: quality bound; a: volume bound; M: no merging of
  // coplanar facets; Q: quiet; z: number from zero.
  char buffer[96];
  std::string switches = "p";
  if (options.maxRadiusEdgeRatio > 0.0) {
    std::snprintf(buffer, sizeof buffer, "q%.3g", options.maxRadiusEdgeRatio);
    switches += buffer;
  }
  if (options.maxVolumeFraction > 0.0) {
    std::snprintf(buffer, sizeof buffer, "a%.6g", options.maxVolumeFraction * volume);
    switches += buffer;
  }
  return switches + (mergeFacets ? "Qz" : "MQz");
}

std::vector<double> wallVolumeBounds(const TriangleMesh& surface, const TetrahedralizeOptions& options,
                                     double volume) {
  if (!(options.wallEdgeFraction > 0.0 && options.maxVolumeFraction > 0.0)) return {};
  // Edges of regular tets: of volume V, a = ∛(6√2 V); of edge a, V = a³ / (6√2).
  const double largest = std::cbrt(6.0 * std::sqrt(2.0) * options.maxVolumeFraction * volume);
  const std::vector<double> thickness = core::wallThickness(surface);
  std::vector<double> bounds(surface.triangles.size(), std::numeric_limits<double>::infinity());
  bool thin = false;
  for (std::size_t t = 0; t < bounds.size(); ++t) {
    const TriangleMesh::Triangle& tri = surface.triangles[t];
    // The thinnest at its corners: a plate's rim gets its faces' thickness, not its width.
    const double edge =
        options.wallEdgeFraction * std::min({thickness[tri[0]], thickness[tri[1]], thickness[tri[2]]});
    if (!(edge < largest)) continue;  // thick enough for the volume bound's tets (or +∞)
    const double bounded = std::max(edge, largest / 3.0);
    bounds[t] = bounded * bounded * bounded / (6.0 * std::sqrt(2.0));
    thin = true;
  }
  if (!thin) bounds.clear();
  return bounds;
}

namespace {

/// A face whose corner across its longest edge lies within this much of the edge's length from its line
/// is a cap, which tetrahedralize flips away when TetGen's tets of the surface as given fall apart.
constexpr double kCapHeight = 1e-4;
/// ... and only if the flips change the volume by at most this much of it.
constexpr double kCapVolume = 1e-6;

/// Names the first crossing of a surface that TetGen could not mesh, and what TetGen did.
std::string selfIntersectionMessage(const std::vector<core::TriangleCrossing>& crossings,
                                    const Error& tetgen) {
  const core::TriangleCrossing& first = crossings.front();
  char where[160];
  std::snprintf(where, sizeof where, "triangles %u and %u cross at (%.6g, %.6g, %.6g)", first.first,
                first.second, first.point.x(), first.point.y(), first.point.z());
  const std::string pairs = crossings.size() == 1
                                ? std::string(where)
                                : std::to_string(crossings.size()) + " pairs of triangles cross; " + where;
  return "the surface passes through itself (" + pairs +
         "), so it bounds no solid to mesh: " + tetgen.message;
}

/// Whether `mesh` fills the surface whose mass properties are `mass`: the same volume and centroid to
/// 1e-9 (relative), as tets whose boundary lies on the surface's faces do.
Status fillsSurface(const TetMesh& mesh, const core::MassProperties& mass) {
  const double volume = mass.volume;
  const core::MassProperties filled = core::computeTetMassProperties(mesh);
  if (std::abs(filled.volume - volume) > 1e-9 * volume ||
      (filled.centerOfMass - mass.centerOfMass).norm() > 1e-9 * std::cbrt(volume)) {
    return Error{ErrorCode::kParse, "TetGen moved the surface: its tets hold " +
                                        std::to_string(filled.volume / volume) + " of the volume"};
  }
  return Ok{};
}

/// The surface's closed shells sorted by what they bound (core::Shell::cavity): the solids, and a point in
/// each cavity.
struct Shells {
  std::size_t solids = 0;
  /// A point inside each cavity, for TetGen's hole list: TetGen fills a cavity with tets as it fills the
  /// solid around it (it removes only what lies outside the outer shell), and removes those of a region
  /// given a point in it. The point: from the centroid of the cavity's largest triangle, along the
  /// triangle's normal (into the void), halfway to the next triangle the ray meets.
  std::vector<core::Vec3> holes;
};

Result<Shells> shellsToMesh(const TriangleMesh& surface) {
  Shells out;
  const std::vector<core::Shell> shells = core::findShells(surface);
  out.solids = core::countShells(shells).solids;
  std::optional<core::ClosestPointTree> tree;
  for (const core::Shell& shell : shells) {
    if (!shell.cavity) continue;
    std::uint32_t largest = shell.triangles.front();
    double largestArea = -1.0;
    core::Vec3 normal = core::Vec3::Zero();
    for (std::uint32_t t : shell.triangles) {
      const TriangleMesh::Triangle& tri = surface.triangles[t];
      const core::Vec3 n = (surface.vertices[tri[1]] - surface.vertices[tri[0]])
                               .cross(surface.vertices[tri[2]] - surface.vertices[tri[0]]);
      if (n.norm() > largestArea) {
        largestArea = n.norm();
        largest = t;
        normal = n;
      }
    }
    const TriangleMesh::Triangle& tri = surface.triangles[largest];
    const core::Vec3 centroid =
        (surface.vertices[tri[0]] + surface.vertices[tri[1]] + surface.vertices[tri[2]]) / 3.0;
    if (!tree) tree.emplace(surface);
    // Its normal points into the void where it is wound inward (negative volume: the surface outward).
    const core::Vec3 into = (shell.volume < 0.0 ? 1.0 : -1.0) * normal.normalized();
    const std::optional<core::RayHit> hit = tree->firstHit(centroid, into, 0.0, largest);
    if (!(largestArea > 0.0) || !hit || !(hit->distance > 0.0))
      return Error{ErrorCode::kParse, "a cavity of the solid (a closed shell wound inward, " +
                                          std::to_string(shell.triangles.size()) +
                                          " triangles) has no inside to find: is it flat?"};
    out.holes.push_back(centroid + 0.5 * hit->distance * into);
  }
  return out;
}

/// One TetGen run with these switches, its output checked and turned positive, and checked to fill the
/// surface: same volume and centroid to 1e-9 (relative).
Result<TetMesh> tetrahedralizeOnce(const TriangleMesh& surface, const std::vector<double>& wallBounds,
                                   const std::vector<core::Vec3>& holes, const TetrahedralizeOptions& options,
                                   const core::MassProperties& mass, bool mergeFacets) {
  const double volume = mass.volume;
  const std::string switches = tetgenSwitches(options, volume, mergeFacets);
  detail::TetGenOutput raw;
  if (options.guarded) {
    auto guarded = detail::runTetGenGuarded(surface, wallBounds, holes, switches, options.timeoutSeconds);
    if (!guarded) return guarded.error();
    raw = std::move(guarded).value();
  } else {
    raw = detail::runTetGen(surface, wallBounds, holes, switches);
  }
  if (raw.status != 0) return Error{ErrorCode::kParse, detail::describeTetGenError(raw.status)};

  TetMesh mesh;
  mesh.nodes.resize(raw.nodes.size() / 3);
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    mesh.nodes[i] = core::Vec3(raw.nodes[3 * i], raw.nodes[3 * i + 1], raw.nodes[3 * i + 2]);
  mesh.tets.resize(raw.tets.size() / 4);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int32_t v = raw.tets[4 * t + k];
      if (v < 0 || static_cast<std::size_t>(v) >= mesh.nodes.size())
        return Error{ErrorCode::kParse, "TetGen returned a tet with an invalid node"};
      mesh.tets[t][k] = static_cast<std::uint32_t>(v);
    }
    // TetGen orients tets negatively in our convention (its manual's right-hand rule); make them positive.
    if (core::tetVolume(mesh, t) < 0.0) std::swap(mesh.tets[t][2], mesh.tets[t][3]);
  }
  dropFlatTets(mesh);
  if (Status valid = core::validateTetMesh(mesh); !valid)
    return Error{ErrorCode::kParse, "TetGen returned an invalid mesh: " + valid.error().message};
  // Flat tets dropped between nearly coplanar facets can leave tets held by an edge or a node alone: a
  // mechanism, which would ring at a near-zero frequency (a plate fragment did, at 1 kHz instead of 17).
  // Refused here, so that the runs below try again without merging facets and with looser bounds.
  if (const std::size_t pieces = core::faceConnectedPieces(mesh); pieces > 1)
    return Error{ErrorCode::kParse, "TetGen's tets make " + std::to_string(pieces) +
                                        " pieces joined only at edges or nodes once its flat tets are "
                                        "dropped (a mechanism, which would ring at a near-zero frequency)"};
  if (Status fills = fillsSurface(mesh, mass); !fills) return fills.error();
  return mesh;
}

}  // namespace

Result<TetMesh> tetrahedralize(const TriangleMesh& surface, const TetrahedralizeOptions& options) {
  if (!((options.maxRadiusEdgeRatio >= 1.1 || options.maxRadiusEdgeRatio == 0.0) &&
        std::isfinite(options.maxRadiusEdgeRatio)))
    return Error{ErrorCode::kInvalidArgument, "TetGen radius-edge ratio must be at least 1.1 (or 0: none)"};
  if (!(options.maxVolumeFraction >= 0.0 && options.maxVolumeFraction <= 1.0))
    return Error{ErrorCode::kInvalidArgument, "TetGen volume fraction must be in [0, 1]"};
  if (!(options.wallEdgeFraction >= 0.0 && std::isfinite(options.wallEdgeFraction)))
    return Error{ErrorCode::kInvalidArgument, "the wall edge fraction must be finite and ≥ 0 (0: none)"};
  if (Status valid = core::validateMesh(surface); !valid) return valid.error();
  auto mass = core::computeMassProperties(surface);
  if (!mass) return mass.error();
  // Per triangle: the same for every run below, the turned surface's included (its triangles are these,
  // and its volume bounds the same), and the capless one's (its flipped faces lie where these did).
  const std::vector<double> wallBounds = wallVolumeBounds(surface, options, mass->volume);
  auto shells = shellsToMesh(surface);
  if (!shells) return shells.error();

  // TetGen merges adjacent facets it finds nearly coplanar, which moves a surface whose facets are only
  // nearly so (a simplified level-set mesh: the volume changed by 1e-6), or aborts on it. Such a run is
  // repeated without merging ('M'); not always: TetGen 1.5 aborts with 'M' on some exactly coplanar
  // input (a box).
  // One run. A guarded run whose worker died or hung (rather than TetGen answering) is repeated once in a
  // fresh worker, so that a broken worker never changes the mesh. (Under ASan on a loaded machine a
  // worker hung until its timeout now and then; the unmerged run that followed gave another mesh, and a
  // resumed database differed from a clean one.)
  auto once = [&wallBounds](const TriangleMesh& input, const std::vector<core::Vec3>& holes,
                            const core::MassProperties& inputMass, const TetrahedralizeOptions& o,
                            bool mergeFacets) {
    Result<TetMesh> result = tetrahedralizeOnce(input, wallBounds, holes, o, inputMass, mergeFacets);
    if (!result && result.error().code == ErrorCode::kIo && o.guarded && o.relaxOnFailure)
      result = tetrahedralizeOnce(input, wallBounds, holes, o, inputMass, mergeFacets);
    return result;
  };
  auto attemptOn = [&](const TriangleMesh& input, const std::vector<core::Vec3>& holes,
                       const core::MassProperties& inputMass, const TetrahedralizeOptions& o) {
    Result<TetMesh> result = once(input, holes, inputMass, o, /*mergeFacets=*/true);
    if (!result) {
      Result<TetMesh> unmerged = once(input, holes, inputMass, o, /*mergeFacets=*/false);
      if (unmerged) return unmerged;
      // Both said why: the merged run often only that merging moved the surface, the unmerged one what is
      // wrong with the tets themselves (pieces that meet only at edges once the flat ones are dropped).
      if (unmerged.error().message != result.error().message)
        return Result<TetMesh>(
            Error{unmerged.error().code,
                  result.error().message + "; without merging facets: " + unmerged.error().message});
    }
    return result;
  };
  auto attempt = [&](const TetrahedralizeOptions& o) { return attemptOn(surface, shells->holes, *mass, o); };
  Result<TetMesh> tets = attempt(options);
  if (tets) return tets;
  // A surface that passes through itself bounds no solid: TetGen refuses it or crashes on it (a scanned
  // horse did, at every bound), so the runs below would fail as well. Looked for only now, so that a
  // surface TetGen meshes costs nothing more.
  if (const std::vector<core::TriangleCrossing> crossings = core::findSelfIntersections(surface);
      !crossings.empty())
    return Error{ErrorCode::kSelfIntersecting, selfIntersectionMessage(crossings, tets.error())};
  // Several solids (closed shells wound outward, none crossing another) are meshed, and refused as
  // pieces: said as what they are. Looked for only now, after the crossings, since shells that cross
  // (two overlapping boxes) count as two as well.
  if (shells->solids > 1)
    return Error{ErrorCode::kParse,
                 "the surface bounds " + std::to_string(shells->solids) +
                     " separate solids (closed shells, none a cavity of another): a tet mesh is of one "
                     "solid, so give each its own mesh, or, where they are parts that touch, --repair joins "
                     "them into one"};
  if (!options.relaxOnFailure) return tets;
  // The fallbacks below, for a surface as given and for one with its caps flipped.
  // `out`: the error to give if none of them meshes `input` (a looser run's replaces it).
  const auto relaxed = [&](const TriangleMesh& input, const core::MassProperties& inputMass,
                           Result<TetMesh> out) -> Result<TetMesh> {
    // TetGen's quality refinement can abort, hang or return a flat tet near sharp input angles (a slender
    // cone's tip did, 4 times in the 4,500-entry catalog): a looser bound, then none.
    for (double looseness : {2.5, 0.0}) {
      if (options.maxRadiusEdgeRatio == 0.0 || (looseness > 0.0 && options.maxRadiusEdgeRatio >= looseness))
        continue;
      TetrahedralizeOptions looser = options;
      looser.maxRadiusEdgeRatio = looseness;
      looser.timeoutSeconds = std::min(looser.timeoutSeconds, 10.0);
      out = attemptOn(input, shells->holes, inputMass, looser);
      if (out) return out;
    }
    // TetGen 1.5.0 asserts in its point location ("finddirection: nonconvex") on some surfaces whose
    // vertices are symmetric about the coordinate planes: two uv-ellipsoids of 12 segments and 6 stacks in
    // the default catalog did, at every bound. The same surface turned by a generic rotation meshes; its
    // nodes are turned back and the surface's own vertices (TetGen keeps them first, in order) restored
    // exactly, so that the tets fill the surface as any run's do.
    const core::Mat3 turn =
        Eigen::AngleAxisd(0.37, core::Vec3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
    TriangleMesh turned = input;
    for (core::Vec3& v : turned.vertices)
      v = turn * v;
    const auto turnedMass = core::computeMassProperties(turned);
    if (!turnedMass) return out;
    std::vector<core::Vec3> turnedHoles = shells->holes;
    for (core::Vec3& h : turnedHoles)
      h = turn * h;
    Result<TetMesh> turnedTets = attemptOn(turned, turnedHoles, *turnedMass, options);
    if (!turnedTets) return out;
    TetMesh back = std::move(turnedTets).value();
    if (back.nodes.size() < input.vertices.size()) return out;
    const double tolerance = 1e-9 * std::cbrt(inputMass.volume);
    for (std::size_t i = 0; i < back.nodes.size(); ++i) {
      const core::Vec3 node = turn.transpose() * back.nodes[i];
      if (i >= input.vertices.size()) {
        back.nodes[i] = node;
      } else if ((node - input.vertices[i]).norm() <= tolerance) {
        back.nodes[i] = input.vertices[i];
      } else {
        return out;  // not the surface's vertex: TetGen numbered them otherwise
      }
    }
    if (!core::validateTetMesh(back) || !fillsSurface(back, inputMass)) return out;  // flat, inverted, moved
    return back;
  };
  tets = relaxed(surface, *mass, std::move(tets));
  if (tets) return tets;
  // A cap, a face whose corner lies a hair off the line of its longest edge (a CAD part's tessellation
  // had three, their corners 5e-6 to 2e-5 of their edges' lengths off them), makes TetGen's refinement run
  // away around it, down to tets a millionth of the solid's size, which dropFlatTets takes for flat: the tets
  // fall apart into pieces. The surface with its caps flipped away (kCapHeight; the vertices stay, the
  // surface moves by less than that) is meshed instead, if its volume is the surface's within kCapVolume.
  TriangleMesh capless = surface;
  if (core::flipThinFaces(capless, kCapHeight) == 0) return tets;
  const auto caplessMass = core::computeMassProperties(capless);
  if (!caplessMass || !(std::abs(caplessMass->volume / mass->volume - 1.0) <= kCapVolume)) return tets;
  Result<TetMesh> flipped = attemptOn(capless, shells->holes, *caplessMass, options);
  if (!flipped) flipped = relaxed(capless, *caplessMass, std::move(flipped));
  return flipped ? std::move(flipped) : std::move(tets);
}

// A surface whose faces are only nearly coplanar (a level-set mesh: float coordinates) leaves wedges of
// 1e-18 of the volume between them, which TetGen fills with flat tets; their stiffness would be garbage,
// and their volume is below the fill check's tolerance by nine orders of magnitude.
void dropFlatTets(TetMesh& mesh) {
  const double minVolume = core::flatTetVolume(mesh);
  std::size_t keptTets = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (core::tetVolume(mesh, t) > minVolume) mesh.tets[keptTets++] = mesh.tets[t];
  mesh.tets.resize(keptTets);
  std::vector<std::int64_t> renumber(mesh.nodes.size(), -1);
  for (const TetMesh::Tet& t : mesh.tets)
    for (std::uint32_t v : t)
      renumber[v] = 0;
  std::size_t kept = 0;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    if (renumber[v] == 0) {
      mesh.nodes[kept] = mesh.nodes[v];
      renumber[v] = static_cast<std::int64_t>(kept++);
    }
  mesh.nodes.resize(kept);
  for (TetMesh::Tet& t : mesh.tets)
    for (std::uint32_t& v : t)
      v = static_cast<std::uint32_t>(renumber[v]);
}

}  // namespace shapedb::volume
