#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/index.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/describe.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/tetrahedralize.h>

#include "test_support.h"

namespace shapedb::volume {
namespace {

/// The families meshed from level sets: tens of milliseconds a shape, so the sweeps below take fewer.
bool fromLevelSets(Family family) {
  return family == Family::kLimbed || family == Family::kUnion;
}

/// The canonical frame of a closed shape, as a query's is found.
core::Normalization normalizationOf(const core::TriangleMesh& mesh) {
  return *core::normalize(mesh, *core::computeMassProperties(mesh));
}

std::vector<Family> nonConvexFamilies() {
  const auto all = generatedFamilies(), convex = convexFamilies();
  return {all.begin() + static_cast<std::ptrdiff_t>(convex.size()), all.end()};
}

TEST(Families, EveryShapeOfEveryFamilyIsOneValidClosedSolidAndDeterministic) {
  for (Family family : generatedFamilies()) {
    const std::uint32_t count = fromLevelSets(family) ? 4 : 16;
    for (std::uint32_t i = 0; i < count; ++i) {
      const ShapeSpec spec = familySpec(family, i);
      auto mesh = makeFamilyShape(spec);
      ASSERT_TRUE(mesh.ok()) << spec.name() << ": " << mesh.error().message;
      ASSERT_TRUE(core::validateMesh(*mesh).ok()) << spec.name();
      const core::TopologyReport topology = core::analyzeTopology(*mesh);
      ASSERT_TRUE(core::requireClosedOriented(topology).ok()) << spec.name();
      EXPECT_EQ(topology.components, 1u) << spec.name();
      auto mass = core::computeMassProperties(*mesh, topology);
      ASSERT_TRUE(mass.ok()) << spec.name() << ": " << mass.error().message;
      EXPECT_GT(mass->volume, 1e-4) << spec.name();
      auto again = makeFamilyShape(familySpec(family, i));
      ASSERT_TRUE(again.ok()) << spec.name();
      EXPECT_EQ(again->vertices, mesh->vertices) << spec.name();
      EXPECT_EQ(again->triangles, mesh->triangles) << spec.name();
    }
  }
}

// A level set simplified down to a few hundred triangles can fold a thin limb into its neighbour:
// limbed-00114 of the sweep (at the quadratic catalog's resolution) came out passing through itself,
// and TetGen crashed on it. Such a draw is drawn again.
TEST(Families, ALevelSetShapeNeverPassesThroughItself) {
  const ShapeResolution catalog{.segments = 12, .stacks = 6, .stoneSubdivisions = 1};
  const ShapeSpec spec = familySpec(Family::kLimbed, 114);
  auto mesh = makeFamilyShape(spec, catalog);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  EXPECT_TRUE(core::findSelfIntersections(*mesh).empty()) << spec.name();
  EXPECT_TRUE(core::requireClosedOriented(core::analyzeTopology(*mesh)).ok()) << spec.name();
  auto meshed = tetrahedralize(*mesh, {});
  EXPECT_TRUE(meshed.ok()) << spec.name() << ": " << meshed.error().message;
}

// A union's surface is simplified to its own triangle budget (ShapeResolution::unionTrianglesPerSegment),
// as far as keeping it one closed solid allows; a smaller budget never gives more triangles.
TEST(Families, AUnionIsSimplifiedToItsOwnTriangleBudget) {
  std::size_t fewer = 0;
  for (std::uint32_t i = 0; i < 6; ++i) {
    const ShapeSpec spec = familySpec(Family::kUnion, i);
    auto coarse = makeFamilyShape(spec, {.segments = 12, .unionTrianglesPerSegment = 12});
    auto fine = makeFamilyShape(spec, {.segments = 12, .unionTrianglesPerSegment = 20});
    ASSERT_TRUE(coarse.ok() && fine.ok()) << spec.name();
    EXPECT_TRUE(core::requireClosedOriented(core::analyzeTopology(*coarse)).ok()) << spec.name();
    EXPECT_LE(coarse->triangles.size(), fine->triangles.size()) << spec.name();
    fewer += coarse->triangles.size() < fine->triangles.size() ? 1 : 0;
  }
  EXPECT_GT(fewer, 0u) << "the budget made no union coarser";
}

// The holes of a handle, a hook's gap, a tube's bore: what makes these families non-convex is there. A
// ring and a tube are of genus 1 (Euler characteristic 0), a plate with n holes of genus n; the others
// of genus 0 but for unions and limbed bodies, whose limbs may close loops.
TEST(Families, TheNonConvexFamiliesHaveTheirHolesAndHollows) {
  for (std::uint32_t i = 0; i < 8; ++i) {
    const auto ring = makeFamilyShape(familySpec(Family::kRing, i));
    ASSERT_TRUE(ring.ok());
    EXPECT_EQ(core::analyzeTopology(*ring).eulerCharacteristic(), 0) << "ring " << i;
    const auto rod = makeFamilyShape(familySpec(Family::kRod, i));
    ASSERT_TRUE(rod.ok());
    EXPECT_EQ(core::analyzeTopology(*rod).eulerCharacteristic(), 2) << "rod " << i;
    const auto beam = makeFamilyShape(familySpec(Family::kBeam, i));
    ASSERT_TRUE(beam.ok());
    EXPECT_EQ(core::analyzeTopology(*beam).eulerCharacteristic(), 2) << "beam " << i;
  }
  for (std::uint32_t i = 0; i < 4; ++i) {
    const ShapeSpec plate = familySpec(Family::kHoled, i);
    const auto holed = makeFamilyShape(plate);
    ASSERT_TRUE(holed.ok());
    const long genus = (2 - core::analyzeTopology(*holed).eulerCharacteristic()) / 2;
    EXPECT_EQ(genus, static_cast<long>(plate.params.z())) << plate.name();
    // Shells: a cup, a bowl and an open box hold a cavity open at one end (genus 0, and their volume
    // well under their hull's); a tube is open at both (genus 1).
    const ShapeSpec shell = familySpec(Family::kShell, i);
    const auto mesh = makeFamilyShape(shell);
    ASSERT_TRUE(mesh.ok());
    EXPECT_EQ(core::analyzeTopology(*mesh).eulerCharacteristic(), i % 4 == 2 ? 0 : 2) << shell.name();
    const core::Vec3 extent = core::computeBounds(*mesh).extent();
    EXPECT_LT(core::computeMassProperties(*mesh)->volume, 0.8 * extent.prod()) << shell.name();
  }
}

// TetGen meshes every non-convex family as the build will (quadratic entries' bounds), and the tets
// fill the surface. (Release builds only, as the next: the sanitizer preset covers TetGen and describe
// elsewhere, and the families' own code above.)
TEST(Families, TetGenMeshesASampleOfEveryNonConvexFamily) {
  const TetrahedralizeOptions options = entryMeshing(ElementOrder::kQuadratic);
  const ShapeResolution resolution{.segments = 16, .stacks = 8};
  for (Family family : nonConvexFamilies()) {
    for (std::uint32_t i : {0u, 5u, 11u}) {
      const ShapeSpec spec = familySpec(family, i);
      auto mesh = makeFamilyShape(spec, resolution);
      ASSERT_TRUE(mesh.ok()) << spec.name();
      auto tets = tetrahedralize(*mesh, options);
      ASSERT_TRUE(tets.ok()) << spec.name() << ": " << tets.error().message;
      EXPECT_TRUE(core::validateTetMesh(*tets).ok()) << spec.name();
      const double surfaceVolume = core::computeMassProperties(*mesh)->volume;
      EXPECT_NEAR(core::computeTetMassProperties(*tets).volume, surfaceVolume, 1e-9 * surfaceVolume)
          << spec.name();
      std::printf("%s: %zu triangles, %zu tets\n", spec.name().c_str(), mesh->triangleCount(),
                  tets->tetCount());
    }
  }
}

// Every non-convex family's entries, queried with their own surface under a random similarity, come back
// as their own best match among the entries of every family.
TEST(Families, EveryNonConvexEntryFindsItselfUnderARandomSimilarity) {
  const core::DescriptorOptions options;  // the default: centroid-voxel, area-sampled
  Describer describer(options);
  std::vector<ShapeSpec> specs;
  for (Family family : generatedFamilies())
    for (std::uint32_t i = 0; i < (fromLevelSets(family) ? 3u : 6u); ++i)
      specs.push_back(familySpec(family, i));
  std::vector<core::TriangleMesh> meshes;
  core::IndexBuilder builder(options);
  for (std::size_t id = 0; id < specs.size(); ++id) {
    meshes.push_back(*makeFamilyShape(specs[id]));
    auto d = describer.describe(meshes.back(), normalizationOf(meshes.back()));
    ASSERT_TRUE(d.ok()) << specs[id].name();
    ASSERT_TRUE(builder.add(static_cast<core::EntryId>(id), *d).ok());
  }
  auto index = std::move(builder).build();
  ASSERT_TRUE(index.ok());
  std::mt19937_64 rng(24);
  int queried = 0;
  for (std::size_t id = 0; id < specs.size(); ++id) {
    if (specs[id].family < Family::kRing) continue;
    for (int trial = 0; trial < 3; ++trial) {
      const core::TriangleMesh query = core::transformed(meshes[id], test::randomSimilarity(rng));
      auto candidates = describer.describeCandidates(query, normalizationOf(query));
      ASSERT_TRUE(candidates.ok()) << specs[id].name();
      auto best = index->search(*candidates);
      ASSERT_TRUE(best.ok());
      EXPECT_EQ(best->front().entry, id)
          << specs[id].name() << " matched " << specs[best->front().entry].name();
      ++queried;
    }
  }
  EXPECT_EQ(queried, 3 * (6 * 6 + 2 * 3));  // limbed and union: 3 entries; the others 6
}

// A stone's subdivisions only refine its facets (ShapeResolution::stoneSubdivisions): at each level it is
// one valid closed solid of 20·4^k triangles, deterministic, inscribed in the finest one and within 15 %
// of its volume; and at the quadratic build's level (1, 80 triangles) each of a sweep of stones still finds
// itself under a random similarity among the others.
TEST(Families, AStoneIsTheSameStoneAtEverySubdivision) {
  const core::DescriptorOptions options;
  Describer describer(options);
  core::IndexBuilder builder(options);
  std::vector<core::TriangleMesh> coarse;
  for (std::uint32_t i = 0; i < 12; ++i) {
    const ShapeSpec spec = familySpec(Family::kStone, 7 * i);
    double finest = 0.0;
    for (int k = 4; k >= 1; --k) {
      const ShapeResolution resolution{.stoneSubdivisions = k};
      auto mesh = makeFamilyShape(spec, resolution);
      ASSERT_TRUE(mesh.ok()) << spec.name();
      EXPECT_EQ(mesh->triangleCount(), std::size_t{20} << (2 * k)) << spec.name();
      ASSERT_TRUE(core::validateMesh(*mesh).ok()) << spec.name();
      ASSERT_TRUE(core::requireClosedOriented(core::analyzeTopology(*mesh)).ok()) << spec.name();
      EXPECT_EQ(makeFamilyShape(spec, resolution)->vertices, mesh->vertices) << spec.name();
      const double volume = core::computeMassProperties(*mesh)->volume;
      if (k == 4) finest = volume;
      // An inscribed polyhedron: a little smaller, the less so the finer (an icosphere of 80 triangles
      // holds 88 % of its sphere).
      EXPECT_LE(volume, finest * (1.0 + 1e-12)) << spec.name() << " at " << k;
      EXPECT_GT(volume, 0.85 * finest) << spec.name() << " at " << k;
      if (k == 1) coarse.push_back(std::move(mesh).value());
    }
    auto d = describer.describe(coarse.back(), normalizationOf(coarse.back()));
    ASSERT_TRUE(d.ok()) << spec.name();
    ASSERT_TRUE(builder.add(i, *d).ok());
  }
  auto index = std::move(builder).build();
  ASSERT_TRUE(index.ok());
  std::mt19937_64 rng(80);
  for (std::uint32_t i = 0; i < coarse.size(); ++i) {
    const core::TriangleMesh query = core::transformed(coarse[i], test::randomSimilarity(rng));
    auto candidates = describer.describeCandidates(query, normalizationOf(query));
    ASSERT_TRUE(candidates.ok());
    auto best = index->search(*candidates);
    ASSERT_TRUE(best.ok());
    EXPECT_EQ(best->front().entry, i) << "stone " << i << " matched " << best->front().entry;
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
  EXPECT_EQ(catalog.back().name(), "union-00280");  // 4500 = 16 × 281 + 4: the first four take one more
  // The convex catalog of older databases is still what it was.
  const auto convex = buildCatalog(4500, convexFamilies());
  EXPECT_EQ(convex.back().name(), "fragment-00561");  // 4500 = 8 × 562 + 4
}

// A fragment is one Voronoi cell of its solid: convex (every vertex on the inner side of every face's
// plane), inside the solid's box (1, a, b), and smaller than the solid (the seeds are at least four).
TEST(Families, FragmentsAreConvexCellsInsideTheirSolid) {
  std::set<int> pieces;
  for (std::uint32_t i = 0; i < 60; ++i) {
    const ShapeSpec spec = familySpec(Family::kFragment, i);
    const double a = spec.params.x(), b = spec.params.y();
    ASSERT_GE(a, b) << spec.name();
    ASSERT_GE(b, 0.04 - 1e-12) << spec.name();
    ASSERT_LE(a, 1.0) << spec.name();
    ASSERT_GE(spec.params.z(), 4.0) << spec.name();
    ASSERT_LT(spec.params.z(), 100.0) << spec.name();
    pieces.insert(static_cast<int>(spec.params.z()));
    auto mesh = makeFamilyShape(spec);
    ASSERT_TRUE(mesh.ok()) << spec.name();
    const core::Vec3 half(1.0, a, b);
    for (const core::Vec3& p : mesh->vertices)
      ASSERT_TRUE((p.cwiseAbs().array() <= half.array() + 1e-9).all())
          << spec.name() << ": " << p.transpose();
    // Vertices sit on a 2⁻³⁰ lattice, so the planes of sliver triangles are noise: judge by the others.
    const auto mass = core::computeMassProperties(*mesh);
    ASSERT_TRUE(mass.ok()) << spec.name();
    for (const auto& t : mesh->triangles) {
      const core::Vec3& p0 = mesh->vertices[t[0]];
      const core::Vec3 cross = (mesh->vertices[t[1]] - p0).cross(mesh->vertices[t[2]] - p0);
      if (cross.norm() < 1e-3 * mass->area) continue;
      for (const core::Vec3& p : mesh->vertices)
        ASSERT_LE(cross.normalized().dot(p - p0), 1e-7) << spec.name() << ": not convex";
    }
    const double solidVolume = 8.0 * a * b;  // the box; the ellipsoid and cylinder are smaller
    EXPECT_LT(mass->volume, solidVolume) << spec.name();
  }
  EXPECT_GT(pieces.size(), 20u);  // the counts vary, not one value for every fragment
}

std::vector<std::string> names(const std::vector<ShapeSpec>& catalog) {
  std::vector<std::string> out;
  for (const ShapeSpec& spec : catalog)
    out.push_back(spec.name());
  return out;
}

// Largest remainders, judged by what they promise rather than recomputed: every family gets its share
// rounded down or up, the entries add up, and a family rounded up never has a smaller fraction than one
// rounded down (nor an equal one, coming after it).
TEST(Families, AWeightedCatalogSharesTheEntriesByLargestRemainders) {
  std::mt19937_64 rng(24);
  std::vector<Family> all(generatedFamilies().begin(), generatedFamilies().end());
  for (int trial = 0; trial < 300; ++trial) {
    std::shuffle(all.begin(), all.end(), rng);
    const std::size_t n = 1 + rng() % all.size();
    const std::vector<Family> families(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n));
    std::vector<unsigned> weights(n);
    for (unsigned& w : weights)
      w = 1 + static_cast<unsigned>(rng() % (trial % 3 == 0 ? 1 : kMaxFamilyWeight));
    const std::size_t entries = rng() % 5000;
    const auto catalog = buildCatalog(entries, families, weights);
    ASSERT_EQ(catalog.size(), entries);
    std::size_t total = 0;
    for (unsigned w : weights)
      total += w;
    std::vector<std::size_t> counts(n);
    for (std::size_t k = 0, f = 0; k < catalog.size(); ++k) {
      while (catalog[k].family != families[f])
        ++f;  // family by family, in the given order
      ASSERT_EQ(catalog[k].index, counts[f]) << "each family's sweep from index 0";
      ++counts[f];
    }
    std::vector<bool> up(n);
    for (std::size_t f = 0; f < n; ++f) {
      const std::size_t floor = entries * weights[f] / total;
      ASSERT_TRUE(counts[f] == floor || counts[f] == floor + 1) << "family " << f << " of trial " << trial;
      up[f] = counts[f] == floor + 1;
    }
    for (std::size_t x = 0; x < n; ++x)
      for (std::size_t y = 0; y < n; ++y) {
        if (!up[x] || up[y]) continue;
        const std::size_t fx = entries * weights[x] % total, fy = entries * weights[y] % total;
        EXPECT_TRUE(fx > fy || (fx == fy && x < y)) << "trial " << trial;
      }
    // No weights and equal weights are the same even catalog.
    if (std::ranges::all_of(weights, [&](unsigned w) { return w == weights[0]; })) {
      EXPECT_EQ(names(catalog), names(buildCatalog(entries, families))) << "trial " << trial;
    }
  }

  const FamilyMix mix = defaultFamilyMix();
  const auto catalog = buildCatalog(1400, mix.families, mix.weights);
  std::map<Family, int> perFamily;
  for (const ShapeSpec& s : catalog)
    ++perFamily[s.family];
  EXPECT_EQ(perFamily[Family::kBox], 88);  // 1400 = 16 × 87 + 8: the first eight take one more
  EXPECT_EQ(perFamily[Family::kFragment], 88);
  EXPECT_EQ(perFamily[Family::kRing], 87);
  EXPECT_EQ(perFamily[Family::kUnion], 87);
}

TEST(Families, AFamilyMixReadsWeightsAndNamesABadOne) {
  auto mix = parseFamilyMix("box,fragment:3,ring:100");
  ASSERT_TRUE(mix.ok()) << mix.error().message;
  EXPECT_EQ(mix->families, (std::vector<Family>{Family::kBox, Family::kFragment, Family::kRing}));
  EXPECT_EQ(mix->weights, (std::vector<unsigned>{1, 3, 100}));
  EXPECT_EQ(toString(*mix), "box,fragment:3,ring:100");
  auto all = parseFamilyMix("all");
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->families.size(), 16u);
  EXPECT_EQ(toString(*all), "all");
  EXPECT_EQ(parseFamilyMix(toString(*all))->weights, defaultFamilyMix().weights);
  for (const char* bad : {"box:0", "box:101", "box:", "box:1.5", "box:-1", "box:2x"}) {
    auto refused = parseFamilyMix(bad);
    ASSERT_FALSE(refused.ok()) << bad;
    EXPECT_NE(refused.error().message.find("weight of 'box'"), std::string::npos) << refused.error().message;
  }
  EXPECT_FALSE(parseFamilyMix("box:2,box").ok());
  EXPECT_FALSE(parseFamilies("box:2").ok());  // where weights mean nothing, they are refused
  EXPECT_TRUE(validFamilyWeights(2, std::vector<unsigned>{}));
  EXPECT_FALSE(validFamilyWeights(2, std::vector<unsigned>{1}));
  EXPECT_FALSE(validFamilyWeights(1, std::vector<unsigned>{0}));
}

TEST(Families, ParseFamiliesNamesTheBadOne) {
  auto ok = parseFamilies("box,shard");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->size(), 2u);
  EXPECT_EQ(parseFamilies("all")->size(), 16u);
  EXPECT_EQ(parseFamilies("ring,rod,beam,holed,shell,limbed,stone,union")->size(), 8u);
  for (Family f : generatedFamilies())
    EXPECT_EQ(parseFamily(toString(f)), f);
  auto bad = parseFamilies("box,torus");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("'torus'"), std::string::npos);
  EXPECT_NE(bad.error().message.find("limbed"), std::string::npos);  // the known ones are listed
  EXPECT_FALSE(parseFamilies("box,box").ok());
  EXPECT_FALSE(parseFamilies("user").ok());
}

}  // namespace
}  // namespace shapedb::volume
