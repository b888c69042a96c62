// The morph (morph.h): an entry's tets carried onto another surface, every tet kept positive or the morph
// refused.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/physics.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/morph.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume {
namespace {

using core::TetMesh;
using core::Vec3;

TEST(Morph, TetQualityIsOneForTheRegularTetAndNegativeWhenInverted) {
  TetMesh regular;
  regular.nodes = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  regular.tets = {{0, 1, 2, 3}};
  if (core::tetVolume(regular, 0) < 0.0) std::swap(regular.tets[0][2], regular.tets[0][3]);
  EXPECT_NEAR(tetQuality(regular, 0), 1.0, 1e-12);
  TetMesh inverted = regular;
  std::swap(inverted.tets[0][2], inverted.tets[0][3]);
  EXPECT_NEAR(tetQuality(inverted, 0), -1.0, 1e-12);
  TetMesh flat = regular;
  flat.nodes[3] = (flat.nodes[0] + flat.nodes[1] + flat.nodes[2]) / 3.0;
  EXPECT_NEAR(tetQuality(flat, 0), 0.0, 1e-9);  // the cube root of a round-off volume
}

TEST(Morph, OntoItsOwnSurfaceNothingMoves) {
  const core::TriangleMesh surface = core::makeUvEllipsoid(Vec3(1.0, 0.7, 0.4), 16, 8);
  Result<TetMesh> tets = tetrahedralize(surface, entryMeshing(ElementOrder::kQuadratic));
  ASSERT_TRUE(tets.ok()) << tets.error().message;
  Result<MorphResult> morphed = morphTetMesh(*tets, surface);
  ASSERT_TRUE(morphed.ok()) << morphed.error().message;
  EXPECT_LT(morphed->report.maxBoundaryMove, 1e-9);
  EXPECT_LT(morphed->report.meanTargetDistance, 1e-9);
  for (std::size_t v = 0; v < tets->nodeCount(); ++v)
    EXPECT_LT((morphed->mesh.nodes[v] - tets->nodes[v]).norm(), 1e-9) << "node " << v;
}

// Randomized targets, some too far to reach: the morph either keeps every tet positive (and above its
// bound) or refuses with kDegenerateFace and a reason; it never returns an inverted tet.
TEST(Morph, EveryTetStaysPositiveOrTheMorphIsRefused) {
  Result<TetMesh> tets = tetrahedralize(core::makeUvEllipsoid(Vec3(1.0, 0.8, 0.6), 16, 8),
                                        entryMeshing(ElementOrder::kQuadratic));
  ASSERT_TRUE(tets.ok()) << tets.error().message;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> aspect(0.2, 2.5), twist(-1.5, 1.5);
  int refused = 0, morphed = 0;
  for (int trial = 0; trial < 12; ++trial) {
    // A box of random proportions, twisted about x: far from the ellipsoid in places.
    core::TriangleMesh target = core::makeBox(Vec3(2.0 * aspect(rng), aspect(rng), aspect(rng)));
    const double k = twist(rng);
    for (Vec3& p : target.vertices) {
      const double a = k * p.x();
      p = Vec3(p.x(), std::cos(a) * p.y() - std::sin(a) * p.z(), std::sin(a) * p.y() + std::cos(a) * p.z());
    }
    // Trial 0 is out of reach by construction: proportions 100:1:1, which no prestretch keeps a tet through.
    if (trial == 0) target = core::makeBox(Vec3(10.0, 0.1, 0.1));
    Result<MorphResult> r = morphTetMesh(*tets, target, {.maxIncrements = 2});
    if (!r) {
      ++refused;
      EXPECT_EQ(r.error().code, ErrorCode::kDegenerateFace) << r.error().message;
      EXPECT_NE(r.error().message.find("quality"), std::string::npos) << r.error().message;
      continue;
    }
    ++morphed;
    ASSERT_EQ(r->mesh.tets, tets->tets);
    for (std::size_t t = 0; t < r->mesh.tetCount(); ++t)
      ASSERT_GT(core::tetVolume(r->mesh, t), 0.0) << "trial " << trial << " tet " << t;
    EXPECT_GT(r->report.worstQuality, 0.0);
  }
  std::printf("%d morphed, %d refused\n", morphed, refused);
  EXPECT_GE(refused, 1);  // the 100:1:1 box
  EXPECT_GE(morphed, 6);
}

// The shared preparation against its oracle: a target prepared once and seen through an orthogonal frame
// (a query's candidate entries each see its surface so) morphs a mesh as a copy of the surface carried
// into that frame does. Random rotations, and one with a reflection (whose copy is wound again outward).
TEST(Morph, APreparedTargetSeenThroughAFrameMorphsAsACopyCarriedIntoIt) {
  Result<TetMesh> tets = tetrahedralize(core::makeUvEllipsoid(Vec3(1.0, 0.8, 0.6), 16, 8),
                                        entryMeshing(ElementOrder::kQuadratic));
  ASSERT_TRUE(tets.ok()) << tets.error().message;
  // A box of other proportions, twisted about x: the morph has all three of its steps to do.
  core::TriangleMesh surface = core::makeBox(Vec3(2.2, 1.1, 0.7));
  for (Vec3& p : surface.vertices) {
    const double a = 0.4 * p.x();
    p = Vec3(p.x(), std::cos(a) * p.y() - std::sin(a) * p.z(), std::sin(a) * p.y() + std::cos(a) * p.z());
  }
  Result<MorphTarget> prepared = MorphTarget::prepare(surface);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message;
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 4; ++trial) {
    core::Mat3 frame = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
                           .normalized()
                           .toRotationMatrix();
    if (trial == 3) frame.col(2) *= -1.0;
    core::Mat4 map = core::Mat4::Identity();
    map.topLeftCorner<3, 3>() = frame;
    const TetMesh& mesh = *tets;
    Result<MorphResult> viewed = morphTetMesh(mesh, MorphTarget::View(*prepared, frame));
    Result<MorphResult> copied = morphTetMesh(mesh, core::transformed(surface, map));
    ASSERT_TRUE(viewed.ok() && copied.ok()) << "trial " << trial;
    EXPECT_GT(viewed->report.maxBoundaryMove, 0.1) << "trial " << trial;
    EXPECT_NEAR(viewed->report.meanTargetDistance, copied->report.meanTargetDistance, 1e-9)
        << "trial " << trial;
    EXPECT_NEAR(viewed->report.projected, copied->report.projected, 1e-9) << "trial " << trial;
    EXPECT_EQ((viewed->report.stretch - copied->report.stretch).norm() < 1e-9, true) << "trial " << trial;
    for (std::size_t v = 0; v < mesh.nodeCount(); ++v)
      ASSERT_LT((viewed->mesh.nodes[v] - copied->mesh.nodes[v]).norm(), 1e-8)
          << "trial " << trial << " node " << v;
  }
}

