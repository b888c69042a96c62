// shapedb bench as a user runs it: a real database, a sphere broken by the real fracture, the CSV,
// summary and plots read back.

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "cli_test_support.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted) {
      fields.push_back(field);
      field.clear();
    } else
      field += c;
  }
  fields.push_back(field);
  return fields;
}

TEST(BenchCli, FractureFragmentsEvaluatedWithSaneCsvSummaryAndPlots) {
  test::ScratchDir dir("bench-cli");
  const auto db = dir / "small.db";
  test::ProcessResult built = test::buildWithCli(db, 9, "box,ellipsoid,shard", 5);
  ASSERT_EQ(built.exitCode, 0) << built.err;
  const auto sphere = dir / "sphere.obj";
  ASSERT_TRUE(io::saveMesh(core::makeIcosphere(0.1, 4), sphere).ok());
  const auto out = dir / "out";
  test::ProcessResult r =
      test::runProcess(SHAPEDB_CLI, {"bench", db.string(), "--fracture", sphere.string(), "--pieces", "3",
                                     "--resolution", "48", "--max-triangles", "400", "--truth-refinement",
                                     "2", "--out", out.string(), "--material", "glass", "--threads", "2"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("| centroid-voxel |"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("direct computations done"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("a warm-up round, then"), std::string::npos) << r.err;  // on by default

  std::ifstream csv(out / "evaluation.csv");
  ASSERT_TRUE(csv.good());
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = splitCsv(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i)
    column[header[i]] = i;
  for (const char* name : {"shape", "method", "f1_hz", "f1_truth_hz", "f1_error", "iou", "speedup", "status"})
    ASSERT_TRUE(column.count(name)) << name;
  std::vector<std::vector<std::string>> rows;
  while (std::getline(csv, line))
    rows.push_back(splitCsv(line));
  const std::vector<std::string> methods{"moment",
                                         "voxel",
                                         "centroid-voxel",
                                         "ellipsoid",
                                         "box",
                                         "centroid-voxel-stretched",
                                         "centroid-voxel-paper",
                                         "centroid-voxel-corrected",
                                         "centroid-voxel-nearest"};
  const std::size_t m = methods.size();
  ASSERT_GE(rows.size(), 2 * m);  // 3 seeds: at least 2 fragments, every method each
  ASSERT_EQ(rows.size() % m, 0u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    ASSERT_EQ(row.size(), header.size()) << i;
    EXPECT_EQ(row[column["method"]], methods[i % m]);
    EXPECT_EQ(row[column["status"]], "ok") << row[column["shape"]];
    if (methods[i % m] == "centroid-voxel-stretched") {  // linear databases only: not evaluated here
      EXPECT_TRUE(row[column["f1_hz"]].empty());
      continue;
    }
    const double f1 = std::stod(row[column["f1_hz"]]), truth = std::stod(row[column["f1_truth_hz"]]);
    // Glass fragments of a 10 cm sphere ring in the kilohertz.
    EXPECT_GT(truth, 1e3);
    EXPECT_LT(truth, 1e6);
    EXPECT_NEAR(std::stod(row[column["f1_error"]]), (f1 - truth) / truth, 1e-6);
    EXPECT_LT(std::abs(std::stod(row[column["f1_error"]])), 1.0);  // same order of magnitude
    const double iou = std::stod(row[column["iou"]]);
    EXPECT_GT(iou, 0.2);
    EXPECT_LE(iou, 1.0);
    // The corrected rows carry their morph's report; the others leave those columns empty.
    const bool corrected = methods[i % m] == "centroid-voxel-corrected";
    for (const char* name : {"worst_quality", "entry_worst_quality", "max_boundary_move",
                             "mean_boundary_move", "projected", "prestretch"}) {
      ASSERT_TRUE(column.count(name)) << name;
      EXPECT_EQ(row[column[name]].empty(), !corrected) << name << " of " << methods[i % m];
    }
    if (corrected) {
      const auto value = [&](const char* name) { return std::stod(row[column[name]]); };
      EXPECT_GT(value("worst_quality"), 0.0);  // every morphed tet positive
      EXPECT_LE(value("worst_quality"), 1.0);
      EXPECT_GT(value("entry_worst_quality"), 0.0);
      EXPECT_GE(value("max_boundary_move"), value("mean_boundary_move"));
      EXPECT_GE(value("mean_boundary_move"), 0.0);
      EXPECT_GE(value("projected"), 0.0);
      EXPECT_LE(value("projected"), 1.0);
      EXPECT_GE(value("prestretch"), 0.0);
    }
    if (methods[i % m] != "ellipsoid" && methods[i % m] != "box") {  // the queries
      EXPECT_GT(std::stod(row[column["speedup"]]), 1.0);
    } else {
      EXPECT_TRUE(row[column["speedup"]].empty());
    }
  }
  const std::string summary = test::readFile(out / "summary.md");
  EXPECT_NE(summary.find("glass"), std::string::npos);
  EXPECT_NE(summary.find("faster"), std::string::npos);
  for (const char* png : {"time.png", "error.png"}) {
    std::ifstream in(out / png, std::ios::binary);
    char magic[8] = {};
    in.read(magic, 8);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG") << png;
  }
}

TEST(BenchCli, UsageAndInputErrorsAreClear) {
  test::ScratchDir dir("bench-cli-errors");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 2, "box", 2).exitCode, 0);
  test::ProcessResult neither =
      test::runProcess(SHAPEDB_CLI, {"bench", db.string(), "--out", (dir / "o").string()});
  EXPECT_EQ(neither.exitCode, 2);
  EXPECT_NE(neither.err.find("--queries DIR or --fracture"), std::string::npos) << neither.err;
  test::ProcessResult missing = test::runProcess(
      SHAPEDB_CLI,
      {"bench", db.string(), "--queries", (dir / "nowhere").string(), "--out", (dir / "o").string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("nowhere: not a directory"), std::string::npos) << missing.err;
  const auto queries = dir / "q";
  std::filesystem::create_directories(queries);
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.1, 0.1, 0.1}), queries / "cube.obj").ok());
  test::ProcessResult tooMany = test::runProcess(
      SHAPEDB_CLI, {"bench", db.string(), "--queries", queries.string(), "--out", (dir / "o").string()});
  EXPECT_EQ(tooMany.exitCode, 2);  // 5 frequencies by default; the database has 2 modes
  EXPECT_NE(tooMany.err.find("2 modes"), std::string::npos) << tooMany.err;
  // Without the warm-up round the summary says the queries were timed in a cold process.
  test::ProcessResult cold = test::runProcess(
      SHAPEDB_CLI, {"bench", db.string(), "--queries", queries.string(), "--frequencies", "2", "--no-warm-up",
                    "--truth-refinement", "2", "--out", (dir / "cold").string()});
  EXPECT_EQ(cold.exitCode, 0) << cold.err;
  EXPECT_EQ(cold.err.find("warm-up round"), std::string::npos) << cold.err;
  EXPECT_NE(cold.out.find("queries timed in a cold process (--no-warm-up)"), std::string::npos) << cold.out;
  test::ProcessResult help = test::runProcess(SHAPEDB_CLI, {"bench", "--help"});
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("physical-fidelity benchmark"), std::string::npos);
}

}  // namespace
}  // namespace shapedb::cli
