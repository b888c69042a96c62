// The geometry correction (correction.h): an entry's tets morphed onto another surface, and their modes
// computed again there, against the modes computed directly on that surface.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>
#include <shapedb/volume/correction.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/morph.h>
#include <shapedb/volume/tetrahedralize.h>

#include "point_masses.h"
#include "synthetic.h"

namespace shapedb::volume {
namespace {

using core::TetMesh;
using core::Vec3;

ModalOptions modalOptions(int modes) {
  ModalOptions options;
  options.modes = modes;
  return options;
}

/// An entry's physical data for `surface` as the default build computes them (quadratic tets at the
/// entry's meshing, unit material), without the descriptors and the collision compound.
core::PhysicalData entryData(const core::TriangleMesh& surface, int modes) {
  core::PhysicalData data;
  Result<TetMesh> tets = tetrahedralize(surface, entryMeshing(ElementOrder::kQuadratic));
  EXPECT_TRUE(tets.ok()) << (tets ? "" : tets.error().message);
  if (!tets) return data;
  data.tetMesh = std::move(tets).value();
  data.massProperties = core::computeTetMassProperties(data.tetMesh);
  Result<core::ModalData> m = computeModes(data.tetMesh, modalOptions(modes));
  EXPECT_TRUE(m.ok()) << (m ? "" : m.error().message);
  if (m) data.modes = std::move(m).value();
  return data;
}

double worstTetQuality(const TetMesh& mesh) {
  double worst = 1.0;
  for (std::size_t t = 0; t < mesh.tetCount(); ++t)
    worst = std::min(worst, tetQuality(mesh, t));
  return worst;
}

/// Largest distance from a boundary node of `mesh` to `target`.
double boundaryToTarget(const TetMesh& mesh, const core::TriangleMesh& target) {
  const core::ClosestPointTree tree(target);
  double worst = 0.0;
  for (const Vec3& p : core::boundarySurface(mesh).vertices)
    worst = std::max(worst, std::sqrt(tree.closest(p).closest.squaredDistance));
  return worst;
}

// The affine case has an exact answer: the box entry morphed onto a box of other proportions must ring
// as that box does, computed directly on its own tets.
TEST(Correction, ABoxEntryMorphedOntoAnotherBoxRingsAsThatBox) {
  const core::PhysicalData entry = entryData(core::makeBox(Vec3(1.3, 1.0, 0.75)), 6);
  ASSERT_EQ(entry.modes.modeCount(), 6u);
  // About the same volume (the query is carried into the entry's frame at unit volume); other proportions.
  const core::TriangleMesh target = core::makeBox(Vec3(1.9, 0.9, 0.57));
  Result<CorrectedEntry> corrected = correctGeometry(entry, target, modalOptions(6));
  ASSERT_TRUE(corrected.ok()) << corrected.error().message;
  const core::PhysicalData direct = entryData(target, 6);
  ASSERT_EQ(direct.modes.modeCount(), 6u);
  const CorrectionReport& report = corrected->report;
  EXPECT_GT(report.morph.worstQuality, 0.0);
  // The boundary on the target's faces; an entry's node on an edge may land beside the target's edge,
  // which rounds that edge off by a hair; the density gives that hair's mass back.
  EXPECT_NEAR(report.massScale, 1.0, 1e-3);
  EXPECT_LT(report.strayShare, 1e-3);
  EXPECT_LT(boundaryToTarget(corrected->physics.tetMesh, target), 1e-3);
  EXPECT_NEAR(corrected->physics.massProperties.volume, 1.9 * 0.9 * 0.57, 1e-3);
  EXPECT_NEAR(corrected->physics.massProperties.mass, 1.9 * 0.9 * 0.57, 1e-9);
  for (int m = 0; m < 6; ++m) {
    const double uncorrected = std::sqrt(entry.modes.eigenvalues[m] / direct.modes.eigenvalues[m]) - 1.0;
    const double error =
        std::sqrt(corrected->physics.modes.eigenvalues[m] / direct.modes.eigenvalues[m]) - 1.0;
    std::printf("box onto box, mode %d: entry %+.1f %%, corrected %+.2f %%\n", m, 100.0 * uncorrected,
                100.0 * error);
    EXPECT_LT(std::abs(error), 0.02) << "mode " << m;
  }
  EXPECT_GT(report.solves, 0);
}

// The non-affine case: an ellipsoid's tets onto a capsule and onto a box (sharp edges the ellipsoid has
// no nodes for). Every tet stays positive; the boundary ends on the target where the morph could project
// it all the way; and the frequencies move from the entry's towards the target's own.
TEST(Correction, AnEllipsoidEntryMorphedOntoOtherSolidsMovesTowardsTheirFrequencies) {
  const core::PhysicalData entry = entryData(core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.45), 16, 8), 4);
  ASSERT_EQ(entry.modes.modeCount(), 4u);
  for (const core::TriangleMesh& target :
       {core::makeCapsule(0.4, 1.4, 16, 4), core::makeBox(Vec3(1.6, 0.9, 0.7))}) {
    Result<CorrectedEntry> corrected = correctGeometry(entry, target, modalOptions(4));
    ASSERT_TRUE(corrected.ok()) << corrected.error().message;
    const TetMesh& mesh = corrected->physics.tetMesh;
    for (std::size_t t = 0; t < mesh.tetCount(); ++t)
      ASSERT_GT(core::tetVolume(mesh, t), 0.0) << "tet " << t;
    EXPECT_NEAR(worstTetQuality(mesh), corrected->report.morph.worstQuality, 1e-12);
    if (corrected->report.morph.projected == 1.0) {
      EXPECT_LT(boundaryToTarget(mesh, target), 1e-6);
    }
    const core::PhysicalData direct = entryData(target, 4);
    const double before = std::abs(std::sqrt(entry.modes.eigenvalues[0] / direct.modes.eigenvalues[0]) - 1.0);
    const double after =
        std::abs(std::sqrt(corrected->physics.modes.eigenvalues[0] / direct.modes.eigenvalues[0]) - 1.0);
    std::printf("ellipsoid onto %zu-triangle target: f1 error %.1f %% -> %.1f %% (projected %.3g)\n",
                target.triangleCount(), 100.0 * before, 100.0 * after, corrected->report.morph.projected);
    EXPECT_LT(after, 0.6 * before);
  }
}

