// shapedb query as a user runs it: the real executable on a real database file and real mesh files.

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/adapt.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/correction.h>
#include <shapedb/volume/entry.h>

#include "cli_test_support.h"
#include "support/mesh_files.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

std::string readPrefix(const std::filesystem::path& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  return s.substr(0, static_cast<std::size_t>(in.gcount()));
}

TEST(QueryCli, JsonParsedBackWithMatchesPhysicsFidelityAndFiles) {
  test::ScratchDir dir("query-cli");
  const auto db = dir / "small.db";
  test::ProcessResult built = test::buildWithCli(db, 6, "box,cylinder", 4);
  ASSERT_EQ(built.exitCode, 0) << built.err;

  // A box 3 × 2 × 1 m... turned, moved and scaled by 0.1: a 30 × 20 × 10 cm box, far from the origin.
  std::mt19937_64 rng(1);
  core::Mat4 pose = test::randomSimilarity(rng, 5.0, 1.0, 1.0);
  const auto box = dir / "box.ply";
  ASSERT_TRUE(io::saveMesh(core::transformed(core::makeBox({0.3, 0.2, 0.1}), pose), box).ok());
  const auto rod = dir / "rod.obj";
  ASSERT_TRUE(io::saveMesh(core::makeCylinder(0.02, 0.5, 32), rod).ok());

  const auto png = dir / "side.png";
  const auto objs = dir / "out";
  test::ProcessResult q = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), box.string(), rod.string(), "--k", "2", "--material", "aluminium",
                    "--json", "--png", png.string(), "--export-obj", objs.string()});
  ASSERT_EQ(q.exitCode, 0) << q.err;
  const nlohmann::json j = nlohmann::json::parse(q.out);
  ASSERT_EQ(j["queries"].size(), 2u);
  const nlohmann::json& b = j["queries"][0];
  EXPECT_EQ(b["file"], box.string());
  // --k 2, and the three nearest whose spectra the answer's eigenvalues are blended from (--neighbours).
  ASSERT_EQ(b["matches"].size(), 3u);
  EXPECT_LE(b["matches"][0]["distance"].get<double>(), b["matches"][1]["distance"].get<double>());
  ASSERT_EQ(b["physics"]["spectrum_weights"].size(), 3u);
  double weights = 0.0;
  for (const auto& w : b["physics"]["spectrum_weights"])
    weights += w.get<double>();
  EXPECT_NEAR(weights, 1.0, 1e-12);
  EXPECT_GT(b["physics"]["spectrum_weights"][0].get<double>(), 0.0);
  for (const auto& m : b["matches"]) {
    EXPECT_GT(m["moment_term"].get<double>(), 0.0);  // no entry is 3:2:1
    EXPECT_LE(m["moment_term"].get<double>(), m["distance"].get<double>());
  }
  EXPECT_TRUE(b["matches"][0]["entry_id"].is_number_unsigned());
  const nlohmann::json& p = b["physics"];
  EXPECT_EQ(p["material"]["name"], "aluminium");
  EXPECT_NEAR(p["mass"].get<double>(), 2700.0 * 0.3 * 0.2 * 0.1, 1e-6 * 16.2);
  EXPECT_EQ(p["frequencies_hz"].size(), 4u);
  EXPECT_GT(p["frequencies_hz"][0].get<double>(), 100.0);  // an aluminium box of 30 cm rings in kHz
  EXPECT_EQ(p["inertia"].size(), 3u);
  EXPECT_GT(p["collision"]["shapes"].size(), 0u);
  // Three box entries only, so the match is rough; the query's own moments are exact: for a 3:2:1 box of
  // unit volume (sides 3s, 2s, s with 6s³ = 1), (5, 10, 13) s² / 12.
  const double s2 = std::pow(6.0, -2.0 / 3.0);
  const std::array<double, 3> expected{5.0 * s2 / 12.0, 10.0 * s2 / 12.0, 13.0 * s2 / 12.0};
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(b["fidelity"]["query_moments"][i].get<double>(), expected[i],
                1e-6 * expected[i]);  // float file
  EXPECT_GE(b["fidelity"]["max_moment_error"].get<double>(), 0.0);
  EXPECT_GE(b["fidelity"]["mean_deviation"].get<double>(), 0.0);
  for (const char* stage : {"describe", "search", "fetch", "adapt", "link", "total"})
    EXPECT_GE(b["timing_us"][stage].get<double>(), 0.0) << stage;
  EXPECT_EQ(j["queries"][1]["matches"][0]["family"], "cylinder");
  // By the paper's distance alone the box query matches a box, whose proportions are further from the
  // query's than those of the default's match (a cylinder, here): the moment term trades the family for
  // the proportions, and the fidelity report shows it.
  test::ProcessResult paper =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), box.string(), "--moment-weight", "0", "--json"});
  ASSERT_EQ(paper.exitCode, 0) << paper.err;
  const nlohmann::json pj = nlohmann::json::parse(paper.out);
  const nlohmann::json& pb = pj["queries"][0];
  EXPECT_EQ(pb["matches"][0]["family"], "box");
  EXPECT_EQ(pb["matches"][0]["moment_term"].get<double>(), 0.0);
  EXPECT_LE(b["fidelity"]["max_moment_error"].get<double>(),
            pb["fidelity"]["max_moment_error"].get<double>());
  // Scaled uniformly by default; with --correct, the matched entry's tets are morphed onto the box and
  // their modes computed again: the frequencies of the 3:2:1 box itself, computed directly here.
  EXPECT_EQ(p["stretch"], nlohmann::json::parse("[1.0, 1.0, 1.0]"));
  EXPECT_FALSE(b.contains("correction"));
  test::ProcessResult corrected = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), box.string(), "--material", "aluminium", "--json", "--correct"});
  ASSERT_EQ(corrected.exitCode, 0) << corrected.err;
  const nlohmann::json cj = nlohmann::json::parse(corrected.out)["queries"][0];
  ASSERT_TRUE(cj.contains("correction")) << corrected.out;
  EXPECT_GT(cj["correction"]["worst_quality"].get<double>(), 0.0);
  EXPECT_GT(cj["correction"]["max_boundary_move"].get<double>(), 0.0);
  // A box onto a box lumps little or nothing, and no mode is one node's.
  EXPECT_LT(cj["correction"]["lumped_mode_share"].get<double>(), volume::kLumpedModeLimit);
  EXPECT_FALSE(cj["correction"]["mass_spread"].get<bool>());
  EXPECT_TRUE(cj["physics"]["warnings"].empty()) << cj["physics"]["warnings"];
  EXPECT_EQ(cj["physics"]["mass"], p["mass"]);
  // The correction computes the modes for aluminium's own Poisson ratio: so does the direct computation.
  const core::Material aluminium = *core::materialPreset("aluminium");
  volume::EntryOptions entry;
  entry.modal.material.poissonRatio = aluminium.poissonRatio;
  auto direct = volume::computeEntry(core::makeBox({0.3, 0.2, 0.1}), entry);
  ASSERT_TRUE(direct.ok()) << direct.error().message;
  const double hz =
      std::sqrt(direct->physics.modes.eigenvalues[0] * aluminium.youngsModulus / aluminium.density) /
      (2.0 * std::numbers::pi * std::cbrt(0.3 * 0.2 * 0.1));
  const double uncorrectedError = p["frequencies_hz"][0].get<double>() / hz - 1.0;
  const double correctedError = cj["physics"]["frequencies_hz"][0].get<double>() / hz - 1.0;
  std::printf("3:2:1 box f1 %.1f Hz: uncorrected %+.1f %%, corrected %+.2f %%\n", hz,
              100.0 * uncorrectedError, 100.0 * correctedError);
  EXPECT_LT(std::abs(correctedError), 0.05);  // another family's tets, morphed: within the entry's resolution
  EXPECT_LT(std::abs(correctedError), std::abs(uncorrectedError));
  // --stretch needs a database of linear tets: refused here, with the reason; and with --correct, a usage
  // error.
  test::ProcessResult refused =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), box.string(), "--json", "--stretch"});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.err.find("linear tets"), std::string::npos) << refused.err;
  EXPECT_EQ(
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), box.string(), "--stretch", "--correct"}).exitCode,
      2);

  // Files beside the queries: two PNGs (one per mesh), and OBJs of the adapted volume and compound.
  for (const char* name : {"side-1.png", "side-2.png"})
    EXPECT_EQ(readPrefix(dir / name, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
  for (const char* name : {"box.volume.obj", "box.collision.obj", "rod.volume.obj", "rod.collision.obj"})
    EXPECT_GT(std::filesystem::file_size(objs / name), 100u) << name;
  auto volume = io::loadMesh(objs / "box.volume.obj");
  ASSERT_TRUE(volume.ok()) << volume.error().message;
  EXPECT_TRUE(volume->topology.isClosed());

  // Text output names the match and the stages with --timing.
  test::ProcessResult text = test::runProcess(SHAPEDB_CLI, {"query", db.string(), box.string(), "--timing"});
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_NE(text.out.find(b["matches"][0]["name"].get<std::string>()), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("timing (µs)"), std::string::npos) << text.out;

  // --table: a header and a row per mesh, saying what the JSON says (the same material, aluminium).
  test::ProcessResult table = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), box.string(), rod.string(), "--material", "aluminium", "--table"});
  ASSERT_EQ(table.exitCode, 0) << table.err;
  std::istringstream lines(table.out);
  std::string header, row;
  ASSERT_TRUE(std::getline(lines, header) && std::getline(lines, row)) << table.out;
  EXPECT_NE(header.find("pred.err"), std::string::npos) << header;
  std::istringstream cells(row);
  std::string file, name, deviation, momentError, predicted;
  double distance = 0.0, mass = 0.0, f1 = 0.0;
  cells >> file >> name >> distance >> deviation >> momentError >> predicted >> mass >> f1;
  EXPECT_EQ(file, "box.ply");
  EXPECT_EQ(name, b["matches"][0]["name"].get<std::string>());
  EXPECT_NEAR(distance, b["matches"][0]["distance"].get<double>(), 1e-4);
  ASSERT_TRUE(b.contains("predicted_frequency_error")) << b;
  EXPECT_NEAR(std::stod(predicted), 100.0 * b["predicted_frequency_error"].get<double>(), 0.005) << row;
  EXPECT_NEAR(mass, p["mass"].get<double>(), 1e-3 * p["mass"].get<double>());
  EXPECT_NEAR(f1, p["frequencies_hz"][0].get<double>(), 0.05);
}

