// shapedb drop as a user runs it: a plate fractured, its fragments given mass properties and compounds
// by a real database, dropped in Bullet; the JSON read back.

#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "cli_test_support.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

TEST(DropCli, PlateFragmentsFallComeToRestOnTheFloorAndFramesAreWritten) {
  test::ScratchDir dir("drop-cli");
  const auto db = dir / "small.db";
  const test::ProcessResult built = test::buildWithCli(db, 24, "box,prism,shard", 2);
  ASSERT_EQ(built.exitCode, 0) << built.err;
  const auto plate = dir / "plate.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.4, 0.3, 0.02}), plate).ok());
  const auto frames = dir / "frames";
  const test::ProcessResult drop = test::runProcess(
      SHAPEDB_CLI, {"drop", db.string(), "--fracture", plate.string(), "--pieces", "6", "--seconds", "3",
                    "--frames", frames.string(), "--frame-rate", "5", "--json"});
  ASSERT_EQ(drop.exitCode, 0) << drop.err;
  const nlohmann::json j = nlohmann::json::parse(drop.out);
  const std::size_t bodies = j["bodies"].size();
  EXPECT_GE(bodies + j["skipped"].size(), 5u);
  EXPECT_GE(bodies, 4u);
  double mass = 0.0;
  for (const nlohmann::json& b : j["bodies"]) {
    SCOPED_TRACE(b["name"].get<std::string>());
    mass += b["mass"].get<double>();
    // Fell from about 0.3 m to the floor: a 2 cm plate's fragments end within a few centimetres of it,
    // neither floating nor through it.
    EXPECT_GT(b["start_center_of_mass"][2].get<double>(), 0.29);
    EXPECT_LT(b["final_center_of_mass"][2].get<double>(), 0.05);
    EXPECT_GT(b["final_lowest_point"].get<double>(), -3e-3);
  }
  // Steel plate 0.4 × 0.3 × 0.02 m: 18.84 kg, the fragments' exact masses add up to it (crumbs aside).
  if (j["skipped"].empty()) {
    EXPECT_NEAR(mass, 7850.0 * 0.4 * 0.3 * 0.02, 0.02 * 18.84);
  }
  std::printf("%zu bodies, %.3f kg in all, %zu at rest\n", bodies, mass, j["at_rest"].get<std::size_t>());
  EXPECT_GE(j["at_rest"].get<std::size_t>(), bodies - 1);
  EXPECT_LT(j["energy_end"].get<double>(), j["energy_start"].get<double>());
  EXPECT_EQ(j["frames"], 15u);
  EXPECT_TRUE(std::filesystem::exists(frames / "frame-0014.png"));

  // Neither meshes nor --fracture: a usage error.
  EXPECT_EQ(test::runProcess(SHAPEDB_CLI, {"drop", db.string()}).exitCode, 2);
}

TEST(DropCli, AnOptionWithoutTheOneItQualifiesIsAnError) {
  // --pieces counts the fragments of --fracture's mesh, --frame-rate the frames of --frames: given alone,
  // either would be ignored.
  test::ScratchDir dir("drop-cli-alone");
  const auto mesh = dir / "cube.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.1, 0.1, 0.1}), mesh).ok());
  for (const auto& [alone, needed] :
       {std::pair{"--pieces", "--fracture"}, std::pair{"--frame-rate", "--frames"}}) {
    const test::ProcessResult drop = test::runProcess(
        SHAPEDB_CLI, {"drop", (dir / "no.db").string(), mesh.string(), alone, "4", "--json"});
    EXPECT_EQ(drop.exitCode, 2) << alone;
    EXPECT_NE(drop.err.find(std::string(alone) + " requires " + needed), std::string::npos) << drop.err;
  }
}

}  // namespace
}  // namespace shapedb::cli
