#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/io/enrich.h>
#include <shapedb/io/store.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/fracture.h>

namespace shapedb::io {
namespace {

/// The first shapes of `family` at the default catalog's resolution, keyed together: surfaceKey (the
/// bits of their vertices, and their faces) of all of them as one mesh.
std::string familyKey(volume::Family family, std::uint32_t count) {
  const volume::ShapeResolution resolution = entryResolution(volume::ElementOrder::kQuadratic);
  core::TriangleMesh all;
  for (std::uint32_t i = 0; i < count; ++i) {
    const volume::ShapeSpec spec = volume::familySpec(family, i);
    auto mesh = volume::makeFamilyShape(spec, resolution);
    if (!mesh) return spec.name() + ": " + mesh.error().message;
    const auto offset = static_cast<std::uint32_t>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), mesh->vertices.begin(), mesh->vertices.end());
    for (auto t : mesh->triangles) {
      for (auto& corner : t)
        corner += offset;
      all.triangles.push_back(t);
    }
  }
  return surfaceKey(all);
}

// A catalog is its family generators run index by index, and the database a build writes is only the
// same file everywhere (shards, MPI ranks, a build resumed by another binary) if every build of the
// same source generates the same bits. CI runs this in the release preset (GCC, -O3, -march=native:
// AVX-512 and FMA where the machine has them) and in the sanitizer presets (Clang, -O1, the portable
// x86-64 instruction set). Three things made them differ, each of them mended where it was:
// - the order in which a call's arguments are drawn from a random generator (random_draws.h): Clang's
//   fragments, shards, stones and unions were other shapes than GCC's;
// - multiply-adds fused by the compiler under -march=native (CMakeLists.txt turns that off): 237 of the
//   1,400 default entries were meshed differently than by a portable build;
// - Eigen's own fused products under -march=native (core::transformPoint is written out): the unions'
//   placed primitives, and so their voxel size, differed in their last bits.
//
// The keys below were recorded from this source on x86-64 with FMA; a processor without it may round a
// few of the C library's sin, cos, exp and log differently (glibc picks their code by the processor). A
// change to a generator changes them on purpose: the catalog is then another catalog (a database built
// before holds other shapes under the same names), and the keys are recorded again from the failure's
// output.
TEST(Catalog, TheShapesAreTheSameBitsInEveryBuild) {
  const std::map<std::string, std::string> recorded = {
      {"box", "2223fd0bd4524555"},   {"ellipsoid", "bc9a7f8bc46aa4b0"}, {"cylinder", "f1f7a9df6b8f4e94"},
      {"cone", "7ca56015334f6d64"},  {"capsule", "68ac0fa5dd031451"},   {"prism", "76f3d9d69a0b44a9"},
      {"shard", "9a4b171d827f63e8"}, {"fragment", "2a49f4ab83ecc03d"},  {"ring", "a403e124aa750834"},
      {"rod", "25a16ffbacf587d9"},   {"beam", "bc30f0f66373ff8a"},      {"holed", "8ac45a1524e73f90"},
      {"shell", "650b387d8169b7e9"}, {"limbed", "76050aeddc0b27e9"},    {"stone", "811b6df440513b51"},
      {"union", "27e55cfdb443bdf1"},
  };
  std::ostringstream now;
  std::string differ;
  for (volume::Family family : volume::generatedFamilies()) {
    // The level-set families take tens of milliseconds a shape (more in the sanitizer builds).
    const bool levelSet = family == volume::Family::kLimbed || family == volume::Family::kUnion;
    const std::string name = volume::toString(family), key = familyKey(family, levelSet ? 3 : 12);
    now << "      {\"" << name << "\", \"" << key << "\"},\n";
    if (const auto it = recorded.find(name); it == recorded.end() || it->second != key)
      differ += (differ.empty() ? "" : ", ") + name;
  }
  EXPECT_TRUE(differ.empty()) << "these families' shapes are not the recorded ones: " << differ
                              << "\nThis build generates:\n"
                              << now.str();
}

// A fracture of one seed is documented to give the same fragments, to the bit (its seeds are drawn as the
// catalog's shapes are: random_draws.h). The keys of a plate's and an ellipsoid's fragments, recorded
// as the catalog's above.
TEST(Catalog, AFractureOfOneSeedIsTheSameFragmentsInEveryBuild) {
  const std::vector<std::vector<std::string>> recorded = {
      {"9c8842cd4947c2f2", "8a1dd8ae28ced277", "a42b89b4e124abdb", "a9c28a51a8b8a2dd", "84876baa1b5b86c2",
       "a7492df8ef70b36d", "bb65f44ff1ebc49c", "ee52b243b6bad405"},
      {"61cb79fc5c216ae3", "75ab34a5abe490eb", "590099d494877724", "73141728a83eff20", "a0ec7dfe42d913a1",
       "6c3579fdad85e7c3", "dcb1279f316adf16", "86efd9356736e92e"},
  };
  volume::FractureOptions options;
  options.pieces = 8;
  options.resolution = 48;
  options.maxTriangles = 300;
  const std::vector<core::TriangleMesh> solids = {core::makeBox(core::Vec3(0.4, 0.3, 0.02)),
                                                  core::makeUvEllipsoid(core::Vec3(1.0, 0.6, 0.4), 24, 12)};
  for (std::size_t s = 0; s < solids.size(); ++s) {
    auto broken = volume::fracture(solids[s], options);
    ASSERT_TRUE(broken.ok()) << broken.error().message;
    std::vector<std::string> keys;
    for (const core::TriangleMesh& fragment : broken->fragments)
      keys.push_back(surfaceKey(fragment));
    std::ostringstream now;
    for (const std::string& key : keys)
      now << " " << key;
    EXPECT_EQ(keys, recorded[s]) << "solid " << s << ": this build's fragments are" << now.str();
  }
}

}  // namespace
}  // namespace shapedb::io