// Low-poly solids, as game props often are: a handful of large faces and sharp edges and corners that a
// rounder entry's boundary cannot follow all the way. The mass the morph misses along those edges is lumped
// where the target lies outside the tets; measured at the target's vertices alone (a cube's eight corners),
// it all went to the corners, where the first modes move most, and the corrected frequencies came out
// 25-35 % (cube, octahedron) to 90 % (tetrahedron) low. Measured over the faces (MorphTarget's samples),
// they ring as the solids do, or, where the morph holds much less than the solid (a capsule's tets in a
// tetrahedron's corners), the answer says it may be far off.
TEST(Correction, LowPolySolidsRingAsTheyDoOrSaySo) {
  const core::PhysicalData entry = entryData(core::makeCapsule(0.45, 1.1, 16, 4), 6);
  ASSERT_EQ(entry.modes.modeCount(), 6u);
  const double s = 0.5 * std::sqrt(2.0);
  core::TriangleMesh octahedron;
  octahedron.vertices = {Vec3(s, 0, 0),  Vec3(-s, 0, 0), Vec3(0, s, 0),
                         Vec3(0, -s, 0), Vec3(0, 0, s),  Vec3(0, 0, -s)};
  octahedron.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                          {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  const std::pair<const char*, core::TriangleMesh> targets[] = {
      {"cube", core::makeBox(Vec3(1.0, 1.0, 1.0))},
      {"octahedron", octahedron},
      {"tetrahedron",
       core::makeTetrahedron(Vec3(0, 0, 0), Vec3(1.6, 0, 0), Vec3(0, 1.6, 0), Vec3(0, 0, 1.6))}};
  for (const auto& [name, surface] : targets) {
    SCOPED_TRACE(name);
    Result<CorrectedEntry> corrected = correctGeometry(entry, surface, modalOptions(6));
    ASSERT_TRUE(corrected.ok()) << corrected.error().message;
    const core::PhysicalData direct = entryData(surface, 6);
    ASSERT_EQ(direct.modes.modeCount(), 6u);
    const double error =
        std::sqrt(corrected->physics.modes.eigenvalues[0] / direct.modes.eigenvalues[0]) - 1.0;
    const bool warned = !correctionWarnings(corrected->report).empty();
    std::printf(
        "capsule onto the %s (%zu triangles): f1 %+.1f %% (mass scale %.3f, projected %.2f, point mass peak "
        "%.1f%s)\n",
        name, surface.triangleCount(), 100.0 * error, corrected->report.massScale,
        corrected->report.morph.projected, corrected->report.pointMassPeak, warned ? ", warned" : "");
    EXPECT_TRUE(std::abs(error) < 0.08 || warned) << error;
  }
}

// A disc's tets morphed onto a ring: the morph moves the disc's boundary onto the ring's surface but cannot
// open a hole, so the tets of the disc's middle stay across the ring's, outside it. The report counts
// their volume (strayShare), the same as the winding number says of every tet's centroid.
TEST(Correction, TheTetsTheMorphCarriesAcrossAGapAreStray) {
  const core::PhysicalData entry = entryData(core::makeCylinder(1.0, 0.5, 24), 4);
  const core::TriangleMesh ring = test::makeTorus(0.75, 0.3, 32, 12);
  Result<MorphedEntry> morphed = morphEntry(entry, ring);
  ASSERT_TRUE(morphed.ok()) << morphed.error().message;
  const TetMesh& mesh = morphed->tetMesh;
  double outside = 0.0, total = 0.0;
  for (std::size_t t = 0; t < mesh.tetCount(); ++t) {
    Vec3 centroid = Vec3::Zero();
    for (const std::uint32_t n : mesh.tets[t])
      centroid += 0.25 * mesh.nodes[n];
    total += core::tetVolume(mesh, t);
    if (core::windingNumber(ring, centroid) < 0.5) outside += core::tetVolume(mesh, t);
  }
  std::printf("disc onto ring: %.1f %% of the tets' volume outside it\n", 100.0 * outside / total);
  EXPECT_NEAR(morphed->report.strayShare, outside / total, 1e-12);
  EXPECT_GT(morphed->report.strayShare, 0.05);
}

// Which candidate's morph the modes are computed on: the one nearer the target's surface, unless its tets
// stray across a gap of the target and the other's do not.
TEST(Correction, TheBetterMorphReachesTheTargetWithoutStrayingAcrossItsGaps) {
  CorrectionReport near, far;
  near.morph.meanTargetDistance = 0.01;
  far.morph.meanTargetDistance = 0.03;
  EXPECT_TRUE(betterMorph(near, far));
  EXPECT_FALSE(betterMorph(far, near));
  EXPECT_FALSE(betterMorph(near, near));
  near.strayShare = 0.25;  // across a gap: the farther one that keeps to the target wins
  far.strayShare = kStrayShareWarning;
  EXPECT_TRUE(betterMorph(far, near));
  EXPECT_FALSE(betterMorph(near, far));
  far.strayShare = 0.3;  // both stray: by distance again
  EXPECT_TRUE(betterMorph(near, far));
}

// What an answer says of a correction that may be far off: one sentence for tets across a gap, one for a
// part of the object the tets do not hold, none for a correction within both bounds (or at them).
TEST(Correction, AnswersWarnOfTetsAcrossAGapAndOfVolumeTheyDoNotHold) {
  CorrectionReport report;
  report.strayShare = kStrayShareWarning;
  report.massScale = kMassScaleWarning;
  EXPECT_TRUE(correctionWarnings(report).empty());
  report.strayShare = 0.27;
  std::vector<std::string> warnings = correctionWarnings(report);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("27 % of the morphed tets lie outside"), std::string::npos) << warnings[0];
  report.massScale = 1.6;  // the tets hold 62.5 % of the target
  warnings = correctionWarnings(report);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[1].find("hold 63 % of the mesh's volume"), std::string::npos) << warnings[1];
  report.strayShare = 0.0;
  EXPECT_EQ(correctionWarnings(report).size(), 1u);
}

