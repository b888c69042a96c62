// The learning database: objects computed in the background and learned as entries while queries go on.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/database.h>
#include <shapedb/io/enrich.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/tetrahedralize.h>

#include "support/synthetic.h"
#include "support/test_support.h"

namespace shapedb::io {
namespace {

// A database of four boxes and cylinders: nothing in it resembles a lopsided blob.
std::filesystem::path tinyDatabase(const test::ScratchDir& dir) {
  const std::filesystem::path path = dir / "tiny.db";
  BuildOptions options;
  options.parameters.entries = 4;
  options.parameters.families = {volume::Family::kBox, volume::Family::kCylinder};
  options.parameters.entry.modal.modes = 6;
  options.threads = 2;
  auto report = buildDatabase(path, options);
  EXPECT_TRUE(report.ok()) << (report ? "" : report.error().message);
  return path;
}

Database::OpenOptions learning() {
  Database::OpenOptions o;
  o.learn = true;
  return o;
}

NamedMesh blob(double a, double b, double c, const std::string& name) {
  return {name, name + ".obj", test::makeLopsidedBlob(core::Vec3(a, b, c), 2)};
}

Result<Learned> learnedOf(const std::shared_future<Result<Learned>>& future) {
  EXPECT_EQ(future.wait_for(std::chrono::minutes(5)), std::future_status::ready);
  return future.get();
}

TEST(Enrich, AQueriedMeshIsLearnedAndThenMatchesItselfWithTheDirectComputationsFrequencies) {
  test::ScratchDir dir("enrich-self");
  const auto path = tinyDatabase(dir);
  auto db = Database::open(path, learning());
  ASSERT_TRUE(db.ok()) << db.error().message;
  const NamedMesh object = blob(1.0, 0.6, 0.35, "blob");

  auto first = db->query(object.mesh);
  ASSERT_TRUE(first.ok()) << first.error().message;
  ASSERT_NE(first->matches.front().entry->family, volume::Family::kLearned);
  const double firstDistance = first->matches.front().match.distance;

  Enricher enricher(*db);
  auto learned = learnedOf(enricher.submit(object));
  ASSERT_TRUE(learned.ok()) << learned.error().message;
  EXPECT_TRUE(learned->computed);
  EXPECT_EQ(learned->name, learnedName(object.mesh));
  ASSERT_NE(db->entry(learned->id), nullptr);
  EXPECT_EQ(db->entry(learned->id)->family, volume::Family::kLearned);
  EXPECT_EQ(db->entry(learned->name), db->entry(learned->id));
  EXPECT_EQ(db->size(), 5u);

  // Queried again under a random similarity: its own entry, at a distance near zero, with the
  // frequencies of the object computed directly.
  std::mt19937_64 rng(5);
  const core::TriangleMesh moved = core::transformed(object.mesh, test::randomSimilarity(rng, 5.0, 0.2, 5.0));
  auto second = db->query(moved);
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_EQ(second->matches.front().match.entry, learned->id);
  EXPECT_LT(second->matches.front().match.distance, 0.05 * firstDistance);
  EXPECT_LT(second->matches.front().match.distance, 1e-2);

  auto direct = volume::computeEntry(moved, db->parameters().entry);
  ASSERT_TRUE(direct.ok()) << direct.error().message;
  auto directAdapted =
      core::adapt(direct->physics, second->normalization, second->massProperties, core::Mat3::Identity(),
                  QueryOptions{}.material, db->parameters().entry.damping);
  ASSERT_TRUE(directAdapted.ok());
  const Eigen::VectorXd got = second->physics->frequenciesHz(), want = directAdapted->frequenciesHz();
  ASSERT_EQ(got.size(), want.size());
  double worst = 0.0;
  for (Eigen::Index i = 0; i < got.size(); ++i) {
    EXPECT_NEAR(got[i], want[i], 0.005 * want[i]) << "mode " << i;
    worst = std::max(worst, std::abs(got[i] / want[i] - 1.0));
  }
  std::printf(
      "first answer %s at distance %.4g; learned in %.2f s; second answer at distance %.3g, "
      "frequencies within %.2g of the direct computation's\n",
      first->matches.front().entry->name.c_str(), firstDistance, learned->seconds,
      second->matches.front().match.distance, worst);
}

TEST(Enrich, AnObjectIsComputedOnceWhetherQueuedLearnedOrLearnedByAnEarlierRun) {
  test::ScratchDir dir("enrich-once");
  const auto path = tinyDatabase(dir);
  const NamedMesh object = blob(1.0, 0.7, 0.5, "pebble");
  core::EntryId id = 0;
  {
    auto db = Database::open(path, learning());
    ASSERT_TRUE(db.ok()) << db.error().message;
    Enricher enricher(*db);
    const auto a = enricher.submit(object), b = enricher.submit(object);  // the second while the first runs
    auto first = learnedOf(a), again = learnedOf(b);
    ASSERT_TRUE(first.ok()) << first.error().message;
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(first->id, again->id);
    EXPECT_EQ(db->size(), 5u);  // one entry for both
    auto later = learnedOf(enricher.submit(object));
    ASSERT_TRUE(later.ok());
    EXPECT_FALSE(later->computed);
    EXPECT_EQ(later->id, first->id);
    id = first->id;
  }
  // Another run on the same file: the database remembers.
  auto db = Database::open(path, learning());
  ASSERT_TRUE(db.ok()) << db.error().message;
  ASSERT_NE(db->entry(id), nullptr);
  EXPECT_EQ(db->entry(id)->family, volume::Family::kLearned);
  EXPECT_EQ(db->entry(id)->source, "pebble.obj");
  Enricher enricher(*db);
  auto known = learnedOf(enricher.submit(object));
  ASSERT_TRUE(known.ok());
  EXPECT_FALSE(known->computed);
  EXPECT_EQ(known->id, id);
  EXPECT_EQ(db->size(), 5u);
}

// The Enricher's workers fork their TetGen processes before its constructor returns (a fork stalls the
// page faults of every thread of the process: a haptic loop started after the Enricher sees none), and
// learning an object forks nothing more.
TEST(Enrich, TheWorkersForkTheirTetGenProcessesBeforeTheEnricherIsReady) {
  test::ScratchDir dir("enrich-forks");
  const auto path = tinyDatabase(dir);
  auto db = Database::open(path, learning());
  ASSERT_TRUE(db.ok()) << db.error().message;
  const int before = volume::testing::tetGenWorkersStarted();
  Enricher enricher(*db, {.workers = 2});
  EXPECT_EQ(volume::testing::tetGenWorkersStarted(), before + 2);
  auto learned = learnedOf(enricher.submit(blob(1.0, 0.7, 0.5, "pebble")));
  ASSERT_TRUE(learned.ok()) << learned.error().message;
  EXPECT_TRUE(learned->computed);
  EXPECT_EQ(volume::testing::tetGenWorkersStarted(), before + 2);
}

TEST(Enrich, ABadObjectFailsByNameAndIsNotComputedAgain) {
  test::ScratchDir dir("enrich-bad");
  const auto path = tinyDatabase(dir);
  auto db = Database::open(path, learning());
  ASSERT_TRUE(db.ok()) << db.error().message;
  NamedMesh open{"lid", "lid.obj", core::makeBox(core::Vec3(1.0, 2.0, 3.0))};
  open.mesh.triangles.pop_back();
  Enricher enricher(*db);
  auto failed = learnedOf(enricher.submit(open));
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kNotClosed) << failed.error().message;
  EXPECT_NE(failed.error().message.find("lid.obj"), std::string::npos) << failed.error().message;
  const auto again = enricher.submit(open);
  EXPECT_EQ(again.wait_for(std::chrono::seconds(0)), std::future_status::ready);  // the same answer, at once
  EXPECT_FALSE(again.get().ok());
  EXPECT_EQ(db->size(), 4u);
}

TEST(Enrich, ShutDownAbandonsTheQueueAndKeepsWhatWasCommitted) {
  test::ScratchDir dir("enrich-shutdown");
  const auto path = tinyDatabase(dir);
  std::vector<std::shared_future<Result<Learned>>> futures;
  {
    auto db = Database::open(path, learning());
    ASSERT_TRUE(db.ok()) << db.error().message;
    Enricher enricher(*db, {.workers = 1});
    for (int i = 0; i < 4; ++i)
      futures.push_back(enricher.submit(blob(1.0, 0.5 + 0.1 * i, 0.3, "stone" + std::to_string(i))));
  }
  std::size_t learned = 0, cancelled = 0;
  for (const auto& f : futures) {
    ASSERT_EQ(f.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    if (f.get().ok())
      ++learned;
    else if (f.get().error().code == ErrorCode::kCancelled)
      ++cancelled;
  }
  EXPECT_EQ(learned + cancelled, futures.size());
  EXPECT_GE(cancelled, 2u);  // one worker: at most the first two had started when the enricher went
  auto store = Store::open(path);
  ASSERT_TRUE(store.ok());
  EXPECT_EQ(store->entries()->size(), 4u + learned);
  auto check = store->check();
  ASSERT_TRUE(check.ok());
  EXPECT_TRUE(check->ok());
}

// Queries running while objects are learned: every one answers, from entries whose data it can read
// (a learned entry is searchable only once it is in the file), and once learned each object matches
// itself.
TEST(Enrich, QueriesBesideLearningAnswerFromReadableEntries) {
  test::ScratchDir dir("enrich-beside");
  const auto path = tinyDatabase(dir);
  auto db = Database::open(path, learning());
  ASSERT_TRUE(db.ok()) << db.error().message;
  std::vector<NamedMesh> objects;
  for (int i = 0; i < 2; ++i)
    objects.push_back(blob(1.0, 0.8 - 0.15 * i, 0.3 + 0.1 * i, "rock" + std::to_string(i)));
  std::atomic<bool> learning{true};
  std::atomic<int> queries{0}, failures{0}, sawLearned{0};
  const auto querier = [&](int seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    QueryOptions options;
    options.search.parallel = false;
    while (learning.load() || queries.load() < 20) {
      const NamedMesh& o = objects[static_cast<std::size_t>(queries.load()) % objects.size()];
      auto r = db->query(core::transformed(o.mesh, test::randomSimilarity(rng, 2.0, 0.5, 2.0)), options);
      ++queries;
      if (!r || !r->physics || r->matches.front().entry == nullptr) {
        ++failures;
        continue;
      }
      if (r->matches.front().entry->family == volume::Family::kLearned) ++sawLearned;
      // Paced, so that the learning thread is not starved on a machine of two cores (it took 52 s under
      // the sanitizers, back to back); the queries still overlap every stage of the learning.
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  };
  std::thread a(querier, 1), b(querier, 2);
  Enricher enricher(*db);
  std::vector<std::shared_future<Result<Learned>>> futures;
  for (const NamedMesh& o : objects)
    futures.push_back(enricher.submit(o));
  for (const auto& f : futures)
    EXPECT_TRUE(learnedOf(f).ok());
  learning = false;
  a.join();
  b.join();
  EXPECT_EQ(failures.load(), 0) << "of " << queries.load();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    auto r = db->query(objects[i].mesh);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->matches.front().entry->name, learnedName(objects[i].mesh)) << objects[i].name;
  }
}

TEST(Enrich, LearningNeedsTheLearningOpenAndAFreeName) {
  test::ScratchDir dir("enrich-open");
  const auto path = tinyDatabase(dir);
  const NamedMesh object = blob(1.0, 0.6, 0.4, "cobble");
  auto data = volume::computeEntry(object.mesh, Store::open(path)->parameters().entry);
  ASSERT_TRUE(data.ok()) << data.error().message;
  {
    auto reading = Database::open(path);
    ASSERT_TRUE(reading.ok());
    auto refused = reading->learn("learned-x", "cobble.obj", *data);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(refused.error().message.find("OpenOptions::learn"), std::string::npos)
        << refused.error().message;
  }
  auto db = Database::open(path, learning());
  ASSERT_TRUE(db.ok());
  const std::string taken = db->entries().front().name;
  auto clash = db->learn(taken, "cobble.obj", *data);
  ASSERT_FALSE(clash.ok());
  EXPECT_NE(clash.error().message.find(taken), std::string::npos) << clash.error().message;
  auto id = db->learn("learned-x", "cobble.obj", *data);
  ASSERT_TRUE(id.ok()) << id.error().message;
  EXPECT_GT(*id, db->entries().back().id);
  ASSERT_EQ(db->learnedEntries().size(), 1u);
  EXPECT_EQ(db->learnedEntries().front().name, "learned-x");
}

TEST(Enrich, TheSurfaceKeyIsTheSurfaceAsGiven) {
  const core::TriangleMesh box = core::makeBox(core::Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(surfaceKey(box), surfaceKey(core::makeBox(core::Vec3(1.0, 2.0, 3.0))));
  EXPECT_EQ(surfaceKey(box).size(), 16u);
  EXPECT_NE(surfaceKey(box), surfaceKey(core::makeBox(core::Vec3(1.0, 2.0, 3.000001))));
  core::TriangleMesh turned = box;
  std::rotate(turned.triangles.front().begin(), turned.triangles.front().begin() + 1,
              turned.triangles.front().end());
  EXPECT_NE(surfaceKey(box), surfaceKey(turned));
  EXPECT_EQ(learnedName(box), "learned-" + surfaceKey(box));
}

}  // namespace
}  // namespace shapedb::io
