#include <set>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/collision.h>
#include <shapedb/volume/families.h>

namespace shapedb::volume {
namespace {

TEST(Families, EveryShapeOfEveryFamilyIsAValidClosedSolidAndDeterministic) {
  for (Family family : generatedFamilies()) {
    for (std::uint32_t i = 0; i < 40; ++i) {
      const ShapeSpec spec = familySpec(family, i);
      auto mesh = makeFamilyShape(spec);
      ASSERT_TRUE(mesh.ok()) << spec.name();
      ASSERT_TRUE(core::validateMesh(*mesh).ok()) << spec.name();
      auto mass = core::computeMassProperties(*mesh);
      ASSERT_TRUE(mass.ok()) << spec.name() << ": " << mass.error().message;
      EXPECT_GT(mass->volume, 1e-4) << spec.name();
      auto again = makeFamilyShape(familySpec(family, i));
      EXPECT_EQ(again->vertices, mesh->vertices) << spec.name();
      EXPECT_EQ(again->triangles, mesh->triangles) << spec.name();
    }
  }
}

TEST(Families, SweepParametersStayInTheirDomainAndCatalogSplitsEvenly) {
  for (std::uint32_t i = 0; i < 1000; ++i) {
    const ShapeSpec box = familySpec(Family::kBox, i);
    EXPECT_LE(box.params.x(), 1.0);
    EXPECT_GE(box.params.y(), 0.1 - 1e-12);
    EXPECT_GE(box.params.x(), box.params.y());
    const ShapeSpec cone = familySpec(Family::kCone, i);
    EXPECT_GE(cone.params.y(), 0.1 - 1e-12);
    EXPECT_LE(cone.params.y(), 10.0 + 1e-12);
  }
  const auto catalog = buildCatalog(4500, generatedFamilies());
  ASSERT_EQ(catalog.size(), 4500u);
  std::set<std::string> names;
  for (const ShapeSpec& s : catalog)
    names.insert(s.name());
  EXPECT_EQ(names.size(), 4500u);
  EXPECT_EQ(catalog.front().name(), "box-00000");
  EXPECT_EQ(catalog.back().name(), "shard-00641");  // 4500 = 7 × 642 + 6: the first six take one more
}

TEST(Families, ParseFamiliesNamesTheBadOne) {
  auto ok = parseFamilies("box,shard");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->size(), 2u);
  EXPECT_EQ(parseFamilies("all")->size(), 7u);
  auto bad = parseFamilies("box,torus");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("'torus'"), std::string::npos);
  EXPECT_FALSE(parseFamilies("box,box").ok());
  EXPECT_FALSE(parseFamilies("user").ok());
}

TEST(Collision, ABoxIsOneBoxAndASphereIsCoveredWithLittleOvershoot) {
  auto box = fitCollisionCompound(core::makeBox(core::Vec3(2.0, 1.0, 0.5)));
  ASSERT_TRUE(box.ok()) << box.error().message;
  ASSERT_EQ(box->shapes.size(), 1u);
  EXPECT_EQ(box->shapes[0].type, core::CollisionShape::Type::kBox);
  EXPECT_GT(box->coverage, 0.99);
  EXPECT_LT(box->overshoot, 0.01);
  EXPECT_NEAR(box->shapes[0].volume(), 1.0, 0.1);

  auto sphere = fitCollisionCompound(core::makeIcosphere(1.0, 3));
  ASSERT_TRUE(sphere.ok());
  // A sphere, or a capsule so short it is one (voxel centres straddle the true centre).
  EXPECT_LT(sphere->shapes.front().halfLength, 0.1);
  EXPECT_GT(sphere->coverage, 0.9);
  EXPECT_LT(sphere->overshoot, 0.05);

  // A capsule along x: mostly covered, little overshoot. (Voxel centres sit half a voxel off its axis,
  // so the fitted capsules are thinner than the real one: a known weakness, see the issue 4 note.)
  const core::TriangleMesh capsule = core::transformed(core::makeCapsule(0.3, 2.0, 24, 8), [] {
    core::Mat4 t = core::Mat4::Identity();
    t.topLeftCorner<3, 3>() << 0, 0, 1, 0, 1, 0, -1, 0, 0;
    return t;
  }());
  auto c = fitCollisionCompound(capsule);
  ASSERT_TRUE(c.ok());
  EXPECT_GT(c->coverage, 0.8);
  EXPECT_LT(c->overshoot, 0.05);
  std::printf("capsule: %zu shapes, coverage %.3f, overshoot %.3f\n", c->shapes.size(), c->coverage,
              c->overshoot);
}

}  // namespace
}  // namespace shapedb::volume
