#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/describe.h>

#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb {
namespace {

// `shapedb describe ARGS...`
test::ProcessResult runDescribe(std::vector<std::string> args) {
  args.insert(args.begin(), "describe");
  return test::runProcess(SHAPEDB_CLI, args);
}

TEST(CliDescribe, JsonHoldsTheGridTheLibraryComputes) {
  test::ScratchDir dir("cli");
  ASSERT_TRUE(io::saveMesh(test::makeLopsidedBlob({1.0, 1.6, 0.7}, 3), dir / "blob.ply").ok());
  const test::ProcessResult run =
      runDescribe({(dir / "blob.ply").string(), "--json", "--grid", "8", "--sampling", "vertices"});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["descriptor"], "centroid-voxel");
  EXPECT_EQ(j["sampling"], "vertices");
  ASSERT_EQ(j["grid"].get<int>(), 8);
  ASSERT_EQ(j["occupancy"].size(), 512u);
  ASSERT_EQ(j["centroids"].size(), 512u);

  // The library on the mesh the file holds gives the same cells and centroids.
  const io::LoadedMesh loaded = *io::loadMesh(dir / "blob.ply");
  const core::Normalization n = *core::normalize(loaded.mesh, *core::computeMassProperties(loaded.mesh));
  core::DescriptorOptions options;
  options.gridSize = 8;
  options.sampling = core::Sampling::kVertices;
  const core::Descriptor d = *volume::describe(loaded.mesh, n, options);
  std::size_t next = 0;
  for (std::uint32_t cell = 0; cell < 512; ++cell) {
    const bool filled = next < d.cells.size() && d.cells[next] == cell;
    EXPECT_EQ(j["occupancy"][cell].get<int>(), filled ? 1 : 0) << cell;
    EXPECT_EQ(j["centroids"][cell].is_null(), !filled) << cell;
    if (filled) {
      for (int a = 0; a < 3; ++a)
        EXPECT_DOUBLE_EQ(j["centroids"][cell][a].get<double>(), d.canonicalCentroid(next)[a]);
      ++next;
    }
  }
  EXPECT_EQ(next, d.cells.size());
  EXPECT_EQ(j["filled_cells"].get<std::size_t>(), d.cells.size());
}

TEST(CliDescribe, MomentAndVoxelCarryTheirFields) {
  test::ScratchDir dir("cli");
  ASSERT_TRUE(io::saveMesh(test::makeLopsidedBlob({1.0, 1.6, 0.7}, 2), dir / "blob.obj").ok());
  const test::ProcessResult moment =
      runDescribe({(dir / "blob.obj").string(), "--json", "--descriptor", "moment"});
  ASSERT_EQ(moment.exitCode, 0) << moment.err;
  const nlohmann::json m = nlohmann::json::parse(moment.out);
  ASSERT_EQ(m["moments"].size(), 3u);
  EXPECT_LE(m["moments"][0].get<double>(), m["moments"][1].get<double>());
  EXPECT_FALSE(m.contains("occupancy"));

  const test::ProcessResult voxel =
      runDescribe({(dir / "blob.obj").string(), "--json", "--descriptor", "voxel"});
  ASSERT_EQ(voxel.exitCode, 0) << voxel.err;
  const nlohmann::json v = nlohmann::json::parse(voxel.out);
  EXPECT_EQ(v["occupancy"].size(), 1000u);
  EXPECT_FALSE(v.contains("centroids"));

  const test::ProcessResult text = runDescribe({(dir / "blob.obj").string()});
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_NE(text.out.find("z=0"), std::string::npos);
  EXPECT_NE(text.out.find('#'), std::string::npos);
}

TEST(CliDescribe, BadInputAndBadOptionsAreReported) {
  test::ScratchDir dir("cli");
  const test::ProcessResult missing = runDescribe({(dir / "nope.obj").string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("nope.obj"), std::string::npos) << missing.err;
  ASSERT_TRUE(io::saveMesh(test::makeLopsidedBlob({1.0, 1.6, 0.7}, 1), dir / "blob.obj").ok());
  EXPECT_EQ(runDescribe({(dir / "blob.obj").string(), "--grid", "1"}).exitCode, 2);
  EXPECT_EQ(runDescribe({(dir / "blob.obj").string(), "--descriptor", "fourier"}).exitCode, 2);
}

}  // namespace
}  // namespace shapedb
