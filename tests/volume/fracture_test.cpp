// Fracture: closed fragments that fill the solid, the same ones for the same seed, clear errors.

#include <cmath>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/fracture.h>
#include <shapedb/volume/tetrahedralize.h>

#include "support/test_support.h"

namespace shapedb::volume {
namespace {

using core::Vec3;

double volumeOf(const core::TriangleMesh& mesh) {
  auto mp = core::computeMassProperties(mesh);
  return mp.ok() ? mp->volume : -1.0;
}

TEST(Fracture, FragmentsAreClosedSolidsThatFillThePlateAndSphere) {
  const core::TriangleMesh plate = core::makeBox({0.4, 0.3, 0.02});
  const core::TriangleMesh sphere = core::makeIcosphere(0.1, 4);
  for (const auto* mesh : {&plate, &sphere}) {
    const double solid = volumeOf(*mesh);
    FractureOptions options;
    options.pieces = 12;
    options.seed = 7;
    options.resolution = 64;
    Result<FractureResult> r = fracture(*mesh, options);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_GE(r->fragments.size(), 10u);  // a seed's cell can hold a crumb only, on a thin plate
    EXPECT_LE(r->fragments.size(), 16u);  // or cut a fragment in two
    EXPECT_EQ(r->openDropped, 0u);
    double total = 0.0, previous = 1e300;
    const core::Bounds box = core::computeBounds(*mesh);
    for (const core::TriangleMesh& piece : r->fragments) {
      ASSERT_TRUE(core::validateMesh(piece).ok());
      const core::TopologyReport topology = core::analyzeTopology(piece);
      EXPECT_TRUE(topology.isClosed());
      EXPECT_TRUE(topology.isConsistentlyOriented());
      const double v = volumeOf(piece);  // positive: wound outward
      EXPECT_GT(v, 0.0);
      EXPECT_LE(v, previous);  // largest first
      previous = v;
      total += v;
      const core::Bounds b = core::computeBounds(piece);
      EXPECT_TRUE((b.min.array() >= box.min.array() - r->voxelSize).all());
      EXPECT_TRUE((b.max.array() <= box.max.array() + r->voxelSize).all());
    }
    // The level set rounds every edge by about a voxel, cut edges too: on this plate, 3 voxels thick at
    // this resolution, that is 6 %; the fragments never add volume.
    EXPECT_GT(total / solid, 0.9);
    EXPECT_LT(total / solid, 1.005);
    EXPECT_NEAR(r->keptVolume, total, 1e-9 * solid);
    EXPECT_NEAR(r->solidVolume, solid, 1e-9 * solid);
  }
}

/// A lopsided pebble 16 × 10 × 7 cm, and twelve pieces of it at a fixed resolution: the solid the tests of
/// where and how large a mesh is break.
core::TriangleMesh flatPebble() {
  core::Mat4 m = core::Mat4::Identity();
  m.diagonal().head<3>() = Vec3(1.6, 1.0, 0.7);
  return core::transformed(core::makeIcosphere(0.05, 3), m);
}

FractureOptions pebbleOptions() {
  FractureOptions options;
  options.pieces = 12;
  options.seed = 5;
  options.resolution = 64;
  return options;
}

TEST(Fracture, AMeshFarFromTheOriginBreaksAsAtTheOrigin) {
  // Scans and CAD exports sit hundreds of metres (or kilometres) from the origin: single-precision level
  // sets there tore fragments open and dropped them. Up to the offset, the fragments are the same.
  const core::TriangleMesh pebble = flatPebble();
  const FractureOptions options = pebbleOptions();
  const Result<FractureResult> here = fracture(pebble, options);
  ASSERT_TRUE(here.ok()) << here.error().message;
  EXPECT_EQ(here->openDropped, 0u);
  EXPECT_EQ(here->resolution, 64);  // as given
  EXPECT_EQ(fragmentName(7), "fragment-007");
  EXPECT_EQ(fragmentName(1234), "fragment-1234");
  for (const double offset : {1e3, 1e6}) {
    SCOPED_TRACE(offset);
    const Vec3 shift(offset, -0.7 * offset, 0.3 * offset);
    core::TriangleMesh far = pebble;
    for (Vec3& p : far.vertices)
      p += shift;
    const Result<FractureResult> there = fracture(far, options);
    ASSERT_TRUE(there.ok()) << there.error().message;
    EXPECT_EQ(there->openDropped, 0u);
    EXPECT_NEAR(there->keptFraction(), here->keptFraction(), 1e-6);
    ASSERT_EQ(there->fragments.size(), here->fragments.size());
    for (std::size_t i = 0; i < here->fragments.size(); ++i) {
      const core::MassProperties a = *core::computeMassProperties(here->fragments[i]);
      const core::MassProperties b = *core::computeMassProperties(there->fragments[i]);
      EXPECT_NEAR(b.volume / a.volume, 1.0, 1e-5) << i;
      EXPECT_LT((b.centerOfMass - shift - a.centerOfMass).norm(), 1e-3 * here->voxelSize) << i;
    }
  }
}

TEST(Fracture, AMeshOfAnySizeBreaksAsAtItsOwn) {
  // A part read in the wrong unit is microns across (or kilometres): OpenVDB refuses voxels that small
  // ("Non-zero scale values required"), so fracture works in a frame of the mesh's own size. Up to the
  // scale, the fragments are the same.
  const core::TriangleMesh pebble = flatPebble();
  const FractureOptions options = pebbleOptions();
  const Result<FractureResult> here = fracture(pebble, options);
  ASSERT_TRUE(here.ok()) << here.error().message;
  for (const double scale : {1e-7, 1e-4, 1e4}) {
    SCOPED_TRACE(scale);
    const core::TriangleMesh sized = core::transformed(pebble, [scale] {
      core::Mat4 m = core::Mat4::Identity();
      m.diagonal().head<3>() = Vec3::Constant(scale);
      return m;
    }());
    const Result<FractureResult> there = fracture(sized, options);
    ASSERT_TRUE(there.ok()) << there.error().message;
    EXPECT_EQ(there->openDropped, 0u);
    EXPECT_NEAR(there->voxelSize / here->voxelSize, scale, 1e-9 * scale);
    EXPECT_NEAR(there->keptFraction(), here->keptFraction(), 1e-6);
    EXPECT_NEAR(there->keptVolume / here->keptVolume, scale * scale * scale, 1e-5 * scale * scale * scale);
    ASSERT_EQ(there->fragments.size(), here->fragments.size());
    for (std::size_t i = 0; i < here->fragments.size(); ++i) {
      const core::MassProperties a = *core::computeMassProperties(here->fragments[i]);
      const core::MassProperties b = *core::computeMassProperties(there->fragments[i]);
      EXPECT_NEAR(b.volume / (a.volume * scale * scale * scale), 1.0, 1e-5) << i;
      EXPECT_LT((b.centerOfMass / scale - a.centerOfMass).norm(), 1e-3 * here->voxelSize) << i;
    }
  }
}

TEST(Fracture, TheAutomaticResolutionResolvesThinSolidsAndSmallPieces) {
  const core::TriangleMesh pebble = core::makeIcosphere(0.05, 3);
  EXPECT_EQ(automaticResolution(pebble, 20), 128);  // 128 voxels already put 16 across each piece
  // In 1,000 pieces: 16 voxels across a piece's (V/1000)^(1/3).
  const int many = automaticResolution(pebble, 1000);
  const double piece = std::cbrt(volumeOf(pebble) / 1000.0);
  const double longest = (core::computeBounds(pebble).max - core::computeBounds(pebble).min).maxCoeff();
  EXPECT_GT(many, 128);
  EXPECT_NEAR(longest / many, piece / 16.0, longest / many * 0.01);
  // A plate 3 mm thick and 0.36 m wide: 6 voxels across its thickness (2V/A, just under 3 mm).
  const core::TriangleMesh tray = core::makeBox({0.36, 0.36, 0.003});
  const int thin = automaticResolution(tray, 50);
  EXPECT_GE(0.36 / thin * 6.0, 0.0029);
  EXPECT_LE(0.36 / thin * 6.0, 0.003);
  EXPECT_EQ(automaticResolution(core::makeBox({1.0, 1.0, 1e-4}), 10), 1024);  // at most 1,024
}

TEST(Fracture, TheSameSeedGivesTheSameFragmentsAndAnotherSeedOthers) {
  const core::TriangleMesh plate = core::makeBox({0.4, 0.3, 0.02});
  FractureOptions options;
  options.pieces = 8;
  options.seed = 42;
  options.resolution = 48;
  const Result<FractureResult> a = fracture(plate, options);
  const Result<FractureResult> b = fracture(plate, options);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->fragments.size(), b->fragments.size());
  for (std::size_t i = 0; i < a->fragments.size(); ++i) {
    EXPECT_EQ(a->fragments[i].vertices, b->fragments[i].vertices) << i;
    EXPECT_EQ(a->fragments[i].triangles, b->fragments[i].triangles) << i;
  }
  options.seed = 43;
  const Result<FractureResult> c = fracture(plate, options);
  ASSERT_TRUE(c.ok());
  EXPECT_NE(c->fragments.front().vertices, a->fragments.front().vertices);
}

TEST(Fracture, BadInputIsAnError) {
  core::TriangleMesh open = core::makeBox({1, 1, 1});
  open.triangles.pop_back();
  Result<FractureResult> r = fracture(open);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotClosed);
  FractureOptions none;
  none.pieces = 0;
  EXPECT_EQ(fracture(core::makeBox({1, 1, 1}), none).error().code, ErrorCode::kInvalidArgument);
  FractureOptions coarse;
  coarse.resolution = 4;
  EXPECT_EQ(fracture(core::makeBox({1, 1, 1}), coarse).error().code, ErrorCode::kInvalidArgument);
  core::TriangleMesh inward = core::makeBox({1, 1, 1});
  for (auto& t : inward.triangles)
    std::swap(t[1], t[2]);
  EXPECT_EQ(fracture(inward).error().code, ErrorCode::kInsideOut);
}

