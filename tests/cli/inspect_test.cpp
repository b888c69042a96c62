#include <tuple>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb {
namespace {

test::ProcessResult shapedb(const std::vector<std::string>& args) {
  return test::runProcess(SHAPEDB_CLI, args);
}

TEST(CliInspect, JsonCarriesTheDocumentedFieldsAndMatchesTheLibrary) {
  test::ScratchDir dir("cli");
  const core::TriangleMesh blob = test::makeLopsidedBlob({1.0, 1.6, 0.7}, 3);
  ASSERT_TRUE(io::saveMesh(blob, dir / "blob.ply").ok());

  const test::ProcessResult run =
      shapedb({"inspect", (dir / "blob.ply").string(), "--json", "--density", "2.5"});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_EQ(run.err, "");
  const nlohmann::json j = nlohmann::json::parse(run.out);
  for (const char* field : {"volume", "area", "center_of_mass", "inertia", "principal_moments",
                            "principal_axes", "transform", "topology"})
    EXPECT_TRUE(j.contains(field)) << field;

  // Same numbers as the library on the mesh the file holds.
  const io::LoadedMesh loaded = *io::loadMesh(dir / "blob.ply");
  const core::MassProperties mp = *core::computeMassProperties(loaded.mesh, {.density = 2.5});
  const core::Normalization n = *core::normalize(loaded.mesh, mp);
  EXPECT_DOUBLE_EQ(j["volume"].get<double>(), mp.volume);
  EXPECT_DOUBLE_EQ(j["mass"].get<double>(), 2.5 * mp.volume);
  EXPECT_DOUBLE_EQ(j["area"].get<double>(), mp.area);
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(j["center_of_mass"][i].get<double>(), mp.centerOfMass[i]);
    EXPECT_DOUBLE_EQ(j["principal_moments"][i].get<double>(), n.principalMoments[i]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_DOUBLE_EQ(j["inertia"][i][k].get<double>(), mp.inertia(i, k));
      EXPECT_DOUBLE_EQ(j["principal_axes"][i][k].get<double>(), n.principalAxes(k, i));
    }
  }
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_DOUBLE_EQ(j["transform"][r][c].get<double>(), n.canonicalFromMesh(r, c));
  EXPECT_EQ(j["topology"]["triangles"].get<std::size_t>(), blob.triangles.size());
  EXPECT_TRUE(j["topology"]["is_closed"].get<bool>());
  EXPECT_EQ(j["degeneracy"]["axes"], "none");
  EXPECT_FALSE(j["approximate"].get<bool>());
}

TEST(CliInspect, FlagsASymmetricShape) {
  test::ScratchDir dir("cli");
  ASSERT_TRUE(io::saveMesh(core::makeIcosphere(1.0, 3), dir / "sphere.obj").ok());
  const test::ProcessResult run = shapedb({"inspect", (dir / "sphere.obj").string(), "--json"});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["degeneracy"]["axes"], "all");
}

