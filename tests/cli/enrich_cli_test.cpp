// shapedb enrich and query --enrich, run as the real executable.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/primitives.h>
#include <shapedb/io/store.h>

#include "cli/cli_test_support.h"
#include "support/mesh_files.h"
#include "support/synthetic.h"
#include "support/test_support.h"

namespace shapedb {
namespace {

// Lopsided blobs of `count` proportions, written as OBJ files: nothing like the boxes of the database.
std::vector<std::string> writeBlobs(const test::ScratchDir& dir, int count) {
  std::vector<std::string> files;
  for (int i = 0; i < count; ++i) {
    const auto path = dir / ("blob" + std::to_string(i) + ".obj");
    test::writeFile(
        path, test::objText(test::makeLopsidedBlob(core::Vec3(1.0, 0.9 - 0.08 * i, 0.3 + 0.05 * i), 2)));
    files.push_back(path.string());
  }
  return files;
}

std::size_t learnedEntries(const std::filesystem::path& db) {
  auto store = io::Store::open(db);
  if (!store) return 0;
  auto entries = store->entries();
  if (!entries) return 0;
  std::size_t n = 0;
  for (const io::EntryRecord& e : *entries)
    n += e.family == volume::Family::kLearned ? 1 : 0;
  return n;
}

TEST(EnrichCli, KilledMidEnrichmentKeepsWhatItCommittedAndTheRerunComputesOnlyTheRest) {
  test::ScratchDir dir("enrich-kill");
  const auto db = dir / "scenario.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "box", 4).exitCode, 0);
  const std::vector<std::string> meshes = writeBlobs(dir, 6);
  std::vector<std::string> args = {"enrich", db.string(), "--workers", "1"};
  args.insert(args.end(), meshes.begin(), meshes.end());

  {
    test::RunningProcess enrich(SHAPEDB_CLI, args);
    ASSERT_TRUE(enrich.started());
    test::waitUntil([&] { return learnedEntries(db) >= 2; }, 120.0);
    ASSERT_TRUE(enrich.kill()) << "the enrichment finished before it was killed";
  }
  const std::size_t atKill = learnedEntries(db);
  std::printf("killed with %zu of 6 meshes learned\n", atKill);
  ASSERT_GE(atKill, 2u);
  ASSERT_LT(atKill, 6u);
  auto store = io::Store::open(db);
  ASSERT_TRUE(store.ok()) << store.error().message;
  auto check = store->check();
  ASSERT_TRUE(check.ok());
  EXPECT_TRUE(check->ok()) << "the killed run left a damaged file";

  const test::ProcessResult rerun = test::runProcess(SHAPEDB_CLI, args);
  ASSERT_EQ(rerun.exitCode, 0) << rerun.err;
  EXPECT_NE(
      rerun.out.find(std::to_string(6 - atKill) + " learned, " + std::to_string(atKill) + " already there"),
      std::string::npos)
      << rerun.out;
  EXPECT_EQ(learnedEntries(db), 6u);
}

TEST(EnrichCli, QueryEnrichAnswersTwiceAndTheSecondAnswerIsTheLearnedEntry) {
  test::ScratchDir dir("enrich-query");
  const auto db = dir / "scenario.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "box,cylinder", 4).exitCode, 0);
  const std::vector<std::string> meshes = writeBlobs(dir, 1);
  const auto open = dir / "open.obj";
  core::TriangleMesh lid = core::makeBox(core::Vec3(1.0, 2.0, 3.0));
  lid.triangles.pop_back();
  test::writeFile(open, test::objText(lid));

  // Predicted to be good enough (a threshold no answer reaches): queried, not learned, and said so.
  const test::ProcessResult skipped =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), meshes[0], "--enrich", "--enrich-above", "100"});
  ASSERT_EQ(skipped.exitCode, 0) << skipped.err;
  EXPECT_NE(skipped.err.find("not learned: predicted error"), std::string::npos) << skipped.err;
  EXPECT_EQ(learnedEntries(db), 0u);

  const test::ProcessResult r =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), meshes[0], open.string(), "--enrich", "--json"});
  EXPECT_EQ(r.exitCode, 1) << r.err;  // the open mesh
  EXPECT_NE(r.err.find("open.obj"), std::string::npos) << r.err;
  const auto json = nlohmann::json::parse(r.out);
  ASSERT_EQ(json["queries"].size(), 1u);
  const auto& q = json["queries"][0];
  EXPECT_NE(q["matches"][0]["family"], "learned");
  ASSERT_TRUE(q.contains("learned")) << q.dump();
  EXPECT_TRUE(q["learned"]["computed"].get<bool>());
  const auto& again = q["after_learning"];
  EXPECT_EQ(again["matches"][0]["name"], q["learned"]["name"]);
  EXPECT_EQ(again["matches"][0]["family"], "learned");
  EXPECT_LT(again["matches"][0]["distance"].get<double>(), 1e-9);
  EXPECT_NE(again["physics"]["frequencies_hz"][0], q["physics"]["frequencies_hz"][0]);
  EXPECT_GT(q["predicted_frequency_error"].get<double>(), 0.0);
  // and the match asked for its own (the neighbours blended beside it have no fidelity report)
  EXPECT_GT(q["matches"][0]["predicted_frequency_error"].get<double>(), 0.0) << q["matches"][0].dump();
  EXPECT_LT(again["matches"][0]["predicted_frequency_error"].get<double>(),
            q["matches"][0]["predicted_frequency_error"].get<double>())
      << "the object's own learned entry is predicted closer than the entry it matched before";

  // Learned once: the file keeps it, the next query --enrich does not compute it again.
  const test::ProcessResult second =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), meshes[0], "--enrich", "--json"});
  ASSERT_EQ(second.exitCode, 0) << second.err;
  const auto q2 = nlohmann::json::parse(second.out)["queries"][0];
  EXPECT_EQ(q2["matches"][0]["name"], q["learned"]["name"]);
  EXPECT_FALSE(q2["learned"]["computed"].get<bool>());

  // A read-only database cannot learn, and says so.
  std::filesystem::permissions(db, std::filesystem::perms::owner_read | std::filesystem::perms::group_read);
  test::RunOptions asUser;
  asUser.obeyFilePermissions = true;
  const test::ProcessResult readOnly =
      test::runProcess(SHAPEDB_CLI, {"enrich", db.string(), meshes[0]}, asUser);
  EXPECT_EQ(readOnly.exitCode, 1);
  EXPECT_NE(readOnly.err.find("read-only"), std::string::npos) << readOnly.err;
}