// A closed mesh with holes punched in it is refused, with the flag that gets past it; with --repair it is
// answered as the closed mesh is: the same match, mass and first frequency within 2 %; with --approximate,
// as it is, marked approximate.
TEST(QueryCli, AMeshWithHolesIsRepairedAndAnsweredAsTheClosedOne) {
  test::ScratchDir dir("query-cli-repair");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "ellipsoid,box", 4).exitCode, 0);
  const core::TriangleMesh closed = core::makeUvEllipsoid({0.12, 0.08, 0.05}, 96, 48);
  core::TriangleMesh holed;
  holed.vertices = closed.vertices;
  for (const auto& t : closed.triangles) {
    const core::Vec3 c = (closed.vertices[t[0]] + closed.vertices[t[1]] + closed.vertices[t[2]]) / 3.0;
    if ((c - core::Vec3(0.12, 0, 0)).norm() > 0.005 && (c - core::Vec3(0, 0.08, 0)).norm() > 0.005)
      holed.triangles.push_back(t);
  }
  const auto closedPath = dir / "closed.obj", holedPath = dir / "holed.obj";
  ASSERT_TRUE(io::saveMesh(closed, closedPath).ok());
  ASSERT_TRUE(io::saveMesh(holed, holedPath).ok());

  test::ProcessResult refused = test::runProcess(SHAPEDB_CLI, {"query", db.string(), holedPath.string()});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.err.find("--repair"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--approximate"), std::string::npos) << refused.err;

  const auto answer = [&](const std::filesystem::path& mesh, const char* flag) {
    std::vector<std::string> args = {"query", db.string(), mesh.string(), "--json", "--no-fidelity"};
    if (flag) args.push_back(flag);
    test::ProcessResult q = test::runProcess(SHAPEDB_CLI, args);
    EXPECT_EQ(q.exitCode, 0) << q.err;
    return q.exitCode == 0 ? nlohmann::json::parse(q.out)["queries"][0] : nlohmann::json();
  };
  const nlohmann::json original = answer(closedPath, nullptr), repaired = answer(holedPath, "--repair");
  ASSERT_FALSE(original.is_null());
  ASSERT_FALSE(repaired.is_null());
  ASSERT_TRUE(repaired.contains("repaired"));
  EXPECT_EQ(repaired["repaired"]["holes"], 2);
  EXPECT_TRUE(repaired["repaired"]["volume_before"].is_null());
  EXPECT_EQ(repaired["matches"][0]["name"], original["matches"][0]["name"]);
  EXPECT_NEAR(repaired["physics"]["mass"].get<double>() / original["physics"]["mass"].get<double>(), 1.0,
              0.02);
  EXPECT_NEAR(repaired["physics"]["frequencies_hz"][0].get<double>() /
                  original["physics"]["frequencies_hz"][0].get<double>(),
              1.0, 0.02);
  EXPECT_FALSE(original["approximate"].get<bool>());
  EXPECT_FALSE(repaired["approximate"].get<bool>());

  // --approximate answers the open surface as it is: the mass from the volume of its fan about the
  // vertices' centroid (the holes' cones are missing: a fraction of a per cent here), the inertia a
  // shell's, and the answer marked approximate. The descriptor is the surface's, holes and all, but the
  // shell's moments enter the distance too: an entry of the same family, not necessarily the same one.
  // The closed one is answered exactly with or without the flag.
  const nlohmann::json approximate = answer(holedPath, "--approximate");
  ASSERT_FALSE(approximate.is_null());
  EXPECT_TRUE(approximate["approximate"].get<bool>());
  EXPECT_EQ(approximate["matches"][0]["family"], original["matches"][0]["family"]);
  EXPECT_NEAR(approximate["physics"]["mass"].get<double>() / original["physics"]["mass"].get<double>(), 1.0,
              0.01);
  ASSERT_FALSE(approximate["physics"]["warnings"].empty());
  EXPECT_NE(approximate["physics"]["warnings"][0].get<std::string>().find("approximate"), std::string::npos)
      << approximate["physics"]["warnings"];
  // A shell's moments of inertia exceed the solid's (by 5/3 for a sphere).
  for (int i = 0; i < 3; ++i)
    EXPECT_GT(approximate["physics"]["principal_moments"][i].get<double>(),
              1.2 * original["physics"]["principal_moments"][i].get<double>());
  const nlohmann::json exact = answer(closedPath, "--approximate");
  ASSERT_FALSE(exact.is_null());
  EXPECT_FALSE(exact["approximate"].get<bool>());
  EXPECT_EQ(exact["physics"]["mass"], original["physics"]["mass"]);
  EXPECT_TRUE(exact["physics"]["warnings"].empty()) << exact["physics"]["warnings"];
}