// The mass the morph misses: an ellipsoid's tets onto a box cut the box's edges and corners. The tets keep
// their shape; the box's volume they lack is lumped at their boundary nodes, all of it (the answer has the
// box's mass), none inside, and most of it at the nodes nearest the box's corners and edges, where it is
// missing; a mode's frequency is then that of the heavier body, below what the bare tets give.
TEST(Correction, TheMassTheMorphMissesIsLumpedWhereTheTargetLiesOutside) {
  const core::PhysicalData entry = entryData(core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.45), 16, 8), 4);
  const Vec3 half(0.8, 0.45, 0.35);
  const core::TriangleMesh box = core::makeBox(2.0 * half);
  Result<MorphedEntry> morphed = morphEntry(entry, box);
  ASSERT_TRUE(morphed.ok()) << morphed.error().message;
  const TetMesh& mesh = morphed->tetMesh;
  const double boxVolume = 8.0 * half.prod();
  const double volume = core::computeTetMassProperties(mesh).volume;
  ASSERT_LT(volume, boxVolume);
  EXPECT_NEAR(morphed->report.massScale, boxVolume / volume, 1e-12);
  ASSERT_EQ(morphed->pointMasses.size(), mesh.nodeCount());
  double total = 0.0, nearCorners = 0.0;
  std::vector<bool> boundary(mesh.nodeCount(), false);
  for (const core::BoundaryFace& f : core::boundaryFaces(mesh))
    for (const std::uint32_t v : f.nodes)
      boundary[v] = true;
  for (std::size_t i = 0; i < mesh.nodeCount(); ++i) {
    const double m = morphed->pointMasses[i];
    ASSERT_GE(m, 0.0);
    if (!boundary[i]) {
      ASSERT_EQ(m, 0.0) << "inner node " << i;
    }
    total += m;
    // Within a fifth of the half-extent of two of the box's faces at once: along an edge or at a corner.
    const Vec3 gap = half - mesh.nodes[i].cwiseAbs();
    int close = 0;
    for (int a = 0; a < 3; ++a)
      close += gap[a] < 0.2 * half[a] ? 1 : 0;
    if (close >= 2) nearCorners += m;
  }
  EXPECT_NEAR(total, boxVolume - volume, 1e-12 * boxVolume);
  EXPECT_GT(nearCorners, 0.5 * total);

  Result<CorrectedEntry> corrected = correctMorphed(entry, *morphed, modalOptions(4));
  ASSERT_TRUE(corrected.ok()) << corrected.error().message;
  EXPECT_NEAR(corrected->physics.massProperties.mass, boxVolume, 1e-9);
  // The same tets without the point masses (at unit density) ring higher.
  Result<core::ModalData> bare = computeModesFrom(mesh, entry.modes.shapes, modalOptions(4));
  ASSERT_TRUE(bare.ok()) << bare.error().message;
  EXPECT_LT(corrected->physics.modes.eigenvalues[0], bare->eigenvalues[0]);
}

