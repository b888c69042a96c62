// Fracture on real meshes: nothing dropped for not closing, no speck kept beside a fragment, the volume
// kept, wherever the mesh sits.
// The meshes are not part of the repository (see tests/support: SHAPEDB_REAL_MESHES); without them these
// tests skip and say why. bench/fracture_volume.sh runs the same on every mesh of the folder at 50 and
// 200 pieces (minutes); this is a sample of the kinds: a CAD part, a thin-walled bottle far from the
// origin in many pieces, a knot.

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/topology.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/fracture.h>

#include "support/test_support.h"

namespace shapedb {
namespace {

struct RealFracture {
  std::string file;
  int pieces;
  core::Vec3 offset;
};

TEST(FractureRealMeshes, NoFragmentIsDroppedForNotClosingAndTheVolumeIsKept) {
  SHAPEDB_REAL_MESHES_OR_SKIP(folder);
  const RealFracture cases[] = {
      {"cad/barkour_foot.stl", 50, core::Vec3::Zero()},
      {"everyday/fuze_bottle.obj", 200, core::Vec3(400.0, -300.0, 250.0)},  // where scans sit
      {"primitive/quadknot.obj", 50, core::Vec3::Zero()},
  };
  for (const RealFracture& c : cases) {
    SCOPED_TRACE(c.file);
    Result<io::LoadedMesh> loaded = io::loadMesh(folder / c.file);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    core::TriangleMesh mesh = std::move(loaded->mesh);
    for (core::Vec3& p : mesh.vertices)
      p += c.offset;
    volume::FractureOptions options;
    options.pieces = c.pieces;
    Result<volume::FractureResult> r = volume::fracture(mesh, options);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->openDropped, 0u);
    EXPECT_GT(r->keptFraction(), 0.98);
    EXPECT_LE(r->keptFraction(), 1.0 + 1e-3);
    EXPECT_GE(r->fragments.size(), static_cast<std::size_t>(c.pieces * 9 / 10));
    double total = 0.0;
    for (const core::TriangleMesh& fragment : r->fragments) {
      ASSERT_TRUE(core::requireClosedOriented(core::analyzeTopology(fragment)).ok());
      // No speck rides along with a fragment: a solid shell of a crumb's volume is a crumb, dropped and
      // counted (the level set's crossing closes such specks where the solid is a voxel thin).
      for (const core::Shell& shell : core::findShells(fragment)) {
        if (shell.cavity) continue;
        EXPECT_GE(shell.volume, options.minVolumeFraction * r->solidVolume);
      }
      Result<core::MassProperties> mp = core::computeMassProperties(fragment);
      ASSERT_TRUE(mp.ok()) << mp.error().message;
      total += mp->volume;
    }
    EXPECT_NEAR(total, r->keptVolume, 1e-6 * r->solidVolume);
  }
}

}  // namespace
}  // namespace shapedb