// The same solid written as users' files have it: as it is, wound inward, as a triangle soup (every
// triangle with its own corners), and in millimetres: the same answer from each, with a warning where the
// file was turned over or welded.
TEST(QueryCli, AnInsideOutCopyASoupAndAMillimetreCopyGiveTheSameAnswer) {
  test::ScratchDir dir("query-cli-forms");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "ellipsoid,box", 4).exitCode, 0);
  const core::TriangleMesh solid = core::makeUvEllipsoid({0.12, 0.08, 0.05}, 48, 24);
  core::TriangleMesh inward = solid, millimetres = solid;
  for (auto& t : inward.triangles)
    std::swap(t[1], t[2]);
  for (core::Vec3& p : millimetres.vertices)
    p *= 1000.0;
  const auto original = dir / "solid.ply", turned = dir / "inward.ply", soup = dir / "soup.obj",
             mm = dir / "solid_mm.ply";
  ASSERT_TRUE(io::saveMesh(solid, original).ok());
  ASSERT_TRUE(io::saveMesh(inward, turned).ok());
  test::writeFile(soup, test::objText(test::soupOf(solid)));
  ASSERT_TRUE(io::saveMesh(millimetres, mm).ok());

  test::ProcessResult q = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), original.string(), turned.string(), soup.string(), "--json"});
  ASSERT_EQ(q.exitCode, 0) << q.err;
  EXPECT_NE(q.err.find(turned.string() + ": the surface is wound inward"), std::string::npos) << q.err;
  EXPECT_NE(q.err.find(soup.string() + ": "), std::string::npos) << q.err;
  EXPECT_NE(q.err.find("coincident vertices welded, which closed the surface"), std::string::npos) << q.err;
  test::ProcessResult qmm =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), mm.string(), "--units", "mm", "--json"});
  ASSERT_EQ(qmm.exitCode, 0) << qmm.err;
  EXPECT_EQ(qmm.err, "");

  const nlohmann::json answers = nlohmann::json::parse(q.out)["queries"];
  const nlohmann::json reference = answers[0];
  std::vector<nlohmann::json> others = {answers[1], answers[2], nlohmann::json::parse(qmm.out)["queries"][0]};
  EXPECT_TRUE(others[0]["flipped_inside_out"].get<bool>());
  EXPECT_GT(others[1]["welded_vertices"].get<int>(), 0);
  EXPECT_EQ(others[2]["scale"].get<double>(), 0.001);
  for (const nlohmann::json& other : others) {
    SCOPED_TRACE(other["file"].get<std::string>());
    EXPECT_EQ(other["matches"][0]["name"], reference["matches"][0]["name"]);
    // Float files: the coordinates agree to single precision.
    EXPECT_NEAR(other["physics"]["mass"].get<double>() / reference["physics"]["mass"].get<double>(), 1.0,
                1e-5);
    for (int i = 0; i < 4; ++i)
      EXPECT_NEAR(other["physics"]["frequencies_hz"][i].get<double>() /
                      reference["physics"]["frequencies_hz"][i].get<double>(),
                  1.0, 1e-5);
  }
}