// A plan (MorphOptions::plan) keeps the first morph's layout for the next morphs of the same tets: each
// morph with it is the morph without one, to the bit (nodes and report), onto any target, for the plan's
// tets and for others, which leave it as it was; morphs sharing it at once too.
TEST(Morph, APlanServesItsTetsOntoAnyTargetAndChangesNoBit) {
  Result<TetMesh> ellipsoid = tetrahedralize(core::makeUvEllipsoid(Vec3(1.0, 0.8, 0.6), 16, 8),
                                             entryMeshing(ElementOrder::kQuadratic));
  Result<TetMesh> box =
      tetrahedralize(core::makeBox(Vec3(1.6, 1.0, 0.8)), entryMeshing(ElementOrder::kQuadratic));
  ASSERT_TRUE(ellipsoid.ok() && box.ok());
  std::vector<core::TriangleMesh> targets{core::makeBox(Vec3(2.2, 1.1, 0.7)),
                                          core::makeCylinder(0.6, 1.8, 24),
                                          core::makeUvEllipsoid(Vec3(1.2, 0.5, 0.9), 20, 10)};
  for (Vec3& p : targets[0].vertices) {  // twisted: every step of the morph has work to do
    const double a = 0.4 * p.x();
    p = Vec3(p.x(), std::cos(a) * p.y() - std::sin(a) * p.z(), std::sin(a) * p.y() + std::cos(a) * p.z());
  }
  const auto expectSame = [](const Result<MorphResult>& a, const Result<MorphResult>& b,
                             const std::string& what) {
    ASSERT_TRUE(a.ok() && b.ok()) << what;
    EXPECT_EQ(a->mesh.nodes, b->mesh.nodes) << what;
    EXPECT_EQ(a->report.meanTargetDistance, b->report.meanTargetDistance) << what;
    EXPECT_EQ(a->report.worstQuality, b->report.worstQuality) << what;
    EXPECT_EQ(a->report.increments, b->report.increments) << what;
    EXPECT_EQ(a->report.projected, b->report.projected) << what;
  };
  MorphPlan plan;
  MorphOptions planned;
  planned.plan = &plan;
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const std::string what = "target " + std::to_string(t);
    expectSame(morphTetMesh(*ellipsoid, targets[t], planned), morphTetMesh(*ellipsoid, targets[t]),
               what + ", the plan's tets");
    EXPECT_TRUE(plan.ready());
    expectSame(morphTetMesh(*box, targets[t], planned), morphTetMesh(*box, targets[t]),
               what + ", other tets");
  }
  Result<MorphTarget> prepared = MorphTarget::prepare(targets[1]);
  ASSERT_TRUE(prepared.ok());
  const Result<MorphResult> alone = morphTetMesh(*ellipsoid, prepared->view());
  std::vector<Result<MorphResult>> together(4, Error{ErrorCode::kInvalidArgument, "not run"});
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < together.size(); ++i)
    threads.emplace_back([&, i] { together[i] = morphTetMesh(*ellipsoid, prepared->view(), planned); });
  for (std::thread& thread : threads)
    thread.join();
  for (const Result<MorphResult>& r : together)
    expectSame(r, alone, "at once");
}

TEST(Morph, BadInputIsAnError) {
  Result<TetMesh> tets = tetrahedralize(core::makeBox(Vec3(1, 1, 1)), entryMeshing(ElementOrder::kQuadratic));
  ASSERT_TRUE(tets.ok()) << tets.error().message;
  EXPECT_EQ(morphTetMesh(*tets, core::TriangleMesh{}).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(morphTetMesh(*tets, core::makeBox(Vec3(1, 1, 1)), {.minQuality = 0.0}).error().code,
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(morphTetMesh(TetMesh{}, core::makeBox(Vec3(1, 1, 1))).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(MorphTarget::prepare(core::TriangleMesh{}).error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace shapedb::volume
