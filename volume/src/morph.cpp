#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/spatial.h>
#include <shapedb/volume/morph.h>

#include "kept_for_tets.h"
#include "mesh_motion.h"
#include "sparse_cholesky.h"

namespace shapedb::volume {
namespace {

using core::TetMesh;
using core::Vec3;
using detail::SparseMatrix;

/// The boundary of a tet mesh as morphing sees it: which nodes lie on it, their neighbours along boundary
/// edges, and the faces (for normals).
struct Boundary {
  std::vector<std::uint32_t> nodes;  ///< boundary nodes, ascending
  std::vector<int> slot;             ///< per mesh node: its index in `nodes`, or -1 inside
  std::vector<std::uint32_t> start;  ///< CSR over `nodes`: neighbours' slots
  std::vector<std::uint32_t> neighbours;
  std::vector<std::array<std::uint32_t, 3>> faces;  ///< slots, wound outward
};

Boundary findBoundary(const TetMesh& mesh) {
  Boundary b;
  b.slot.assign(mesh.nodeCount(), -1);
  const std::vector<core::BoundaryFace> faces = core::boundaryFaces(mesh);
  for (const core::BoundaryFace& f : faces)
    for (std::uint32_t n : f.nodes)
      b.slot[n] = 0;
  for (std::uint32_t n = 0; n < mesh.nodeCount(); ++n)
    if (b.slot[n] == 0) {
      b.slot[n] = static_cast<int>(b.nodes.size());
      b.nodes.push_back(n);
    }
  std::vector<std::uint64_t> edges;
  for (const core::BoundaryFace& f : faces) {
    std::array<std::uint32_t, 3> s{};
    for (std::size_t i = 0; i < 3; ++i)
      s[i] = static_cast<std::uint32_t>(b.slot[f.nodes[i]]);
    b.faces.push_back(s);
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t p = s[i], q = s[(i + 1) % 3];
      edges.push_back((static_cast<std::uint64_t>(p) << 32) | q);
      edges.push_back((static_cast<std::uint64_t>(q) << 32) | p);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  b.start.assign(b.nodes.size() + 1, 0);
  for (std::uint64_t e : edges) {
    ++b.start[(e >> 32) + 1];
    b.neighbours.push_back(static_cast<std::uint32_t>(e & 0xffffffffu));
  }
  for (std::size_t i = 0; i < b.nodes.size(); ++i)
    b.start[i + 1] += b.start[i];
  return b;
}

/// ∫ (x − c)(x − c)ᵀ dV at unit density, from the inertia about the centre of mass.
core::Mat3 covariance(const core::MassProperties& m) {
  return core::covarianceFromInertia(m.inertia / m.density);
}

double worstQuality(const TetMesh& mesh) {
  double worst = 1.0;
  for (std::size_t t = 0; t < mesh.tetCount(); ++t)
    worst = std::min(worst, tetQuality(mesh, t));
  return worst;
}

/// Per boundary node, a third of the area of its boundary faces at positions `nodes`.
std::vector<double> boundaryAreas(const Boundary& boundary, const TetMesh& mesh) {
  std::vector<double> area(boundary.nodes.size(), 0.0);
  for (const auto& f : boundary.faces) {
    const Vec3 &a = mesh.nodes[boundary.nodes[f[0]]], &b = mesh.nodes[boundary.nodes[f[1]]],
               &c = mesh.nodes[boundary.nodes[f[2]]];
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (std::uint32_t s : f)
      area[s] += third;
  }
  return area;
}

/// Elastic registration (the non-rigid ICP of Amberg et al. 2007, on a tet mesh): rounds of correspondences
/// both ways, then the total displacement U that minimizes Uᵀ K U + w Σ (fit terms), K the mesh-motion
/// stiffness of the start configuration, w growing round by round. A round whose displacement would push a
/// tet under `minQuality` is taken in part (halved up to three times) or not at all. `nearest` holds, per
/// boundary node, the target triangle its closest point was last found on (MorphTarget::kNoHint before
/// the first search): each search starts from it, as a node moves little from round to round. `analysis` is
/// the symbolic analysis of K's sparsity (MorphLayout's); without one there is no registration.
void registerElastically(TetMesh& mesh, const Boundary& boundary, const MorphTarget::View& target, int rounds,
                         double minQuality, const detail::MotionStiffness& stiffness,
                         const detail::SymbolicFactor* analysis, std::vector<std::uint32_t>& nearest) {
  if (rounds <= 0) return;
  const TetMesh start = mesh;
  SparseMatrix k = stiffness.matrix();
  stiffness.assemble(start, k);
  const auto n = static_cast<Eigen::Index>(3 * mesh.nodeCount());
  const std::vector<double> nodeArea = boundaryAreas(boundary, start);
  // The target's side: up to 2,000 of its samples, each with its share of the target's area.
  const std::vector<double>& sampleArea = target.target().sampleAreas();
  const std::size_t stride = std::max<std::size_t>(1, target.sampleCount() / 2000);
  double stiffnessScale = 0.0, fitScale = 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
    stiffnessScale += k.coeff(i, i);
  for (double a : nodeArea)
    fitScale += 3.0 * a;
  // CHOLMOD's factor, on the layout's analysis (a node-block order worked out once): K's sparsity holds
  // the fit's.
  detail::SparseCholesky solver;
  Eigen::VectorXd total = Eigen::VectorXd::Zero(n);
  SparseMatrix a = k;
  // Per target point, the boundary face its closest point was last found on: the faces keep their
  // numbering from round to round.
  std::vector<std::uint32_t> onBoundary((target.sampleCount() + stride - 1) / stride, MorphTarget::kNoHint);
  for (int round = 0; round < rounds; ++round) {
    // From stiff (the fit moves the body nearly as a whole) to close: w from 0.1 to 100 times the
    // stiffness, in equal ratios.
    const double ratio = rounds == 1 ? 1.0 : std::pow(1000.0, static_cast<double>(round) / (rounds - 1));
    const double w = 0.1 * ratio * stiffnessScale / fitScale;
    // A = K + the fit terms, which couple only nodes of one boundary face: within K's sparsity (so A is
    // laid out once, and each round starts from K's values).
    std::copy_n(k.valuePtr(), k.nonZeros(), a.valuePtr());
    double* values = a.valuePtr();
    bool inPattern = true;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    const auto addPoint = [&](std::span<const std::uint32_t> nodes, std::span<const double> weights,
                              const Vec3& goal, double weight) {
      // weight · |Σ βᵢ (xᵢ + Uᵢ) − goal|², with x the start configuration.
      Vec3 at = Vec3::Zero();
      for (std::size_t i = 0; i < nodes.size(); ++i)
        at += weights[i] * start.nodes[nodes[i]];
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (std::size_t j = 0; j < nodes.size(); ++j) {
          const std::array<Eigen::Index, 3> slots = stiffness.diagonalIndices(nodes[i], nodes[j]);
          inPattern = inPattern && slots[0] >= 0;
          if (slots[0] >= 0)
            for (Eigen::Index index : slots)
              values[index] += weight * weights[i] * weights[j];
        }
        rhs.segment<3>(3 * static_cast<Eigen::Index>(nodes[i])) += weight * weights[i] * (goal - at);
      }
    };
    // Boundary nodes to their closest target points.
    for (std::size_t b = 0; b < boundary.nodes.size(); ++b) {
      const std::uint32_t node = boundary.nodes[b];
      const double one = 1.0;
      // Before the first search, the previous node's triangle: nodes numbered near are mostly near.
      if (nearest[b] == MorphTarget::kNoHint && b > 0) nearest[b] = nearest[b - 1];
      addPoint({&node, 1}, {&one, 1}, target.closestPoint(mesh.nodes[node], nearest[b]), w * nodeArea[b]);
    }
    // Target points to their closest boundary points (a face of the current boundary, by barycentric
    // weights).
    const core::TriangleMesh current = [&] {
      core::TriangleMesh surface;
      surface.vertices = mesh.nodes;
      for (const auto& f : boundary.faces)
        surface.triangles.push_back({boundary.nodes[f[0]], boundary.nodes[f[1]], boundary.nodes[f[2]]});
      return surface;
    }();
    const core::ClosestPointTree currentTree(current);
    for (std::size_t v = 0, i = 0; v < target.sampleCount(); v += stride, ++i) {
      const Vec3 point = target.sample(v);
      if (onBoundary[i] == MorphTarget::kNoHint && i > 0) onBoundary[i] = onBoundary[i - 1];
      const core::ClosestPointTree::Hit hit = currentTree.closest(point, onBoundary[i]);
      onBoundary[i] = hit.triangle;
      const auto& t = current.triangles[hit.triangle];
      addPoint(t, hit.closest.barycentric, point, w * sampleArea[v] * static_cast<double>(stride));
    }
    if (!inPattern) break;  // cannot be: two nodes of a boundary face share its tet
    // Every round's A has K's sparsity: the first round's analysis serves them all.
    if (!(round > 0 ? solver.refactorize(a) : analysis && solver.factorize(a, *analysis))) break;
    // The fit terms hold the start configuration's rigid motions, so the system is definite.
    Eigen::VectorXd next(n);
    if (!solver.solve(rhs.data(), next.data())) break;
    // Take the round's step, or as much of it as keeps every tet above the bound.
    bool taken = false;
    for (double t = 1.0; t >= 0.125 && !taken; t *= 0.5) {
      const Eigen::VectorXd u = total + t * (next - total);
      TetMesh moved = start;
      for (std::size_t v = 0; v < moved.nodeCount(); ++v)
        moved.nodes[v] += u.segment<3>(3 * static_cast<Eigen::Index>(v));
      if (worstQuality(moved) >= minQuality) {
        mesh = std::move(moved);
        total = u;
        taken = true;
      }
    }
    if (!taken) break;
  }
}

}  // namespace

namespace detail {

/// Per node of a mesh of `nodeCount` nodes, whether it is one of `boundary`'s.
std::vector<char> boundaryMask(const Boundary& boundary, std::size_t nodeCount) {
  std::vector<char> mask(nodeCount, 0);
  for (std::uint32_t node : boundary.nodes)
    mask[node] = 1;
  return mask;
}

/// What morphTetMesh works out from the tets' connectivity alone (MorphPlan): immutable once made, shared by
/// the morphs of those tets.
struct MorphLayout {
  explicit MorphLayout(const TetMesh& mesh)
      : boundary(findBoundary(mesh)),
        motion(
            std::make_shared<const InteriorMotion::Layout>(mesh, boundaryMask(boundary, mesh.nodeCount()))) {
    // The registration's system has K's sparsity (the fit couples nodes of one boundary face only).
    const SparseMatrix pattern = motion->stiffness.matrix();
    registration = SparseCholesky::analyze(pattern, nodeBlockOrder(pattern));
  }
  Boundary boundary;
  std::shared_ptr<const InteriorMotion::Layout> motion;  ///< the interior's, shared by the morphs
  /// The analysis of the registration's system; null where it failed (out of memory), and with it the
  /// registration.
  std::shared_ptr<const SymbolicFactor> registration;
};

/// A MorphPlan's layout, kept for the tets it is of.
struct MorphPlanState : KeptForTets<MorphLayout> {};

}  // namespace detail

MorphPlan::MorphPlan() : mState(std::make_unique<detail::MorphPlanState>()) {}
MorphPlan::~MorphPlan() = default;
bool MorphPlan::ready() const {
  return mState->ready();
}

double tetQuality(const TetMesh& mesh, std::size_t t) {
  const auto& tet = mesh.tets[t];
  double edges = 0.0;
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = i + 1; j < 4; ++j)
      edges += (mesh.nodes[tet[i]] - mesh.nodes[tet[j]]).squaredNorm();
  const double volume = core::tetVolume(mesh, t);
  const double q = 12.0 * std::cbrt(9.0 * volume * volume) / edges;
  return volume < 0.0 ? -q : q;
}