// Every real mesh of the development folder through query, each in its own unit (none of the files says
// it: CAD exports and the knot and fox are in millimetres, the torus in centimetres, the Bob figure has
// none and is read as decimetres, the rest are in metres), as steel: no size warning, and a mass and size
// plausible for a steel object held in the hand. Read in metres, the millimetre ones would be houses of
// steel: the warning names the unit. Files of the folder not in the list are queried as metres.
TEST(QueryCli, EveryRealMeshIsAnsweredWithAPlausibleMassInItsUnit) {
  SHAPEDB_REAL_MESHES_OR_SKIP(folder);
  test::ScratchDir dir("query-cli-real");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "ellipsoid,box", 4).exitCode, 0);
  const std::vector<std::pair<std::vector<std::string>, std::vector<std::string>>> groups = {
      {{"--units", "m"},
       {"cad/barkour_foot.stl", "cad/cube_cup_hi.obj", "everyday/fuze_bottle.obj", "scanned/horse.ply"}},
      {{"--units", "mm"},
       {"cad/shadowhand_lf_metacarpal.obj", "cad/tray_bottom_1002.STL", "cad/turbineblade.ply",
        "everyday/goblet_vase.stl", "primitive/quadknot.obj", "scanned/fox.ply"}},
      {{"--units", "cm"}, {"primitive/torus.STL"}},
      {{"--scale", "0.1"}, {"scanned/bob_small.ply"}},
  };
  std::set<std::filesystem::path> listed;
  std::size_t answered = 0, missing = 0;
  for (const auto& [units, files] : groups) {
    std::vector<std::string> args = {"query", db.string(), "--json", "--no-fidelity"};
    args.insert(args.end(), units.begin(), units.end());
    for (const std::string& file : files) {
      listed.insert(std::filesystem::weakly_canonical(folder / file));
      if (std::filesystem::exists(folder / file))
        args.push_back((folder / file).string());
      else
        ++missing;
    }
    if (args.size() == 4 + units.size()) continue;
    test::ProcessResult q = test::runProcess(SHAPEDB_CLI, args);
    ASSERT_EQ(q.exitCode, 0) << q.err;
    EXPECT_EQ(q.err.find("across, read in metres"), std::string::npos) << q.err;
    const nlohmann::json j = nlohmann::json::parse(q.out);
    for (const nlohmann::json& answer : j["queries"]) {
      SCOPED_TRACE(answer["file"].get<std::string>());
      const nlohmann::json& p = answer["physics"];
      EXPECT_EQ(p["material"]["name"], "steel");
      EXPECT_NEAR(p["mass"].get<double>(), 7850.0 * answer["volume"].get<double>(),
                  1e-9 * p["mass"].get<double>());
      EXPECT_GT(p["mass"].get<double>(), 0.01);  // 10 g: a robot's foot pad is 33 g
      EXPECT_LT(p["mass"].get<double>(), 20.0);  // 20 kg: the knot is 8 kg
      EXPECT_GT(answer["size"].get<double>(), 0.01);
      EXPECT_LT(answer["size"].get<double>(), 0.3);
      EXPECT_GT(p["frequencies_hz"][0].get<double>(), 0.0);
      ++answered;
    }
  }
  EXPECT_EQ(answered, listed.size() - missing);

  // The millimetre files read as metres: told so, with the unit to give.
  std::vector<std::string> asMetres = {"query", db.string(), "--json", "--no-fidelity"};
  for (const char* file : {"cad/tray_bottom_1002.STL", "scanned/fox.ply"})
    if (std::filesystem::exists(folder / file)) asMetres.push_back((folder / file).string());
  if (asMetres.size() > 4) {
    test::ProcessResult q = test::runProcess(SHAPEDB_CLI, asMetres);
    ASSERT_EQ(q.exitCode, 0) << q.err;
    EXPECT_NE(q.err.find("give --units mm"), std::string::npos) << q.err;
    const nlohmann::json j = nlohmann::json::parse(q.out);
    EXPECT_EQ(j["queries"].size(), asMetres.size() - 4);
    for (const nlohmann::json& answer : j["queries"])
      EXPECT_GT(answer["physics"]["mass"].get<double>(), 1e5) << answer["file"];
  }

  // Whatever else the folder holds runs through query too.
  auto all = io::listMeshFiles(folder);
  ASSERT_TRUE(all.ok()) << all.error().message;
  std::vector<std::string> others = {"query", db.string(), "--json", "--no-fidelity"};
  for (const std::filesystem::path& file : *all)
    if (!listed.count(std::filesystem::weakly_canonical(file))) others.push_back(file.string());
  if (others.size() > 4) {
    test::ProcessResult q = test::runProcess(SHAPEDB_CLI, others);
    EXPECT_EQ(q.exitCode, 0) << q.err;
  }
}

