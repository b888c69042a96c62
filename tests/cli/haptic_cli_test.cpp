// shapedb haptic as a user runs it: the real executable on a real database, a scene directory of mesh
// files and a CSV trajectory; its JSON report parsed back.

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "cli_test_support.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

core::TriangleMesh boxAt(const core::Vec3& size, const core::Vec3& center) {
  core::TriangleMesh mesh = core::makeBox(size);
  for (core::Vec3& v : mesh.vertices)
    v += center;
  return mesh;
}

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(HapticCli, ReportParsedBackForASceneWithAnOpenMesh) {
  test::ScratchDir dir("haptic-cli");
  const auto db = dir / "small.db";
  test::ProcessResult built = test::buildWithCli(db, 12, "box", 4);
  ASSERT_EQ(built.exitCode, 0) << built.err;

  // Two boxes 10 × 6 × 4 cm on a line, and an open surface (a tetrahedron missing a face) between them.
  const auto scene = dir / "scene";
  std::filesystem::create_directories(scene);
  ASSERT_TRUE(io::saveMesh(boxAt({0.1, 0.06, 0.04}, {0.0, 0.0, 0.02}), scene / "a-box.obj").ok());
  ASSERT_TRUE(io::saveMesh(boxAt({0.1, 0.06, 0.04}, {0.4, 0.0, 0.02}), scene / "c-box.ply").ok());
  std::ofstream(scene / "b-open.obj")
      << "v 0.2 0 0\nv 0.25 0 0\nv 0.2 0.05 0\nv 0.2 0 0.05\nf 1 3 2\nf 1 2 4\nf 2 3 4\n";
  std::ofstream(scene / "notes.txt") << "not a mesh: ignored\n";
  // The proxy comes down onto the first box, presses 5 mm into its top (z = 4 cm) for a while, then moves
  // over to the last one and presses into it. (A database of 12 boxes matches a box only roughly: the
  // compound's top can be a few mm off the mesh's.)
  const auto trajectory = dir / "path.csv";
  std::ofstream(trajectory)
      << "t,x,y,z\n0,0,0,0.1\n0.2,0,0,0.04\n0.6,0,0,0.04\n0.8,0.4,0,0.1\n1.0,0.4,0,0.04\n"
         "1.5,0.4,0,0.04\n";

  const auto simulated = dir / "simulated.json";
  test::ProcessResult run = test::runProcess(
      SHAPEDB_CLI, {"haptic", db.string(), scene.string(), "--trajectory", trajectory.string(), "--seconds",
                    "1.5", "--report", simulated.string(), "--simulate", "--material", "aluminium"});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("b-open.obj: not augmented"), std::string::npos) << run.err;
  const nlohmann::json r = readJson(simulated);
  EXPECT_EQ(r["clock"], "simulated");
  EXPECT_EQ(r["ticks"], 1500);
  EXPECT_EQ(r["objects"].size(), 3u);
  EXPECT_EQ(r["objects_augmented"], 2);
  EXPECT_EQ(r["objects_failed"], 1);
  EXPECT_EQ(r["objects"][1]["name"], "b-open.obj");
  EXPECT_EQ(r["objects"][1]["state"], "failed");
  EXPECT_NE(r["objects"][1]["error"].get<std::string>().find("not closed"), std::string::npos)
      << r["objects"][1];
  for (int i : {0, 2}) {
    EXPECT_EQ(r["objects"][i]["state"], "augmented");
    EXPECT_EQ(r["objects"][i]["entry"].get<std::string>().rfind("box-", 0), 0u) << r["objects"][i];
    EXPECT_NEAR(r["objects"][i]["augmentation_latency_ms"].get<double>(), 20.0, 1e-6);
  }
  EXPECT_GT(r["contact_ticks"].get<int>(), 500);  // 0.4 s pressed on each box, less the approach
  EXPECT_GT(r["max_force_n"].get<double>(), 0.0);
  EXPECT_LE(r["max_force_n"].get<double>(), 10.0);  // the default device limit
  EXPECT_EQ(r["material"], "aluminium");
  for (const char* key : {"p50", "p99", "max"})
    EXPECT_GE(r["tick_us"][key].get<double>(), 0.0) << key;

  EXPECT_EQ(r["options"]["correct"], false);

  // The same scene on the steady clock, augmented with the geometry correction: the structure is the
  // same; the timing is the machine's.
  const auto steady = dir / "steady.json";
  run = test::runProcess(
      SHAPEDB_CLI, {"haptic", db.string(), scene.string(), "--trajectory", trajectory.string(), "--seconds",
                    "0.5", "--report", steady.string(), "--correct"});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("deadline misses"), std::string::npos) << run.out;
  const nlohmann::json s = readJson(steady);
  EXPECT_EQ(s["clock"], "steady");
  EXPECT_EQ(s["options"]["correct"], true);
  EXPECT_GT(s["ticks"].get<int>(), 0);
  EXPECT_GT(s["achieved_rate_hz"].get<double>(), 0.0);
  EXPECT_GE(s["deadline_misses"].get<int>(), 0);
  int accounted = 0;
  for (const char* key : {"objects_augmented", "objects_failed", "objects_pending"})
    accounted += s[key].get<int>();
  EXPECT_LE(accounted, 3);
  EXPECT_TRUE(s["augmentation_latency_ms"].contains("p99"));
}