TEST(CliInspect, TextReportNamesTheFileAndItsNumbers) {
  test::ScratchDir dir("cli");
  ASSERT_TRUE(io::saveMesh(core::makeBox({1, 2, 3}), dir / "box.obj").ok());
  const test::ProcessResult run = shapedb({"inspect", (dir / "box.obj").string()});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("box.obj (obj): 8 vertices, 12 triangles"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("volume           6 m³"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("closed, consistently oriented"), std::string::npos);
}

// A surface that passes through itself (two boxes that overlap, written as one mesh, as exports of parts
// are) still has its mass properties, and its crossing triangles are counted and named; a box has none.
TEST(CliInspect, CountsTheTrianglesThatCross) {
  test::ScratchDir dir("cli");
  ASSERT_TRUE(io::saveMesh(test::twoUnitBoxes({0.5, 0.3, 0.2}), dir / "crossed.obj").ok());
  ASSERT_TRUE(io::saveMesh(core::makeBox({1, 2, 3}), dir / "box.obj").ok());

  const test::ProcessResult json = shapedb({"inspect", (dir / "crossed.obj").string(), "--json"});
  ASSERT_EQ(json.exitCode, 0) << json.err;
  const nlohmann::json topology = nlohmann::json::parse(json.out)["topology"];
  EXPECT_GT(topology["crossing_triangle_pairs"].get<int>(), 0);
  const auto pair = topology["first_crossing"]["triangles"].get<std::vector<int>>();
  ASSERT_EQ(pair.size(), 2u);
  EXPECT_LT(pair[0], 12);  // one triangle of each box
  EXPECT_GE(pair[1], 12);
  const test::ProcessResult text = shapedb({"inspect", (dir / "crossed.obj").string()});
  EXPECT_NE(text.out.find("CROSSING triangle pairs"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("--repair"), std::string::npos) << text.out;

  const test::ProcessResult box = shapedb({"inspect", (dir / "box.obj").string(), "--json"});
  ASSERT_EQ(box.exitCode, 0) << box.err;
  const nlohmann::json boxTopology = nlohmann::json::parse(box.out)["topology"];
  EXPECT_EQ(boxTopology["crossing_triangle_pairs"].get<int>(), 0);
  EXPECT_TRUE(boxTopology["first_crossing"].is_null());
}

// A surface of several shells: its solids and cavities counted, in the text and the JSON (a box with a
// box-shaped cavity; two boxes apart; one box).
TEST(CliInspect, CountsTheSolidsAndCavitiesOfItsShells) {
  test::ScratchDir dir("cli-shells");
  const core::TriangleMesh hollow =
      test::withShell(core::makeBox({2, 2, 2}), core::makeBox({1, 1, 1}), core::Vec3::Zero(), true);
  ASSERT_TRUE(io::saveMesh(hollow, dir / "hollow.obj").ok());
  ASSERT_TRUE(io::saveMesh(test::twoUnitBoxes({3.0, 0.0, 0.0}), dir / "apart.obj").ok());
  ASSERT_TRUE(io::saveMesh(core::makeBox({1, 2, 3}), dir / "box.obj").ok());
  for (const auto& [name, solids, cavities] :
       {std::tuple{"hollow.obj", 1, 1}, {"apart.obj", 2, 0}, {"box.obj", 1, 0}}) {
    const test::ProcessResult json = shapedb({"inspect", (dir / name).string(), "--json"});
    ASSERT_EQ(json.exitCode, 0) << json.err;
    const nlohmann::json topology = nlohmann::json::parse(json.out)["topology"];
    EXPECT_EQ(topology["solids"].get<int>(), solids) << name;
    EXPECT_EQ(topology["cavities"].get<int>(), cavities) << name;
  }
  const test::ProcessResult text = shapedb({"inspect", (dir / "hollow.obj").string()});
  EXPECT_NE(text.out.find("shells: 1 solid, 1 cavity"), std::string::npos) << text.out;
  const test::ProcessResult one = shapedb({"inspect", (dir / "box.obj").string()});
  EXPECT_EQ(one.out.find("shells:"), std::string::npos) << one.out;
}

TEST(CliInspect, OpenMeshFailsWithOneLineUnlessApproximate) {
  test::ScratchDir dir("cli");
  test::writeFile(dir / "open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n");
  const test::ProcessResult refused = shapedb({"inspect", (dir / "open.obj").string()});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_EQ(refused.out, "");
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find("open.obj: mesh is not closed (3 boundary edges)"), std::string::npos)
      << refused.err;

  const test::ProcessResult approx =
      shapedb({"inspect", (dir / "open.obj").string(), "--approximate", "--json"});
  ASSERT_EQ(approx.exitCode, 0) << approx.err;
  const nlohmann::json j = nlohmann::json::parse(approx.out);
  EXPECT_TRUE(j["approximate"].get<bool>());
  EXPECT_EQ(j["topology"]["boundary_edges"].get<int>(), 3);
}

TEST(CliInspect, BadInputAndUsageGiveNonZeroExitAndAMessage) {
  test::ScratchDir dir("cli");
  const test::ProcessResult missing = shapedb({"inspect", (dir / "absent.stl").string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("absent.stl: no such file"), std::string::npos) << missing.err;

  EXPECT_EQ(shapedb({"inspect"}).exitCode, 2);
  EXPECT_EQ(shapedb({"frobnicate"}).exitCode, 2);
  EXPECT_EQ(shapedb({"inspect", (dir / "x.obj").string(), "--density", "-3"}).exitCode, 2);
}

TEST(CliInspect, AMillimetreMeshIsReadInItsUnitOrWarnedAbout) {
  test::ScratchDir dir("cli-units");
  const core::TriangleMesh tray = core::makeBox({300.0, 200.0, 10.0});  // a CAD export, in mm
  ASSERT_TRUE(io::saveMesh(tray, dir / "tray.ply").ok());
  const test::ProcessResult asMetres = shapedb({"inspect", (dir / "tray.ply").string(), "--json"});
  ASSERT_EQ(asMetres.exitCode, 0) << asMetres.err;
  EXPECT_NE(asMetres.err.find("--units mm"), std::string::npos) << asMetres.err;
  const test::ProcessResult inMm =
      shapedb({"inspect", (dir / "tray.ply").string(), "--json", "--units", "mm", "--density", "2700"});
  ASSERT_EQ(inMm.exitCode, 0) << inMm.err;
  EXPECT_EQ(inMm.err, "");
  const nlohmann::json j = nlohmann::json::parse(inMm.out);
  EXPECT_NEAR(j["volume"].get<double>(), 0.3 * 0.2 * 0.01, 1e-12);
  EXPECT_NEAR(j["mass"].get<double>(), 2700.0 * 0.3 * 0.2 * 0.01, 1e-9);
  EXPECT_EQ(j["scale"].get<double>(), 0.001);
  const test::ProcessResult scaled =
      shapedb({"inspect", (dir / "tray.ply").string(), "--json", "--scale", "0.001"});
  ASSERT_EQ(scaled.exitCode, 0) << scaled.err;
  EXPECT_EQ(nlohmann::json::parse(scaled.out)["volume"], j["volume"]);
  EXPECT_NE(shapedb({"inspect", (dir / "tray.ply").string(), "--units", "furlong"}).exitCode, 0);

  // 20 km across: millimetres would still leave it 20 m, so no unit is offered, only that it may be wrong.
  ASSERT_TRUE(io::saveMesh(core::makeBox({2e4, 1e4, 5e3}), dir / "huge.ply").ok());
  const test::ProcessResult huge = shapedb({"inspect", (dir / "huge.ply").string(), "--json"});
  ASSERT_EQ(huge.exitCode, 0) << huge.err;
  EXPECT_NE(huge.err.find("20 km across, read in metres; if that is not its unit, give --units or --scale"),
            std::string::npos)
      << huge.err;
}

TEST(CliInspect, HelpExplains) {
  const test::ProcessResult top = shapedb({"--help"});
  EXPECT_EQ(top.exitCode, 0);
  EXPECT_NE(top.out.find("inspect"), std::string::npos);
  const test::ProcessResult inspect = shapedb({"inspect", "--help"});
  EXPECT_EQ(inspect.exitCode, 0);
  for (const char* word : {"--json", "--density", "--approximate", "canonicalFromMesh"})
    EXPECT_NE(inspect.out.find(word), std::string::npos) << word;
}

}  // namespace
}  // namespace shapedb