// Files are read several at a time: over more files than a group holds, the answers come in the files'
// order, and so do what reading them says (warnings, files that cannot be read) and then what querying
// them says (surfaces refused); a file that fails leaves the others answered.
TEST(QueryCli, ManyFilesAreAnsweredAndWarnedAboutInTheirOrder) {
  test::ScratchDir dir("query-cli-many");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 2, "box", 2).exitCode, 0);
  std::vector<std::string> args = {"query", db.string(), "--json", "--no-fidelity"};
  // Files in order: answered; warned about or unreadable (reading); refused (querying).
  std::vector<std::string> answered, reading, querying;
  for (int i = 0; i < 37; ++i) {
    const auto path = dir / ("mesh-" + std::to_string(100 + i) + ".obj");
    args.push_back(path.string());
    if (i % 7 == 5) {
      test::writeFile(path, "v 0 0 0\nf 1 2 3\n");  // a face on vertices the file lacks
      reading.push_back(path.string());
      continue;
    }
    core::TriangleMesh box = core::makeBox({1.0 + 0.05 * i, 2.0, 3.0});
    if (i % 5 == 3) {
      box.triangles.pop_back();  // open: refused
      querying.push_back(path.string());
    } else {
      if (i % 5 == 1) {
        for (auto& t : box.triangles)
          std::swap(t[1], t[2]);  // wound inward: flipped, with a warning
        reading.push_back(path.string());
      }
      answered.push_back(path.string());
    }
    ASSERT_TRUE(io::saveMesh(box, path).ok());
  }
  test::ProcessResult q = test::runProcess(SHAPEDB_CLI, args);
  EXPECT_EQ(q.exitCode, 1) << "some files were refused";
  const nlohmann::json queries = nlohmann::json::parse(q.out)["queries"];
  ASSERT_EQ(queries.size(), answered.size());
  for (std::size_t i = 0; i < answered.size(); ++i)
    EXPECT_EQ(queries[i]["file"].get<std::string>(), answered[i]);
  std::size_t at = 0;
  for (const std::string& file : reading) {
    const std::size_t found = q.err.find(file + ":", at);
    ASSERT_NE(found, std::string::npos) << file << " is not reported after the files before it:\n" << q.err;
    at = found + 1;
  }
  for (const std::string& file : querying) {
    const std::size_t found = q.err.find(file + ":", at);
    ASSERT_NE(found, std::string::npos) << file << " is not reported after the files before it:\n" << q.err;
    at = found + 1;
  }
}