TEST(FractureCli, WritesClosedFragmentsTheSameForTheSameSeedAndFeedsTheHapticLoop) {
  test::ScratchDir dir("fracture-cli");
  const auto plate = dir / "plate.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.4, 0.3, 0.02}), plate).ok());
  const auto out = dir / "pieces", again = dir / "again";
  for (const auto& target : {out, again}) {
    test::ProcessResult r =
        test::runProcess(SHAPEDB_CLI, {"fracture", plate.string(), "--pieces", "6", "--seed", "3",
                                       "--resolution", "48", "--out", target.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("fragments from 6 seeds"), std::string::npos) << r.out;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(out))
    files.push_back(entry.path());
  ASSERT_GE(files.size(), 4u);
  for (const auto& file : files) {
    auto mesh = io::loadMesh(file);
    ASSERT_TRUE(mesh.ok()) << mesh.error().message;
    EXPECT_TRUE(mesh->topology.isClosed()) << file;
    EXPECT_EQ(test::readFile(file), test::readFile(again / file.filename())) << file.filename();
  }

  // --format glb: the same fragments for a game engine, read back within single precision of each.
  const auto glb = dir / "glb";
  test::ProcessResult asGlb =
      test::runProcess(SHAPEDB_CLI, {"fracture", plate.string(), "--pieces", "6", "--seed", "3",
                                     "--resolution", "48", "--format", "glb", "--out", glb.string()});
  ASSERT_EQ(asGlb.exitCode, 0) << asGlb.err;
  for (const auto& file : files) {
    std::filesystem::path binary = glb / file.filename();
    binary.replace_extension(".glb");
    auto fromGlb = io::loadMesh(binary);
    auto fromObj = io::loadMesh(file);
    ASSERT_TRUE(fromGlb.ok()) << fromGlb.error().message;
    EXPECT_TRUE(fromGlb->topology.isClosed()) << binary;
    EXPECT_EQ(fromGlb->mesh.triangles, fromObj->mesh.triangles) << binary;
    EXPECT_LT(test::maxVertexDifference(fromGlb->mesh, fromObj->mesh), 1e-7) << binary;
  }

  // --max-triangles: the same fragments, coarser (and still closed); a count under 100 is refused.
  const auto coarse = dir / "coarse";
  test::ProcessResult few = test::runProcess(
      SHAPEDB_CLI, {"fracture", plate.string(), "--pieces", "6", "--seed", "3", "--resolution", "48",
                    "--max-triangles", "200", "--out", coarse.string()});
  ASSERT_EQ(few.exitCode, 0) << few.err;
  std::size_t fine = 0, coarseTotal = 0;
  double fineVolume = 0.0, coarseVolume = 0.0;
  for (const auto& file : files) {
    auto full = io::loadMesh(file);
    auto reduced = io::loadMesh(coarse / file.filename());
    ASSERT_TRUE(full.ok() && reduced.ok()) << file.filename();
    EXPECT_TRUE(reduced->topology.isClosed()) << file.filename();
    fine += full->mesh.triangleCount();
    coarseTotal += reduced->mesh.triangleCount();
    fineVolume += core::computeMassProperties(full->mesh)->volume;
    coarseVolume += core::computeMassProperties(reduced->mesh)->volume;
  }
  EXPECT_EQ(static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(coarse),
                                                   std::filesystem::directory_iterator())),
            files.size());
  EXPECT_NEAR(coarseVolume, fineVolume, 0.02 * fineVolume);
  std::printf("fragments: %zu triangles, %zu with --max-triangles 200\n", fine, coarseTotal);
  EXPECT_LT(coarseTotal, fine);
  EXPECT_EQ(test::runProcess(SHAPEDB_CLI, {"fracture", plate.string(), "--max-triangles", "50", "--out",
                                           (dir / "x").string()})
                .exitCode,
            2);

  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 8, "shard,box", 4).exitCode, 0);
  const auto report = dir / "report.json";
  test::ProcessResult run =
      test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), "--fracture", plate.string(), "--pieces", "6",
                                     "--seed", "3", "--resolution", "48", "--simulate", "--seconds", "4",
                                     "--speed", "0.3", "--report", report.string()});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json r = readJson(report);
  EXPECT_EQ(r["scene"], plate.string());
  EXPECT_EQ(r["objects"].size(), files.size());  // the same fragments as shapedb fracture wrote
  EXPECT_GT(r["objects_augmented"].get<int>(), 0);
  EXPECT_EQ(r["objects_failed"], 0);
  EXPECT_GT(r["contact_ticks"].get<int>(), 0);

  // --burst: the fracture as an event, every fragment requested at the first tick (in real time, the
  // proxy nowhere near most of them): all augmented, and the time to all of them reported.
  const auto burstReport = dir / "burst.json";
  test::ProcessResult burst =
      test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), "--fracture", plate.string(), "--pieces", "6",
                                     "--seed", "3", "--resolution", "48", "--burst", "--workers", "2",
                                     "--seconds", "1", "--report", burstReport.string()});
  ASSERT_EQ(burst.exitCode, 0) << burst.err;
  const nlohmann::json b = readJson(burstReport);
  EXPECT_TRUE(b["options"]["burst"].get<bool>());
  EXPECT_EQ(b["objects_augmented"].get<std::size_t>(), files.size()) << burst.out;
  EXPECT_NE(burst.out.find("burst: " + std::to_string(files.size()) +
                           " objects requested at the first tick, all augmented within"),
            std::string::npos)
      << burst.out;

  test::ProcessResult both = test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), out.string(), "--fracture",
                                                            plate.string(), "--report", report.string()});
  EXPECT_EQ(both.exitCode, 2);
  EXPECT_NE(both.err.find("not both"), std::string::npos) << both.err;
  test::ProcessResult pieces = test::runProcess(
      SHAPEDB_CLI, {"haptic", db.string(), out.string(), "--pieces", "4", "--report", report.string()});
  EXPECT_EQ(pieces.exitCode, 2);
  const auto openPath = dir / "open.obj";
  std::ofstream(openPath) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n";
  test::ProcessResult open = test::runProcess(
      SHAPEDB_CLI, {"fracture", openPath.string(), "--pieces", "3", "--out", (dir / "x").string()});
  EXPECT_EQ(open.exitCode, 1);
  EXPECT_NE(open.err.find("open.obj: mesh is not closed"), std::string::npos) << open.err;
}