// A capsule's tets morphed onto a tetrahedron reach towards its sharp corners in slivers, and a corner's
// missing mass goes to the nodes nearest it, a sliver's tip among them: by weight alone one node would
// take some fifty times its own mass here (pointMassPeak). No node takes more than kPointMassLimit times
// it, and the mass placed is still all the tets lack.
TEST(Correction, NoNodeTakesMoreOfTheMissingMassThanItsLimit) {
  const core::PhysicalData entry = entryData(core::makeCapsule(0.45, 1.1, 16, 4), 6);
  const core::TriangleMesh tetrahedron =
      core::makeTetrahedron(Vec3(0, 0, 0), Vec3(1.6, 0, 0), Vec3(0, 1.6, 0), Vec3(0, 0, 1.6));
  const double target = core::computeMassProperties(tetrahedron)->volume;
  Result<MorphedEntry> morphed = morphEntry(entry, tetrahedron);
  ASSERT_TRUE(morphed.ok()) << morphed.error().message;
  const TetMesh& mesh = morphed->tetMesh;
  std::vector<double> own(mesh.nodeCount(), 0.0);
  for (std::size_t t = 0; t < mesh.tetCount(); ++t)
    for (const std::uint32_t n : mesh.tets[t])
      own[n] += 0.25 * std::abs(core::tetVolume(mesh, t));
  const double volume = std::accumulate(own.begin(), own.end(), 0.0);
  ASSERT_LT(volume, target);
  ASSERT_EQ(morphed->pointMasses.size(), mesh.nodeCount());
  EXPECT_NEAR(std::accumulate(morphed->pointMasses.begin(), morphed->pointMasses.end(), 0.0), target - volume,
              1e-12 * target);
  // At most the limit, and, were every node near the corners at it, the rest spread by own mass.
  for (std::size_t i = 0; i < mesh.nodeCount(); ++i)
    EXPECT_LE(morphed->pointMasses[i], (kPointMassLimit + (target - volume) / volume) * own[i] * (1.0 + 1e-9))
        << "node " << i;
  std::printf("capsule onto a tetrahedron: point mass peak %.1f\n", morphed->report.pointMassPeak);
  EXPECT_GT(morphed->report.pointMassPeak, 2.0 * kPointMassLimit);  // the limit held some node back
}