TEST(QueryCli, BadInputsAreClearErrors) {
  test::ScratchDir dir("query-cli-bad");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 2, "box", 2).exitCode, 0);
  const auto good = dir / "good.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({1, 2, 3}), good).ok());
  // An open surface: a tetrahedron without its fourth face.
  const auto openPath = dir / "open.obj";
  std::ofstream(openPath) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n";

  test::ProcessResult missing =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), (dir / "none.obj").string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("none.obj"), std::string::npos) << missing.err;

  test::ProcessResult openQuery =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), openPath.string(), good.string()});
  EXPECT_EQ(openQuery.exitCode, 1) << "one mesh failed";
  EXPECT_NE(openQuery.err.find("open.obj"), std::string::npos) << openQuery.err;
  EXPECT_NE(openQuery.out.find("good.obj"), std::string::npos) << "the good mesh is still answered";

  // A closed tetrahedron with one face turned over: refused, naming the flag that remeshes it.
  const auto twistedPath = dir / "twisted.obj";
  std::ofstream(twistedPath) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 3 4\n";
  test::ProcessResult twisted = test::runProcess(SHAPEDB_CLI, {"query", db.string(), twistedPath.string()});
  EXPECT_EQ(twisted.exitCode, 1);
  EXPECT_NE(twisted.err.find("twisted.obj"), std::string::npos) << twisted.err;
  EXPECT_NE(twisted.err.find("--repair"), std::string::npos) << twisted.err;

  test::ProcessResult material =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), good.string(), "--material", "cheese"});
  EXPECT_EQ(material.exitCode, 2);
  EXPECT_NE(material.err.find("unknown material 'cheese'"), std::string::npos) << material.err;

  test::ProcessResult both = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), good.string(), "--material", "steel", "--density", "1000"});
  EXPECT_EQ(both.exitCode, 2);
  test::ProcessResult custom = test::runProcess(
      SHAPEDB_CLI,
      {"query", db.string(), good.string(), "--density", "1000", "--youngs", "1e9", "--poisson", "0.45"});
  EXPECT_EQ(custom.exitCode, 0) << custom.err;
  EXPECT_NE(custom.out.find("warning: material Poisson ratio"), std::string::npos) << custom.out;

  // An option that only means something beside another is an error without it, not ignored.
  for (const auto& [alone, needed] :
       {std::pair{std::vector<std::string>{"--correct-candidates", "2"}, "--correct"},
        std::pair{std::vector<std::string>{"--repair-resolution", "64"}, "--repair"},
        std::pair{std::vector<std::string>{"--enrich-above", "0.1"}, "--enrich"}}) {
    std::vector<std::string> args{"query", db.string(), good.string()};
    args.insert(args.end(), alone.begin(), alone.end());
    const test::ProcessResult result = test::runProcess(SHAPEDB_CLI, args);
    EXPECT_EQ(result.exitCode, 2) << alone[0];
    EXPECT_NE(result.err.find(std::string(alone[0]) + " requires " + needed), std::string::npos)
        << result.err;
  }

  // The candidates' bound is the library's (io::kMaxCorrectionCandidates).
  const test::ProcessResult tooMany = test::runProcess(
      SHAPEDB_CLI, {"query", db.string(), good.string(), "--correct", "--correct-candidates", "101"});
  EXPECT_EQ(tooMany.exitCode, 2);
  EXPECT_NE(tooMany.err.find("--correct-candidates"), std::string::npos) << tooMany.err;
  EXPECT_NE(tooMany.err.find("100"), std::string::npos) << tooMany.err;

  test::ProcessResult notDb = test::runProcess(SHAPEDB_CLI, {"query", good.string(), good.string()});
  EXPECT_EQ(notDb.exitCode, 1);
  EXPECT_NE(notDb.err.find("good.obj"), std::string::npos) << notDb.err;

  // A folder where a file belongs, as the mesh and as the database: said so, not "unknown format" or
  // "no such file".
  const std::string folder = good.parent_path().string();
  for (const auto& args : {std::vector<std::string>{"query", db.string(), folder},
                           std::vector<std::string>{"query", folder, good.string()}}) {
    const test::ProcessResult result = test::runProcess(SHAPEDB_CLI, args);
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_NE(result.err.find(folder + ": is a directory"), std::string::npos) << result.err;
  }
}

}  // namespace
}  // namespace shapedb::cli
