#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/spatial.h>
#include <shapedb/volume/correction.h>

#include "point_masses.h"

namespace shapedb::volume {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Each node's own mass at unit density: a quarter of every tet it is a corner of.
std::vector<double> nodeMasses(const core::TetMesh& tets) {
  std::vector<double> own(tets.nodeCount(), 0.0);
  for (std::size_t t = 0; t < tets.tetCount(); ++t) {
    const double quarter = 0.25 * std::abs(core::tetVolume(tets, t));
    for (const std::uint32_t node : tets.tets[t])
      own[node] += quarter;
  }
  return own;
}

}  // namespace

namespace detail {

std::vector<double> limitedShares(std::span<const double> weights, std::span<const double> own, double mass) {
  // λ · weight for every node, but at most kPointMassLimit × own: the nodes whose limit is least for their
  // weight reach it first, and each one that does leaves the rest to the others (water filling).
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < weights.size(); ++i)
    if (weights[i] > 0.0) order.push_back(i);
  std::vector<double> out(weights.size(), 0.0);
  if (order.empty()) return out;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return own[a] * weights[b] < own[b] * weights[a]; });
  // The weight of the nodes from the j-th on, summed from the last (no cancellation from subtracting).
  std::vector<double> rest(order.size() + 1, 0.0);
  for (std::size_t j = order.size(); j-- > 0;)
    rest[j] = rest[j + 1] + weights[order[j]];
  double placed = 0.0;
  std::size_t full = 0;
  for (; full < order.size(); ++full) {
    const std::size_t i = order[full];
    const double limit = kPointMassLimit * own[i];
    if ((mass - placed) * weights[i] <= limit * rest[full]) break;
    out[i] = limit;
    placed += limit;
  }
  if (full < order.size()) {
    for (std::size_t j = full; j < order.size(); ++j)
      out[order[j]] = (mass - placed) * (weights[order[j]] / rest[full]);
  } else {
    // Every node at its limit: the rest over all the nodes by their own mass, as a uniform density would.
    const double all = std::accumulate(own.begin(), own.end(), 0.0);
    if (all > 0.0)
      for (std::size_t i = 0; i < out.size(); ++i)
        out[i] += (mass - placed) * (own[i] / all);
  }
  return out;
}

}  // namespace detail

namespace {

// `mass` shared among the nodes of `tets` next to where `target` lies outside them (MorphedEntry::
// pointMasses), none more than kPointMassLimit times its `own` mass (nodeMasses); empty if no sample of
// the target lies outside. `peak`: CorrectionReport::pointMassPeak.
std::vector<double> missingMass(const core::TetMesh& tets, std::span<const double> own,
                                const MorphTarget::View& target, double mass, double& peak) {
  const std::vector<double>& area = target.target().sampleAreas();
  const core::TetLocator locator(tets);
  core::TetLocator::Hint hint;
  std::vector<double> share(tets.nodeCount(), 0.0);
  for (std::size_t v = 0; v < target.sampleCount(); ++v) {
    const core::TetLocation at = locator.locate(target.sample(v), hint);
    if (at.inside() || area[v] == 0.0) continue;
    const double gap = area[v] * at.distance;
    // The closest point is on a boundary face of at.tet: the node across from it has weight 0, to
    // round-off, which must not put mass inside.
    for (std::size_t k = 0; k < 4; ++k)
      if (at.weights[k] > 1e-9) share[tets.tets[at.tet][k]] += gap * at.weights[k];
  }
  const double total = std::accumulate(share.begin(), share.end(), 0.0);
  if (!(total > 0.0)) return {};
  peak = 0.0;
  for (std::size_t i = 0; i < share.size(); ++i)
    if (share[i] > 0.0 && own[i] > 0.0) peak = std::max(peak, mass * share[i] / total / own[i]);
  return detail::limitedShares(share, own, mass);
}

// CorrectionReport::strayShare: the volume of the tets whose centroid lies outside `target`, over all
// of theirs.
double strayShare(const core::TetMesh& tets, const MorphTarget::View& target) {
  double outside = 0.0, total = 0.0;
  std::uint32_t near = MorphTarget::kNoHint;  // the previous tet's: tets numbered near are mostly near
  for (std::size_t t = 0; t < tets.tetCount(); ++t) {
    const core::Vec3 centroid = 0.25 * (tets.nodes[tets.tets[t][0]] + tets.nodes[tets.tets[t][1]] +
                                        tets.nodes[tets.tets[t][2]] + tets.nodes[tets.tets[t][3]]);
    const double volume = std::abs(core::tetVolume(tets, t));
    total += volume;
    if (!target.inside(centroid, near)) outside += volume;
  }
  return total > 0.0 ? outside / total : 0.0;
}

}  // namespace