TEST(EnrichCli, HapticEnrichSwapsEachObjectsLearnedDataIntoTheLoop) {
  test::ScratchDir dir("enrich-haptic");
  const auto db = dir / "scenario.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "box", 4).exitCode, 0);
  const auto scene = dir / "scene";
  std::filesystem::create_directories(scene);
  for (int i = 0; i < 2; ++i) {
    core::TriangleMesh prism = core::makeTriangularPrism(0.08, 0.05 + 0.02 * i, 0.1);
    for (core::Vec3& v : prism.vertices)
      v.x() += 0.3 * i;
    test::writeFile(scene / ("prism" + std::to_string(i) + ".obj"), test::objText(prism));
  }
  const auto report = dir / "report.json";
  const test::ProcessResult r =
      test::runProcess(SHAPEDB_CLI, {"haptic", db.string(), scene.string(), "--report", report.string(),
                                     "--seconds", "5", "--speed", "1", "--radius", "0.2", "--enrich"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto json = nlohmann::json::parse(test::readFile(report));
  EXPECT_EQ(json["objects_augmented"], 2);
  EXPECT_EQ(json["objects_learned"], 2) << json.dump(2);
  ASSERT_EQ(json["objects"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& o = json["objects"][i];
    const auto& other = json["objects"][1 - i];
    EXPECT_EQ(o["entry"].get<std::string>().rfind("learned-", 0), 0u) << o.dump();
    // First a box, or the other prism's learned entry where it was learned before this one was met (on a
    // loaded machine the proxy can reach the second prism that late): never its own.
    const std::string first = o["first_entry"];
    EXPECT_TRUE(first.rfind("box-", 0) == 0 || first == other["entry"]) << json.dump(2);
    EXPECT_GT(o["learned_latency_ms"].get<double>(), o["augmentation_latency_ms"].get<double>());
  }
  EXPECT_EQ(learnedEntries(db), 2u);
}

}  // namespace
}  // namespace shapedb