Result<MorphTarget> MorphTarget::prepare(core::TriangleMesh surface) {
  if (Status valid = core::validateMesh(surface); !valid)
    return Error{ErrorCode::kInvalidArgument,
                 "morph: the target surface is not valid: " + valid.error().message};
  MorphTarget out;
  if (auto mass = core::computeMassProperties(surface)) {
    out.mMass = *mass;
    out.mSide = core::SurfaceSide(surface);
  } else {
    out.mTree = core::ClosestPointTree(surface);
  }
  out.mSamples = surface.vertices;
  out.mSampleAreas = core::vertexAreaWeights(surface);
  double total = 0.0;
  for (const double a : out.mSampleAreas)
    total += a;
  const double largest = total / kSampledArea;
  for (const core::TriangleMesh::Triangle& t : surface.triangles) {
    const Vec3 &a = surface.vertices[t[0]], &b = surface.vertices[t[1]], &c = surface.vertices[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (!(area > largest)) continue;
    // n² small triangles of area ≤ largest; a point's share is a third of its small triangles' area: one
    // at a corner, three along an edge, six inside.
    const int n = static_cast<int>(std::ceil(std::sqrt(area / largest)));
    const double third = area / (3.0 * n * n);
    for (const std::uint32_t corner : t)
      out.mSampleAreas[corner] -= area / 3.0 - third;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const int onEdges = (i == 0) + (j == 0) + (i + j == n);
        if (onEdges == 2) continue;  // a corner: the vertex itself
        out.mSamples.push_back(a + (static_cast<double>(i) / n) * (b - a) +
                               (static_cast<double>(j) / n) * (c - a));
        out.mSampleAreas.push_back((onEdges == 1 ? 3.0 : 6.0) * third);
      }
  }
  out.mSurface = std::move(surface);
  return out;
}

