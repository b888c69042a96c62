// TetGen behind its guard (volume/tetrahedralize.h): the tets fill the surface exactly, an entry's tets are
// valid in its canonical frame, the guarded worker gives the in-process mesh, a worker's death costs
// nothing, and bad input is an error, not a crash.

#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/primitives.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume {
namespace {

using core::TetMesh;
using core::Vec3;

TetMesh meshOrDie(const core::TriangleMesh& surface, const TetrahedralizeOptions& options = {}) {
  Result<TetMesh> tets = tetrahedralize(surface, options);
  EXPECT_TRUE(tets.ok()) << (tets ? "" : tets.error().message);
  return tets ? std::move(tets).value() : TetMesh{};
}

TEST(Tetrahedralize, TetVolumeIntegralsEqualSurfaceIntegrals) {
  for (const core::TriangleMesh& surface :
       {core::makeBox(Vec3(2, 1, 0.5)), core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.3), 24, 12),
        core::makeCone(0.5, 1.5, 20), core::makeCapsule(0.3, 1.0, 16, 4),
        core::makeTriangularPrism(1.0, 0.7, 2.0)}) {
    const TetMesh tets = meshOrDie(surface);
    ASSERT_TRUE(core::validateTetMesh(tets).ok());
    const core::MassProperties fromTets = core::computeTetMassProperties(tets);
    Result<core::MassProperties> fromSurface = core::computeMassProperties(surface);
    ASSERT_TRUE(fromSurface.ok());
    EXPECT_NEAR(fromTets.volume, fromSurface->volume, 1e-9 * fromSurface->volume);
    EXPECT_LT((fromTets.centerOfMass - fromSurface->centerOfMass).norm(),
              1e-9 * std::cbrt(fromSurface->volume));
    EXPECT_LT((fromTets.inertia - fromSurface->inertia).norm(), 1e-9 * fromSurface->inertia.norm());
    // The tets' boundary is the input surface, refined: same area.
    EXPECT_NEAR(core::computeSurfaceArea(core::boundarySurface(tets)), fromSurface->area,
                1e-9 * fromSurface->area);
  }
}

// The tets an entry stores are in the canonical frame, and the database's reader refuses any tet that is
// flat there (validateTetMesh). TetGen's flat tets are dropped in the input frame; fragment-00502 of
// the default catalog kept one that the move to the canonical frame flattened by round-off, and the
// built database could not read its entry back ("corrupted tet mesh blob").
TEST(Tetrahedralize, AnEntrysTetsAreValidInTheCanonicalFrame) {
  const ShapeSpec spec = familySpec(Family::kFragment, 502);
  auto surface = makeFamilyShape(spec);
  ASSERT_TRUE(surface.ok());
  EntryOptions options;
  options.modal.modes = 2;
  auto entry = computeEntry(*surface, options);
  ASSERT_TRUE(entry.ok()) << entry.error().message;
  const Status valid = core::validateTetMesh(entry->physics.tetMesh);
  EXPECT_TRUE(valid.ok()) << valid.error().message;
}

TEST(Tetrahedralize, GuardedAndInProcessGiveTheSameMesh) {
  const core::TriangleMesh surface = core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.3), 16, 8);
  const TetMesh guarded = meshOrDie(surface, {.guarded = true});
  const TetMesh local = meshOrDie(surface, {.guarded = false});
  ASSERT_EQ(guarded.nodes.size(), local.nodes.size());
  ASSERT_EQ(guarded.tets, local.tets);
  for (std::size_t i = 0; i < local.nodes.size(); ++i)
    ASSERT_EQ(guarded.nodes[i], local.nodes[i]);
}

// A worker that dies (or hangs) costs its request only: the same request is repeated in a fresh worker,
// and the mesh is the one a healthy worker gives. These boxes are the first of the catalog a build of 24
// entries makes; for them the run without facet merging, which used to follow a dead worker, gives
// another mesh (box-00005's made a resumed database differ from a clean one under ASan).
TEST(Tetrahedralize, AWorkerThatDiesDoesNotChangeTheMesh) {
  const std::vector<Family> families = {Family::kBox, Family::kCone, Family::kShard};
  for (const ShapeSpec& spec : buildCatalog(24, families)) {
    if (spec.family != Family::kBox) continue;
    const Result<core::TriangleMesh> surface = makeFamilyShape(spec);
    ASSERT_TRUE(surface.ok()) << surface.error().message;
    const TetMesh healthy = meshOrDie(*surface);
    testing::killNextTetGenWorkers(1);
    const TetMesh afterDeath = meshOrDie(*surface);
    testing::killNextTetGenWorkers(0);
    ASSERT_EQ(afterDeath.nodes.size(), healthy.nodes.size()) << "box " << spec.index;
    ASSERT_EQ(afterDeath.tets, healthy.tets) << "box " << spec.index;
    for (std::size_t i = 0; i < healthy.nodes.size(); ++i)
      ASSERT_EQ(afterDeath.nodes[i], healthy.nodes[i]) << "box " << spec.index;
  }
}

TEST(Tetrahedralize, BadInputIsAnErrorNotACrash) {
  core::TriangleMesh open = core::makeBox(Vec3(1, 1, 1));
  open.triangles.pop_back();
  Result<TetMesh> r = tetrahedralize(open);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotClosed);

  // Closed and oriented but self-intersecting: two overlapping cubes in one mesh. TetGen's own check.
  core::TriangleMesh overlap = core::makeBox(Vec3(1, 1, 1));
  const core::TriangleMesh other = core::transformed(core::makeBox(Vec3(1, 1, 1)), [] {
    core::Mat4 t = core::Mat4::Identity();
    t.topRightCorner<3, 1>() = Vec3(0.5, 0.3, 0.2);
    return t;
  }());
  const auto offset = static_cast<std::uint32_t>(overlap.vertices.size());
  overlap.vertices.insert(overlap.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (auto tri : other.triangles)
    overlap.triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
  r = tetrahedralize(overlap);
  ASSERT_FALSE(r.ok());
  std::printf("self-intersecting: %s\n", r.error().message.c_str());

  // The worker that crashed is replaced: the next mesh tetrahedralizes as before.
  const TetMesh after = meshOrDie(core::makeBox(Vec3(1, 2, 3)));
  EXPECT_NEAR(core::computeTetMassProperties(after).volume, 6.0, 1e-12);
}

}  // namespace
}  // namespace shapedb::volume