TEST(Fracture, OnePieceIsTheWholeSolid) {
  const core::TriangleMesh sphere = core::makeIcosphere(1.0, 3);
  FractureOptions options;
  options.pieces = 1;
  options.resolution = 32;
  const Result<FractureResult> r = fracture(sphere, options);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r->fragments.size(), 1u);
  EXPECT_NEAR(volumeOf(r->fragments[0]) / volumeOf(sphere), 1.0, 0.03);
}

// A hollow ball (an inner shell wound inward, a cavity) breaks into pieces of its wall, not of the ball:
// the level set is the union of its solids less its cavities. (meshToLevelSet alone signed the cavity
// inside, and the fragments held twice the solid's volume.) Every fragment is the wall's: none reaches
// into the cavity.
TEST(Fracture, AHollowBallBreaksIntoPiecesOfItsWall) {
  const core::TriangleMesh hollow =
      test::withShell(core::makeIcosphere(1.0, 3), core::makeIcosphere(0.7, 3), core::Vec3::Zero(), true);
  FractureOptions options;
  options.pieces = 6;
  options.resolution = 48;
  const Result<FractureResult> r = fracture(hollow, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_GE(r->fragments.size(), 2u);
  double kept = 0.0;
  for (const core::TriangleMesh& f : r->fragments) {
    kept += volumeOf(f);
    for (const core::Vec3& v : f.vertices)
      ASSERT_GT(v.norm(), 0.7 - 2.0 * r->voxelSize);
  }
  EXPECT_NEAR(kept / volumeOf(hollow), 1.0, 0.03);
  EXPECT_NEAR(r->keptVolume / r->solidVolume, 1.0, 0.03);
}

TEST(Fracture, FragmentsAreSimplifiedAndTetGenFillsThemExactly) {
  // The raw level-set meshes hold edges a thousandth of a voxel long, on which TetGen failed or merged
  // nearly coplanar facets (moving the surface); simplified fragments mesh, and their tets fill them.
  FractureOptions options;
  options.pieces = 4;
  options.seed = 3;
  options.resolution = 64;
  options.maxTriangles = 1500;
  const Result<FractureResult> r = fracture(core::makeIcosphere(0.1, 4), options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_GE(r->fragments.size(), 3u);
  for (const core::TriangleMesh& piece : r->fragments) {
    EXPECT_LE(piece.triangles.size(), 1500u);
    TetrahedralizeOptions tetgen;
    tetgen.maxVolumeFraction = 1.0 / 200.0;
    const Result<core::TetMesh> tets = tetrahedralize(piece, tetgen);
    ASSERT_TRUE(tets.ok()) << tets.error().message;
    EXPECT_NEAR(core::computeTetMassProperties(*tets).volume / volumeOf(piece), 1.0, 1e-9);
  }
  options.maxTriangles = 0;  // the raw meshes: many more triangles
  const Result<FractureResult> raw = fracture(core::makeIcosphere(0.1, 4), options);
  ASSERT_TRUE(raw.ok());
  EXPECT_GT(raw->fragments.front().triangles.size(), 3000u);
}

TEST(Fracture, ACellThatHoldsTwoSeparatePartsGivesTwoFragments) {
  // Two boxes apart, one mesh: the single cell covers both, and segmentation must split them.
  core::TriangleMesh pair = core::makeBox({0.2, 0.2, 0.2});
  core::TriangleMesh other = core::makeBox({0.1, 0.1, 0.1});
  for (core::Vec3& p : other.vertices)
    p += core::Vec3(0.5, 0.0, 0.0);
  core::append(pair, other);
  FractureOptions options;
  options.pieces = 1;
  options.resolution = 96;
  const Result<FractureResult> r = fracture(pair, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->fragments.size(), 2u);
  EXPECT_NEAR(volumeOf(r->fragments[0]), 0.008, 0.0008);  // largest first
  EXPECT_NEAR(volumeOf(r->fragments[1]), 0.001, 0.0002);
  EXPECT_GT(core::computeBounds(r->fragments[1]).min.x(), 0.3);
}

}  // namespace
}  // namespace shapedb::volume
