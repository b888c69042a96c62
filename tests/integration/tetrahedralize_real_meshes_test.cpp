// Real meshes TetGen cannot mesh (the meshes are not part of the repository; without them these tests
// skip and say why): a scan whose surface folds through itself, and a CAD part whose tets come apart into
// two pieces that meet only along edges, and what the error says of it.

#include <gtest/gtest.h>

#include <shapedb/core/self_intersection.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/tetrahedralize.h>

#include "support/test_support.h"

namespace shapedb {
namespace {

// The horse scan folds through itself: 4 pairs of its 96,966 triangles cross, which is what TetGen
// segfaults on (in its guarded worker) and what tetrahedralize's error then names
// (Tetrahedralize.BadInputIsAnErrorNotACrash shows that on two overlapping cubes, in a fraction of the
// time four crashing TetGen runs on the horse take).
TEST(TetrahedralizeRealMeshes, TheScanThatFoldsThroughItselfHasItsCrossingsFound) {
  SHAPEDB_REAL_MESHES_OR_SKIP(folder);
  Result<io::LoadedMesh> horse = io::loadMesh(folder / "scanned/horse.ply");
  ASSERT_TRUE(horse.ok()) << horse.error().message;
  const std::vector<core::TriangleCrossing> crossings = core::findSelfIntersections(horse->mesh);
  EXPECT_FALSE(crossings.empty());
  EXPECT_LT(crossings.size(), 100u);
  for (const std::string other : {"scanned/bob_small.ply", "scanned/fox.ply", "primitive/torus.STL"}) {
    Result<io::LoadedMesh> loaded = io::loadMesh(folder / other);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_TRUE(core::findSelfIntersections(loaded->mesh).empty()) << other;
  }
}

TEST(TetrahedralizeRealMeshes, APartWhoseTetsComeApartSaysSoBesideTheMergedRunsError) {
  SHAPEDB_REAL_MESHES_OR_SKIP(folder);
  Result<io::LoadedMesh> part = io::loadMesh(folder / "cad/shadowhand_lf_metacarpal.obj");
  ASSERT_TRUE(part.ok()) << part.error().message;
  EXPECT_TRUE(core::findSelfIntersections(part->mesh).empty());
  const Result<core::TetMesh> tets =
      volume::tetrahedralize(part->mesh, volume::entryMeshing(volume::ElementOrder::kQuadratic));
  ASSERT_FALSE(tets.ok());
  // TetGen's merged run moves the surface a little; its unmerged run fills it exactly, and its tets make
  // two pieces once the flat ones (between nearly coplanar facets) are dropped: both are said.
  EXPECT_NE(tets.error().message.find("; without merging facets: "), std::string::npos)
      << tets.error().message;
  EXPECT_NE(tets.error().message.find("2 pieces joined only at edges or nodes"), std::string::npos)
      << tets.error().message;
}

}  // namespace
}  // namespace shapedb