TEST(HapticCli, BadInputsAreClearErrors) {
  test::ScratchDir dir("haptic-cli-bad");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 2, "box", 2).exitCode, 0);
  const auto scene = dir / "scene";
  std::filesystem::create_directories(scene);
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.1, 0.1, 0.1}), scene / "box.obj").ok());
  const auto report = (dir / "r.json").string();

  test::ProcessResult noScene =
      test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), (dir / "nowhere").string(), "--report", report});
  EXPECT_EQ(noScene.exitCode, 1);
  EXPECT_NE(noScene.err.find("nowhere: not a directory"), std::string::npos) << noScene.err;

  const auto empty = dir / "empty";
  std::filesystem::create_directories(empty);
  test::ProcessResult emptyScene =
      test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), empty.string(), "--report", report});
  EXPECT_EQ(emptyScene.exitCode, 1);
  EXPECT_NE(emptyScene.err.find("no mesh files"), std::string::npos) << emptyScene.err;

  const auto csv = dir / "bad.csv";
  std::ofstream(csv) << "0,0,0,0\n1,0,0\n";
  test::ProcessResult badCsv = test::runProcess(
      SHAPEDB_CLI, {"haptic", db.string(), scene.string(), "--trajectory", csv.string(), "--report", report});
  EXPECT_EQ(badCsv.exitCode, 1);
  EXPECT_NE(badCsv.err.find("bad.csv:2:"), std::string::npos) << badCsv.err;

  test::ProcessResult rate = test::runProcess(
      SHAPEDB_CLI, {"haptic", db.string(), scene.string(), "--report", report, "--rate", "0"});
  EXPECT_EQ(rate.exitCode, 2);
  test::ProcessResult noReport = test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), scene.string()});
  EXPECT_EQ(noReport.exitCode, 2);
  EXPECT_NE(noReport.err.find("--report"), std::string::npos) << noReport.err;

  test::ProcessResult notDb = test::runProcess(
      SHAPEDB_CLI, {"haptic", (scene / "box.obj").string(), scene.string(), "--report", report});
  EXPECT_EQ(notDb.exitCode, 1);
  EXPECT_NE(notDb.err.find("box.obj"), std::string::npos) << notDb.err;
  EXPECT_FALSE(std::filesystem::exists(report)) << "no report from runs that failed";
}

}  // namespace
}  // namespace shapedb::cli
