// Surfaces that are not closed solids made into closed ones (volume/repair.h): a closed solid keeps its
// volume, holes punched out of one are shut with the volume it had, overlapping solids become their
// union, and what cannot be closed is an error that says why.

#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/repair.h>

namespace shapedb::volume {
namespace {

using core::TriangleMesh;
using core::Vec3;

/// What a repair promises: closed, consistently oriented, wound outward, and not passing through itself
/// (a simplification that folded a thin wall through another was a repair that needed repairing).
bool closedAndOriented(const TriangleMesh& mesh) {
  return core::validateMesh(mesh).ok() && core::requireClosedOriented(core::analyzeTopology(mesh)).ok() &&
         core::computeSignedVolume(mesh) > 0.0 && core::findSelfIntersections(mesh).empty();
}

/// `mesh` without the triangles whose centroids lie within `radius` of any of `centres`.
TriangleMesh withHoles(const TriangleMesh& mesh, const std::vector<Vec3>& centres, double radius) {
  TriangleMesh out;
  out.vertices = mesh.vertices;
  for (const auto& t : mesh.triangles) {
    const Vec3 c = (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
    bool cut = false;
    for (const Vec3& centre : centres)
      cut = cut || (c - centre).norm() < radius;
    if (!cut) out.triangles.push_back(t);
  }
  return out;
}

TEST(Repair, AClosedSolidKeepsItsVolumeWithinOnePerCent) {
  const core::Mat4 turn = [] {
    core::Mat4 m = core::Mat4::Identity();
    m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    m.topRightCorner<3, 1>() = Vec3(120.0, -40.0, 7.0);  // far from the origin, as scans are
    return m;
  }();
  for (const TriangleMesh& solid :
       {core::makeBox(Vec3(2.0, 1.0, 0.5)), core::transformed(core::makeBox(Vec3(2.0, 1.0, 0.5)), turn),
        core::makeUvEllipsoid(Vec3(1.0, 0.6, 0.4), 48, 24), core::makeCapsule(0.2, 1.5, 32, 8)}) {
    Result<RepairedSurface> repaired = repairSurface(solid);
    ASSERT_TRUE(repaired.ok()) << repaired.error().message;
    const RepairReport& r = repaired->report;
    EXPECT_TRUE(closedAndOriented(repaired->mesh));
    EXPECT_EQ(r.holes, 0u);
    ASSERT_TRUE(r.volumeBefore.has_value());
    const double volume = core::computeSignedVolume(solid);
    EXPECT_NEAR(*r.volumeBefore, volume, 1e-12 * volume);
    EXPECT_NEAR(r.volumeAfter / volume, 1.0, 0.01);
    EXPECT_NEAR(r.areaAfter / r.areaBefore, 1.0, 0.03);
    EXPECT_NEAR(r.closingRadius, 1.5 * r.voxelSize, 1e-12);
    EXPECT_LE(r.trianglesAfter, RepairOptions{}.maxTriangles);
    std::printf("closed solid of %zu triangles: volume %+.3f %%, area %+.3f %%, %zu triangles\n",
                r.trianglesBefore, 100.0 * (r.volumeAfter / volume - 1.0),
                100.0 * (r.areaAfter / r.areaBefore - 1.0), r.trianglesAfter);
  }
}

TEST(Repair, HolesPunchedOutOfAClosedSolidAreShutWithItsVolume) {
  const TriangleMesh solid = core::makeUvEllipsoid(Vec3(1.0, 0.7, 0.5), 64, 32);
  const TriangleMesh open =
      withHoles(solid, {Vec3(1.0, 0.0, 0.0), Vec3(0.0, 0.0, 0.5), Vec3(-0.6, 0.56, 0.0)}, 0.06);
  ASSERT_LT(open.triangles.size(), solid.triangles.size());
  ASSERT_FALSE(core::analyzeTopology(open).isClosed());
  Result<RepairedSurface> repaired = repairSurface(open);
  ASSERT_TRUE(repaired.ok()) << repaired.error().message;
  const RepairReport& r = repaired->report;
  EXPECT_TRUE(closedAndOriented(repaired->mesh));
  EXPECT_EQ(r.holes, 3u);
  EXPECT_FALSE(r.volumeBefore.has_value()) << "an open surface encloses no volume";
  EXPECT_GT(r.closingRadius, 0.06) << "wide enough for the widest hole";
  const core::MassProperties before = *core::computeMassProperties(solid);
  const core::MassProperties after = *core::computeMassProperties(repaired->mesh);
  EXPECT_NEAR(after.volume / before.volume, 1.0, 0.02);
  EXPECT_LT((after.centerOfMass - before.centerOfMass).norm(), 0.01);
  EXPECT_LT((after.inertia - before.inertia).norm(), 0.03 * before.inertia.norm());
  std::printf("three holes shut: volume %+.2f %% of the closed solid's, closing radius %.3f\n",
              100.0 * (after.volume / before.volume - 1.0), r.closingRadius);
}

// Two overlapping boxes written as one mesh (self-intersecting, as exports of several parts are): their
// union, 2 × 1 + 1 × 1 − the overlap.
TEST(Repair, OverlappingSolidsBecomeTheirUnion) {
  TriangleMesh both = core::makeBox(Vec3(1.0, 1.0, 1.0));
  core::Mat4 shift = core::Mat4::Identity();
  shift.topRightCorner<3, 1>() = Vec3(0.5, 0.25, 0.0);
  core::append(both, core::transformed(core::makeBox(Vec3(1.0, 1.0, 1.0)), shift));
  Result<RepairedSurface> repaired = repairSurface(both);
  ASSERT_TRUE(repaired.ok()) << repaired.error().message;
  EXPECT_TRUE(closedAndOriented(repaired->mesh));
  const double unionVolume = 2.0 - 0.5 * 0.75 * 1.0;
  EXPECT_NEAR(repaired->report.volumeAfter / unionVolume, 1.0, 0.01);
}

// The whole repair at a coarse resolution, cheap enough for the sanitizers: an ellipsoid with two holes
// comes back closed, with about its volume.
TEST(Repair, ACoarseRepairOfAnEllipsoidWithHolesIsClosed) {
  const TriangleMesh solid = core::makeUvEllipsoid(Vec3(1.0, 0.8, 0.6), 24, 12);
  const TriangleMesh open = withHoles(solid, {Vec3(1.0, 0.0, 0.0), Vec3(0.0, 0.8, 0.0)}, 0.16);
  Result<RepairedSurface> repaired = repairSurface(open, {.resolution = 40, .maxHoleFraction = 0.3});
  ASSERT_TRUE(repaired.ok()) << repaired.error().message;
  EXPECT_TRUE(closedAndOriented(repaired->mesh));
  EXPECT_EQ(repaired->report.holes, 2u);
  EXPECT_NEAR(repaired->report.volumeAfter / core::computeSignedVolume(solid), 1.0, 0.05);
  // The same a millionth the size (a part in metres read as millimetres): the same answer, to scale.
  core::Mat4 shrink = core::Mat4::Identity();
  shrink.topLeftCorner<3, 3>() *= 1e-6;
  Result<RepairedSurface> tiny =
      repairSurface(core::transformed(open, shrink), {.resolution = 40, .maxHoleFraction = 0.3});
  ASSERT_TRUE(tiny.ok()) << tiny.error().message;
  EXPECT_TRUE(closedAndOriented(tiny->mesh));
  EXPECT_NEAR(tiny->report.volumeAfter / (1e-18 * repaired->report.volumeAfter), 1.0, 1e-3);
}

TEST(Repair, WhatCannotBeClosedIsAnErrorThatSaysWhy) {
  // A hole a third of the solid across.
  const TriangleMesh solid = core::makeUvEllipsoid(Vec3(1.0, 1.0, 1.0), 32, 16);
  Result<RepairedSurface> wide = repairSurface(withHoles(solid, {Vec3(0.0, 0.0, 1.0)}, 0.35));
  ASSERT_FALSE(wide.ok());
  EXPECT_EQ(wide.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(wide.error().message.find("wider than the repair closes"), std::string::npos)
      << wide.error().message;
  // A single sheet: its boundary is one loop as wide as the sheet.
  TriangleMesh sheet;
  sheet.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  sheet.triangles = {{0, 1, 2}, {0, 2, 3}};
  Result<RepairedSurface> open = repairSurface(sheet, {.resolution = 64, .maxHoleFraction = 0.5});
  ASSERT_FALSE(open.ok());
  EXPECT_EQ(open.error().code, ErrorCode::kInvalidArgument) << open.error().message;
  // The same sheet twice, back to back: no boundary, and nothing enclosed.
  sheet.triangles.push_back({0, 2, 1});
  sheet.triangles.push_back({0, 3, 2});
  Result<RepairedSurface> flat = repairSurface(sheet, {.resolution = 64});
  ASSERT_FALSE(flat.ok());
  EXPECT_EQ(flat.error().code, ErrorCode::kParse) << flat.error().message;
  EXPECT_NE(flat.error().message.find("no closed surface"), std::string::npos) << flat.error().message;
  // Options and inputs out of range.
  EXPECT_EQ(repairSurface(solid, {.resolution = 8}).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(repairSurface(TriangleMesh{}).error().code, ErrorCode::kEmptyMesh);
}

}  // namespace
}  // namespace shapedb::volume