Result<MorphedEntry> morphEntry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                const CorrectionOptions& options) {
  const Clock::time_point start = Clock::now();
  auto prepared = MorphTarget::prepare(target);
  if (!prepared) return prepared.error();
  auto out = morphEntry(entry, prepared->view(), options);
  if (out) out->report.morphSeconds = secondsSince(start);
  return out;
}

Result<MorphedEntry> morphEntry(const core::PhysicalData& entry, const MorphTarget::View& target,
                                const CorrectionOptions& options, MissingMass missing) {
  if (entry.modes.shapes.rows() != static_cast<Eigen::Index>(3 * entry.tetMesh.nodeCount()) ||
      entry.modes.shapes.cols() < 1)
    return Error{ErrorCode::kInvalidArgument, "correction: the entry's mode shapes do not fit its tet mesh"};
  const Clock::time_point start = Clock::now();
  auto morphed = morphTetMesh(entry.tetMesh, target, options.morph);
  if (!morphed) return morphed.error();
  MorphedEntry out;
  out.report.morph = morphed->report;
  out.tetMesh = std::move(morphed->mesh);
  // The morphed tets fill the target only as far as the projection went: a boundary node held back off a
  // sharp edge cuts the edge or the corner, and a part the entry has no tets for is left out. What is
  // cut off is at the body's rim, mass where a mode moves most and little stiffness (a free edge carries
  // no stress). So its mass is given back where it is missing, and not its volume: the target's samples
  // that lie outside the tets (MorphTarget::sampleAreas: over its faces, not only at its corners), each
  // with its area times its distance to them, share the missing mass among the corners of the boundary
  // faces nearest to them. Scaling the tets
  // up to the target's volume, as before, thickened the whole body, stiffness with the mass, and left the
  // corrected first frequencies higher (docs/architecture.md).
  const std::optional<core::MassProperties>& targetMass = target.target().massProperties();
  const double volume = core::computeTetMassProperties(out.tetMesh).volume;
  if (targetMass && std::isfinite(targetMass->volume / volume) && targetMass->volume > 0.0)
    out.report.massScale = targetMass->volume / volume;
  if (missing == MissingMass::kPlaced) placeMissingMass(out, target);
  // A side is defined only for a surface that bounds a solid (closed and oriented, the precondition of
  // SurfaceSide, which computeMassProperties checks): for any other the share stays 0, unknown.
  if (targetMass) out.report.strayShare = strayShare(out.tetMesh, target);
  out.report.morphSeconds = secondsSince(start);
  return out;
}

void placeMissingMass(MorphedEntry& morphed, const MorphTarget::View& target) {
  const std::optional<core::MassProperties>& targetMass = target.target().massProperties();
  if (!targetMass) return;
  // The tets' volume is their nodes' own masses at unit density, which the sharing needs too.
  const std::vector<double> own = nodeMasses(morphed.tetMesh);
  const double volume = std::accumulate(own.begin(), own.end(), 0.0);
  if (std::isfinite(targetMass->volume / volume) && targetMass->volume > volume && volume > 0.0)
    morphed.pointMasses =
        missingMass(morphed.tetMesh, own, target, targetMass->volume - volume, morphed.report.pointMassPeak);
}