Vec3 MorphTarget::View::closestPoint(const Vec3& p) const {
  std::uint32_t none = kNoHint;
  return closestPoint(p, none);
}

Vec3 MorphTarget::View::closestPoint(const Vec3& p, std::uint32_t& near) const {
  const core::ClosestPointTree::Hit hit = mTarget->tree().closest(mFrame.transpose() * p, near);
  near = hit.triangle;
  return mFrame * hit.closest.point;
}

core::Mat3 MorphTarget::View::covariance() const {
  return mFrame * volume::covariance(*mTarget->mMass) * mFrame.transpose();
}

Result<MorphResult> morphTetMesh(const TetMesh& mesh, const core::TriangleMesh& target,
                                 const MorphOptions& options) {
  auto prepared = MorphTarget::prepare(target);
  if (!prepared) return prepared.error();
  return morphTetMesh(mesh, prepared->view(), options);
}

Result<MorphResult> morphTetMesh(const TetMesh& mesh, const MorphTarget::View& target,
                                 const MorphOptions& options) {
  if (Status valid = core::validateTetMesh(mesh); !valid)
    return Error{ErrorCode::kInvalidArgument, "morph: the tet mesh is not valid: " + valid.error().message};
  if (options.registrationRounds < 0 || options.maxIncrements < 1 ||
      !(options.minQuality > 0.0 && options.minQuality < 1.0))
    return Error{ErrorCode::kInvalidArgument,
                 "morph: registrationRounds ≥ 0, maxIncrements ≥ 1 and minQuality in (0, 1)"};

  MorphResult out;
  out.mesh = mesh;
  out.report.entryWorstQuality = worstQuality(mesh);
  // An entry that has worse tets than the bound may keep them: the bound is then half its worst.
  const double minQuality = std::min(options.minQuality, 0.5 * out.report.entryWorstQuality);

  // The affine part first: the stretch that gives the tets the target's second moments along x, y, z.
  if (options.prestretch) {
    if (target.target().massProperties()) {
      const core::MassProperties own = core::computeTetMassProperties(mesh);
      const Vec3 a = (target.covariance().diagonal().array() / covariance(own).diagonal().array()).sqrt();
      if (a.allFinite() && (a.array() > 0.0).all()) {
        out.report.stretch = a;
        for (Vec3& p : out.mesh.nodes)
          p = own.centerOfMass + a.cwiseProduct(p - own.centerOfMass);
      }
    }
  }

  // Elastic registration, then every boundary node onto its closest target point. The boundary and the
  // systems' layouts are the plan's where it has them for these tets.
  std::shared_ptr<const detail::MorphLayout> layout =
      options.plan ? options.plan->mState->find(mesh) : nullptr;
  if (!layout) {
    layout = std::make_shared<const detail::MorphLayout>(mesh);
    if (options.plan) options.plan->mState->keep(mesh, layout);
  }
  const Boundary& boundary = layout->boundary;
  detail::InteriorMotion motion(layout->motion);
  std::vector<std::uint32_t> nearest(boundary.nodes.size(), MorphTarget::kNoHint);
  registerElastically(out.mesh, boundary, target, options.registrationRounds, minQuality, motion.stiffness(),
                      layout->registration.get(), nearest);
  std::vector<Vec3> p(boundary.nodes.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (nearest[i] == MorphTarget::kNoHint && i > 0) nearest[i] = nearest[i - 1];
    p[i] = target.closestPoint(out.mesh.nodes[boundary.nodes[i]], nearest[i]);
  }
  Eigen::VectorXd move(3 * static_cast<Eigen::Index>(p.size()));
  for (std::size_t i = 0; i < p.size(); ++i)
    move.segment<3>(3 * static_cast<Eigen::Index>(i)) = p[i] - out.mesh.nodes[boundary.nodes[i]];

  // The interior follows, in as few increments as keep every tet above the quality bound. Where even the
  // finest increments would not (nodes the projection crowds onto a sharp edge of the target, or the four
  // boundary nodes of a tet flattened onto one face), the boundary nodes of the tets that fell under the
  // bound and of their neighbours take half their projection, round by round (½, ¼, ⅛, then none): the rest
  // of the boundary still goes all the way onto the target.
  const TetMesh start = out.mesh;
  const double reached = worstQuality(start);
  std::vector<double> taken(boundary.nodes.size(), 1.0);
  const std::array<int, 2> incrementSteps{1, options.maxIncrements};
  bool done = false;
  const detail::NodeNeighbours& neighbours = motion.stiffness().neighbours();
  constexpr int kRounds = 8;
  for (int round = 0; round < kRounds && !done; ++round) {
    const bool last = round == kRounds - 1;
    if (last) std::fill(taken.begin(), taken.end(), 0.0);
    Eigen::VectorXd step = move;
    for (std::size_t i = 0; i < taken.size(); ++i)
      step.segment<3>(3 * static_cast<Eigen::Index>(i)) *= taken[i];
    std::vector<std::size_t> bad;
    for (const int increments : incrementSteps) {
      // Every attempt's first increment starts from `start`: its system is factorized once for all.
      TetMesh moved = start;
      for (int k = 0; k < increments; ++k)
        if (Status st = k == 0 ? motion.extendFromAnchor(moved, step / increments)
                               : motion.extend(moved, step / increments);
            !st)
          return st.error();
      bad.clear();
      for (std::size_t t = 0; t < moved.tetCount(); ++t)
        if (tetQuality(moved, t) < minQuality) bad.push_back(t);
      if (bad.empty()) {
        out.mesh = std::move(moved);
        out.report.increments = increments;
        done = true;
        break;
      }
      if (increments == options.maxIncrements) break;
    }
    if (done || last) break;
    // Hold back the boundary nodes of the tets that fell under the bound and of their neighbours (a tet
    // inside is crushed by the boundary nodes around it); where all of those are held back already, the
    // whole boundary.
    std::vector<char> hold(taken.size(), 0);
    for (std::size_t t : bad)
      for (std::uint32_t node : mesh.tets[t])
        for (std::uint32_t k = neighbours.start[node]; k < neighbours.start[node + 1]; ++k)
          if (const int slot = boundary.slot[neighbours.nodes[k]]; slot >= 0)
            hold[static_cast<std::size_t>(slot)] = 1;
    bool held = false;
    for (std::size_t i = 0; i < taken.size(); ++i)
      if (hold[i] && taken[i] > 0.0) {
        taken[i] = taken[i] < 0.2 ? 0.0 : 0.5 * taken[i];
        held = true;
      }
    if (!held)
      for (double& share : taken)
        share = share < 0.2 ? 0.0 : 0.5 * share;
  }
  if (!done && reached < minQuality)
    return Error{ErrorCode::kDegenerateFace, "morph: a tet would fall to quality " + std::to_string(reached) +
                                                 " (bound " + std::to_string(minQuality) +
                                                 "): the target is too far from the mesh's shape"};
  if (!done) out.mesh = start;
  // The share of the projection taken, weighted by the boundary nodes' areas.
  const std::vector<double> nodeArea = boundaryAreas(boundary, start);
  double area = 0.0, projected = 0.0;
  for (std::size_t i = 0; i < taken.size(); ++i) {
    area += nodeArea[i];
    projected += nodeArea[i] * (done ? taken[i] : 0.0);
  }
  out.report.projected = area > 0.0 ? projected / area : 0.0;
  out.report.worstQuality = worstQuality(out.mesh);

  // How far the boundary went, prestretch included, and how much of the target it leaves out (over at
  // most 2,000 of the target's samples, by their areas).
  double sum = 0.0;
  for (std::uint32_t node : boundary.nodes) {
    const double d = (out.mesh.nodes[node] - mesh.nodes[node]).norm();
    out.report.maxBoundaryMove = std::max(out.report.maxBoundaryMove, d);
    sum += d;
  }
  out.report.meanBoundaryMove =
      boundary.nodes.empty() ? 0.0 : sum / static_cast<double>(boundary.nodes.size());
  const core::ClosestPointTree morphed(core::boundarySurface(out.mesh));
  const std::size_t stride = std::max<std::size_t>(1, target.sampleCount() / 2000);
  const std::vector<double>& sampleArea = target.target().sampleAreas();
  double distance = 0.0, sampled = 0.0;
  std::uint32_t near = MorphTarget::kNoHint;  // the previous point's face: the target's samples come in runs
  for (std::size_t v = 0; v < target.sampleCount(); v += stride) {
    const core::ClosestPointTree::Hit hit = morphed.closest(target.sample(v), near);
    near = hit.triangle;
    distance += sampleArea[v] * std::sqrt(hit.closest.squaredDistance);
    sampled += sampleArea[v];
  }
  out.report.meanTargetDistance = sampled > 0.0 ? distance / sampled : 0.0;
  return out;
}

}  // namespace shapedb::volume
