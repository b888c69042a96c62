// The geometry correction (correction.h): an entry's tets morphed onto another surface, and their modes
// computed again there, against the modes computed directly on that surface.

#include <algorithm>
#include <cmath>
#include <cstdio>

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
  // which rounds that edge off by a hair, and the volume scale gives that hair back.
  EXPECT_NEAR(report.volumeScale, 1.0, 1e-3);
  EXPECT_LT(boundaryToTarget(corrected->physics.tetMesh, target), 1e-3);
  EXPECT_NEAR(corrected->physics.massProperties.volume, 1.9 * 0.9 * 0.57, 1e-9);
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

}  // namespace
}  // namespace shapedb::volume
