// Real meshes TetGen cannot mesh as they are (the meshes are not part of the repository; without them
// these tests skip and say why): a scan whose surface folds through itself, whose crossings the error
// names, and a CAD part whose tets come apart into pieces until its caps are flipped away.

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/core/topology.h>
#include <shapedb/io/enrich.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/simplify.h>
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

// A CAD part's tessellation has three caps, faces whose corner lies 5e-6 to 2e-5 of their longest edge's
// length off it. TetGen's refinement runs away around them, down to tets a millionth of the part's size,
// which tetrahedralize takes for flat and drops: the tets then come apart into pieces that meet only at
// edges (a mechanism), at every bound tried. tetrahedralize meshes the surface with its caps flipped away
// instead: one solid, of the part's vertices and volume.
TEST(TetrahedralizeRealMeshes, APartWhoseCapsMakeItsTetsComeApartIsMeshedWithThemFlipped) {
  SHAPEDB_REAL_MESHES_OR_SKIP(folder);
  Result<io::LoadedMesh> part = io::loadMesh(folder / "cad/shadowhand_lf_metacarpal.obj");
  ASSERT_TRUE(part.ok()) << part.error().message;
  const core::TriangleMesh& surface = part->mesh;
  EXPECT_TRUE(core::findSelfIntersections(surface).empty());
  core::TriangleMesh capless = surface;
  EXPECT_EQ(core::flipThinFaces(capless, 1e-4), 3u);

  // Without its fallbacks, the surface as given: TetGen's tets make pieces once the tiny ones are dropped
  // (with merging and without).
  volume::TetrahedralizeOptions options = volume::entryMeshing(volume::ElementOrder::kQuadratic);
  options.relaxOnFailure = false;
  const Result<core::TetMesh> asGiven = volume::tetrahedralize(surface, options);
  ASSERT_FALSE(asGiven.ok());
  EXPECT_NE(asGiven.error().message.find("pieces joined only at edges or nodes"), std::string::npos)
      << asGiven.error().message;

  const Result<core::TetMesh> tets =
      volume::tetrahedralize(surface, volume::entryMeshing(volume::ElementOrder::kQuadratic));
  ASSERT_TRUE(tets.ok()) << tets.error().message;
  EXPECT_TRUE(core::validateTetMesh(*tets).ok());
  EXPECT_EQ(core::faceConnectedPieces(*tets), 1u);
  ASSERT_GE(tets->nodes.size(), surface.vertices.size());
  for (std::size_t v = 0; v < surface.vertices.size(); ++v)
    ASSERT_EQ(tets->nodes[v], surface.vertices[v]) << "vertex " << v;  // TetGen keeps them first
  const double volume = core::computeMassProperties(surface)->volume;
  EXPECT_NEAR(core::computeTetMassProperties(*tets).volume / volume, 1.0, 1e-6);
}

// What an Enricher learns is every real mesh's own data: each file of the folder, its surface as the
// Enricher takes it (volume::surfaceForEntry at EnricherOptions' triangle count), is meshed at the default
// database's meshing, or refused because it passes through itself (the horse: its simplified surface may
// or may not still cross).
TEST(TetrahedralizeRealMeshes, EverySurfaceAnEnricherTakesIsMeshedOrCrossesItself) {
  SHAPEDB_REAL_MESHES_OR_SKIP(folder);
  const Result<std::vector<std::filesystem::path>> files = io::listMeshFiles(folder);
  ASSERT_TRUE(files.ok()) << files.error().message;
  std::size_t meshed = 0;
  for (const std::filesystem::path& file : *files) {
    SCOPED_TRACE(file.string());
    const Result<io::LoadedMesh> loaded = io::loadMesh(file);
    if (!loaded) continue;  // a file the loader refuses is the loader tests' business
    const auto simplified = volume::surfaceForEntry(loaded->mesh, io::EnricherOptions{}.maxTriangles);
    ASSERT_TRUE(simplified.ok()) << simplified.error().message;
    const core::TriangleMesh& surface = *simplified ? **simplified : loaded->mesh;
    const Result<core::TetMesh> tets =
        volume::tetrahedralize(surface, volume::entryMeshing(volume::ElementOrder::kQuadratic));
    if (tets) {
      ++meshed;
      EXPECT_EQ(core::faceConnectedPieces(*tets), 1u);
    } else {
      EXPECT_EQ(tets.error().code, ErrorCode::kSelfIntersecting) << tets.error().message;
    }
  }
  EXPECT_GT(meshed, 0u);
}

}  // namespace
}  // namespace shapedb