std::vector<std::string> correctionWarnings(const CorrectionReport& report) {
  std::vector<std::string> out;
  if (report.strayShare > kStrayShareWarning)
    out.push_back("geometry correction: " + std::to_string(std::lround(100 * report.strayShare)) +
                  " % of the morphed tets lie outside the mesh (the entry spans a gap the object has, as "
                  "between limbs or through a loop): the corrected frequencies may be far off; the object's "
                  "own data (enrichment) are the answer for it");
  if (report.massScale > kMassScaleWarning)
    out.push_back("geometry correction: the morphed tets hold " +
                  std::to_string(std::lround(100 / report.massScale)) +
                  " % of the mesh's volume (a part of the object the entry has no tets for): the rest is "
                  "carried as mass without stiffness, and the corrected frequencies may be far off; the "
                  "object's own data (enrichment) are the answer for it");
  return out;
}

bool betterMorph(const CorrectionReport& a, const CorrectionReport& b) {
  const bool aStrays = a.strayShare > kStrayShareWarning, bStrays = b.strayShare > kStrayShareWarning;
  if (aStrays != bStrays) return bStrays;
  return a.morph.meanTargetDistance < b.morph.meanTargetDistance;
}

ModalOptions morphedModalOptions(const MorphedEntry& morphed, const ModalOptions& modal) {
  ModalOptions unit = modal;
  unit.material = core::unitMaterial(modal.material.poissonRatio);
  if (!morphed.pointMasses.empty())
    unit.pointMasses = morphed.pointMasses;
  else
    unit.material.density = morphed.report.massScale;
  return unit;
}

namespace {

// CorrectionReport::lumpedModeShare of `modes`, computed with `pointMasses`.
double lumpedModeShare(const core::ModalData& modes, std::span<const double> pointMasses) {
  // The shapes are M-orthonormal, lumped masses included: node i's share of the first mode's kinetic
  // energy is its lumped mass times |φᵢ|² (its share of the tets' own mass is left out).
  double most = 0.0;
  if (modes.shapes.cols() > 0)
    for (std::size_t i = 0; i < pointMasses.size(); ++i)
      most =
          std::max(most, pointMasses[i] *
                             modes.shapes.col(0).segment<3>(3 * static_cast<Eigen::Index>(i)).squaredNorm());
  return most;
}

}  // namespace

Result<CorrectedEntry> correctMorphed(const core::PhysicalData& entry, MorphedEntry morphed,
                                      const ModalOptions& modal) {
  CorrectedEntry out;
  out.report = morphed.report;
  out.physics.tetMesh = std::move(morphed.tetMesh);
  out.physics.massProperties = core::computeTetMassProperties(out.physics.tetMesh, out.report.massScale);

  // The entry's modes on the same nodes are the seeds: the morph moved the nodes, not their numbering.
  const Clock::time_point start = Clock::now();
  ModalOptions unit = morphedModalOptions(morphed, modal);
  auto modes = computeModesFrom(out.physics.tetMesh, entry.modes.shapes, unit, &out.report.solves);
  if (!modes) return withContext(modes.error(), "correction: modes on the morphed tets");
  out.report.lumpedModeShare = lumpedModeShare(*modes, unit.pointMasses);
  if (out.report.lumpedModeShare > kLumpedModeLimit) {
    // A mode of one node's lumped mass, which the object does not have: the missing mass over the tets
    // instead, as density (what morphedModalOptions gives where none is lumped).
    morphed.pointMasses.clear();
    unit = morphedModalOptions(morphed, modal);
    int solves = 0;
    modes = computeModesFrom(out.physics.tetMesh, entry.modes.shapes, unit, &solves);
    if (!modes) return withContext(modes.error(), "correction: modes on the morphed tets, the mass spread");
    out.report.solves += solves;
    out.report.massSpread = true;
  }
  out.physics.modes = std::move(modes).value();
  out.report.modesSeconds = secondsSince(start);

  out.physics.collision = entry.collision;
  out.physics.sound.frequenciesHz = out.physics.modes.frequenciesHz();
  out.physics.sound.damping = entry.sound.damping;
  return out;
}

Result<CorrectedEntry> correctGeometry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                       const ModalOptions& modal, const CorrectionOptions& options) {
  auto morphed = morphEntry(entry, target, options);
  if (!morphed) return morphed.error();
  return correctMorphed(entry, std::move(morphed).value(), modal);
}

}  // namespace shapedb::volume