// A node the morph leaves held by next to no stiffness (here the tip of a needle tet standing on a box's
// face) rings on its own once mass is lumped there: a mode of that node, which the object does not have,
// as the first. The correction finds it (lumpedModeShare past kLumpedModeLimit) and computes the modes
// again with the missing mass spread over the tets as density: then they are the modes computed directly
// so. The same mass lumped over the whole face is left lumped. The lump is a fiftieth of the box's mass: a
// heavier one swings the free box about with it, and its own share of the mode falls (0.42 at a third).
TEST(Correction, AModeOfOneNodesLumpedMassIsFoundAndTheMassIsSpreadInstead) {
  core::PhysicalData entry = entryData(core::makeBox(Vec3(1.0, 0.8, 0.6)), 6);
  TetMesh mesh = entry.tetMesh;
  const auto onFace = [&](std::uint32_t v) { return std::abs(mesh.nodes[v].x() - 0.5) < 1e-9; };
  const std::vector<core::BoundaryFace> faces = core::boundaryFaces(mesh);
  const auto base = std::find_if(faces.begin(), faces.end(), [&](const core::BoundaryFace& f) {
    return onFace(f.nodes[0]) && onFace(f.nodes[1]) && onFace(f.nodes[2]);
  });
  ASSERT_NE(base, faces.end());
  const auto [a, b, c] = base->nodes;
  const auto apex = static_cast<std::uint32_t>(mesh.nodeCount());
  mesh.nodes.push_back((mesh.nodes[a] + mesh.nodes[b] + mesh.nodes[c]) / 3.0 + Vec3(0.6, 0.0, 0.0));
  mesh.tets.push_back({a, b, c, apex});
  if (core::tetVolume(mesh, mesh.tetCount() - 1) < 0.0) std::swap(mesh.tets.back()[0], mesh.tets.back()[1]);
  Result<core::ModalData> seeds = computeModes(mesh, modalOptions(6));
  ASSERT_TRUE(seeds.ok()) << seeds.error().message;
  entry.tetMesh = mesh;
  entry.modes = *seeds;
  const double volume = core::computeTetMassProperties(mesh).volume, missing = 0.01;

  const auto correctedWith = [&](std::vector<double> pointMasses) {
    MorphedEntry morphed;
    morphed.tetMesh = mesh;
    morphed.pointMasses = std::move(pointMasses);
    morphed.report.massScale = (volume + missing) / volume;
    return correctMorphed(entry, std::move(morphed), modalOptions(6));
  };
  ModalOptions spread = modalOptions(6);
  spread.material.density = (volume + missing) / volume;
  Result<core::ModalData> direct = computeModes(mesh, spread);
  ASSERT_TRUE(direct.ok()) << direct.error().message;

  // All of it at the needle's tip: that node's own mode comes first, far below the body's.
  std::vector<double> atTip(mesh.nodeCount(), 0.0);
  atTip[apex] = missing;
  ModalOptions lumped = modalOptions(6);
  lumped.pointMasses = atTip;
  Result<core::ModalData> tipMode = computeModes(mesh, lumped);
  ASSERT_TRUE(tipMode.ok()) << tipMode.error().message;
  EXPECT_LT(tipMode->eigenvalues[0], 0.25 * direct->eigenvalues[0]);
  Result<CorrectedEntry> tip = correctedWith(atTip);
  ASSERT_TRUE(tip.ok()) << tip.error().message;
  std::printf("needle tip: lumped mode share %.3f; first eigenvalue %.4g lumped, %.4g spread\n",
              tip->report.lumpedModeShare, tipMode->eigenvalues[0], tip->physics.modes.eigenvalues[0]);
  EXPECT_GT(tip->report.lumpedModeShare, kLumpedModeLimit);
  EXPECT_TRUE(tip->report.massSpread);
  for (Eigen::Index m = 0; m < 6; ++m)
    EXPECT_NEAR(tip->physics.modes.eigenvalues[m], direct->eigenvalues[m], 1e-6 * direct->eigenvalues[m])
        << "mode " << m;

  // The same mass over the face's nodes by their own masses: the body's modes, with the mass lumped. (By
  // their number, the box's corner nodes, each a share of few tets, took several times their own mass,
  // and one of the first modes had 0.56 of its energy on one of them.)
  std::vector<double> own(mesh.nodeCount(), 0.0), overFace(mesh.nodeCount(), 0.0);
  for (std::size_t t = 0; t + 1 < mesh.tetCount(); ++t)  // the box's tets, not the needle
    for (const std::uint32_t n : mesh.tets[t])
      own[n] += 0.25 * std::abs(core::tetVolume(mesh, t));
  double faceMass = 0.0;
  for (std::uint32_t v = 0; v < apex; ++v)
    faceMass += onFace(v) ? own[v] : 0.0;
  for (std::uint32_t v = 0; v < apex; ++v)
    if (onFace(v)) overFace[v] = missing * own[v] / faceMass;
  lumped.pointMasses = overFace;
  Result<core::ModalData> faceModes = computeModes(mesh, lumped);
  ASSERT_TRUE(faceModes.ok()) << faceModes.error().message;
  Result<CorrectedEntry> spreadOver = correctedWith(overFace);
  ASSERT_TRUE(spreadOver.ok()) << spreadOver.error().message;
  EXPECT_LT(spreadOver->report.lumpedModeShare, kLumpedModeLimit);
  EXPECT_FALSE(spreadOver->report.massSpread);
  for (Eigen::Index m = 0; m < 6; ++m)
    EXPECT_NEAR(spreadOver->physics.modes.eigenvalues[m], faceModes->eigenvalues[m],
                1e-6 * faceModes->eigenvalues[m])
        << "mode " << m;
}

// The shares of the missing mass against a search for the same answer by bisection: λ such that
// Σ min(λ wᵢ, L mᵢ) is the mass to place (L = kPointMassLimit), each node's share min(λ wᵢ, L mᵢ); or,
// where even every weighted node at its limit is too little, those limits and the rest by own mass.
TEST(Correction, TheMissingMassIsSharedByWeightAndNoNodeTakesPastItsLimit) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int limited = 0, overflowing = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 1 + rng() % 40;
    std::vector<double> weights(n), own(n);
    for (std::size_t i = 0; i < n; ++i) {
      weights[i] = unit(rng) < 0.3 ? 0.0 : std::pow(unit(rng), 4);  // some nodes unweighted, some far heavier
      own[i] = std::pow(10.0, -4.0 * unit(rng));                    // own masses over four decades
    }
    double room = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (weights[i] > 0.0) room += kPointMassLimit * own[i];
    const double mass = room * (trial % 5 == 0 ? 1.0 + unit(rng) : unit(rng));
    const std::vector<double> shares = detail::limitedShares(weights, own, mass);
    ASSERT_EQ(shares.size(), n);
    const double weight = std::accumulate(weights.begin(), weights.end(), 0.0);
    if (weight == 0.0) {
      for (const double s : shares)
        EXPECT_EQ(s, 0.0);
      continue;
    }
    EXPECT_NEAR(std::accumulate(shares.begin(), shares.end(), 0.0), mass, 1e-12 * mass);
    std::vector<double> expected(n, 0.0);
    if (mass >= room) {
      ++overflowing;
      const double all = std::accumulate(own.begin(), own.end(), 0.0);
      for (std::size_t i = 0; i < n; ++i)
        expected[i] = (weights[i] > 0.0 ? kPointMassLimit * own[i] : 0.0) + (mass - room) * own[i] / all;
    } else {
      const auto placed = [&](double lambda) {
        double sum = 0.0;
        for (std::size_t i = 0; i < n; ++i)
          sum += std::min(lambda * weights[i], kPointMassLimit * own[i]);
        return sum;
      };
      double low = 0.0, high = 1.0;
      while (placed(high) < mass)
        high *= 2.0;
      for (int step = 0; step < 200; ++step) {
        const double mid = 0.5 * (low + high);
        (placed(mid) < mass ? low : high) = mid;
      }
      bool atLimit = false;
      for (std::size_t i = 0; i < n; ++i) {
        expected[i] = std::min(high * weights[i], kPointMassLimit * own[i]);
        atLimit = atLimit || (weights[i] > 0.0 && high * weights[i] > kPointMassLimit * own[i]);
        EXPECT_LE(shares[i], kPointMassLimit * own[i] * (1.0 + 1e-12));
      }
      limited += atLimit ? 1 : 0;
    }
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_NEAR(shares[i], expected[i], 1e-9 * mass) << "trial " << trial << ", node " << i;
  }
  // Both regimes were met, and some nodes were held at their limit.
  EXPECT_GT(limited, 50);
  EXPECT_GT(overflowing, 20);
}

}  // namespace
}  // namespace shapedb::volume
