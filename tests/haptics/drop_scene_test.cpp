// The drop scenario as one library call: meshes given physical data by a real database file, raised to
// the asked height, dropped, summarized and rendered.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <limits>

#include <gtest/gtest.h>

#include <shapedb/core/primitives.h>
#include <shapedb/haptics/drop_scene.h>
#include <shapedb/io/build.h>
#include <shapedb/volume/families.h>

#include "support/test_support.h"

namespace shapedb::haptics {
namespace {

/// A database of two box entries in `dir`, opened.
io::Database boxDatabase(const test::ScratchDir& dir) {
  io::BuildOptions build;
  build.parameters.entries = 2;
  build.parameters.families = {volume::Family::kBox};
  build.parameters.entry.modal.modes = 2;
  build.threads = 2;
  EXPECT_TRUE(io::buildDatabase(dir / "boxes.db", build).ok());
  Result<io::Database> db = io::Database::open(dir / "boxes.db");
  EXPECT_TRUE(db.ok()) << (db ? "" : db.error().message);
  return std::move(db).value();
}

core::TriangleMesh boxAt(const core::Vec3& size, const core::Vec3& center) {
  core::TriangleMesh mesh = core::makeBox(size);
  for (core::Vec3& p : mesh.vertices)
    p += center;
  return mesh;
}

DropSceneOptions steelFor(double seconds) {
  DropSceneOptions options;
  options.material = *core::materialPreset("steel");
  options.height = 0.2;
  options.drop.seconds = seconds;
  return options;
}

TEST(DropScene, BoxesFromADatabaseStartAtTheHeightAndComeToRestOnTheFloor) {
  const test::ScratchDir dir("drop-scene");
  const io::Database db = boxDatabase(dir);
  DropScene scene;
  scene.meshes = {boxAt({0.1, 0.06, 0.04}, {0, 0, 0.5}), boxAt({0.05, 0.05, 0.05}, {0.3, 0, 0.7})};
  scene.names = {"slab", "cube"};
  const Result<DropSceneReport> dropped = dropOnFloor(db, scene, steelFor(3.0));
  ASSERT_TRUE(dropped.ok()) << dropped.error().message;
  ASSERT_EQ(dropped->bodies.size(), 2u);
  EXPECT_TRUE(dropped->skipped.empty());
  EXPECT_EQ(dropped->source, (std::vector<std::size_t>{0, 1}));

  // The lowest collision point of all bodies starts at the asked height.
  double lowest = std::numeric_limits<double>::infinity();
  core::Mat4 lift = core::Mat4::Identity();
  lift(2, 3) = dropped->options.lift;
  for (const RigidBody& b : dropped->bodies)
    for (const core::CollisionShape& s : b.collision.shapes)
      lowest = std::min(lowest, lowestPoint(s, lift));
  EXPECT_NEAR(lowest, 0.2, 1e-9);

  // Steel boxes: the masses of the query's own volumes, both at rest on the floor at the end.
  EXPECT_NEAR(dropped->totalMass, 7850.0 * (0.1 * 0.06 * 0.04 + 0.05 * 0.05 * 0.05), 1e-6);
  EXPECT_EQ(dropped->report.atRest, 2u);
  EXPECT_GT(dropped->deepestAtEnd, -0.002);
  EXPECT_LT(dropped->energyEnd, dropped->energyStart);
  EXPECT_GT(dropped->lastRest, 0.0);
}

TEST(DropScene, AMeshWithoutDataIsSkippedByNameAndNoneWithDataIsAnError) {
  const test::ScratchDir dir("drop-scene-skip");
  const io::Database db = boxDatabase(dir);
  core::TriangleMesh open = boxAt({0.1, 0.1, 0.1}, {0, 0, 0});
  open.triangles.pop_back();  // a boundary: no volume, so no query

  DropScene scene;
  scene.meshes = {open, boxAt({0.05, 0.05, 0.05}, {0.3, 0, 0})};
  scene.names = {"open", "cube"};
  const Result<DropSceneReport> dropped = dropOnFloor(db, scene, steelFor(0.2));
  ASSERT_TRUE(dropped.ok()) << dropped.error().message;
  EXPECT_EQ(dropped->source, std::vector<std::size_t>{1});
  ASSERT_EQ(dropped->skipped.size(), 1u);
  EXPECT_EQ(dropped->skipped[0].name, "open");
  EXPECT_EQ(dropped->skipped[0].error.code, ErrorCode::kNotClosed) << dropped->skipped[0].error.message;

  scene.meshes = {open, open};
  scene.names = {"first", "second"};
  const Result<DropSceneReport> none = dropOnFloor(db, scene, steelFor(0.2));
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code, ErrorCode::kNotClosed) << "the first mesh's error";
  EXPECT_NE(none.error().message.find("first: "), std::string::npos) << none.error().message;
  EXPECT_NE(none.error().message.find("second: "), std::string::npos) << none.error().message;

  scene.names = {"only one name"};
  EXPECT_EQ(dropOnFloor(db, scene, steelFor(0.2)).error().code, ErrorCode::kInvalidArgument);
}

TEST(DropScene, FramesAreWrittenOnePerRecordAndAnUnwritableFolderIsNamed) {
  const test::ScratchDir dir("drop-scene-frames");
  const io::Database db = boxDatabase(dir);
  DropScene scene;
  scene.meshes = {boxAt({0.05, 0.05, 0.05}, {0, 0, 0})};
  scene.names = {"cube"};
  DropSceneOptions options = steelFor(0.25);
  options.drop.recordEvery = 20;
  const Result<DropSceneReport> dropped = dropOnFloor(db, scene, options);
  ASSERT_TRUE(dropped.ok()) << dropped.error().message;
  ASSERT_GE(dropped->report.frames.size(), 3u);

  ASSERT_TRUE(saveDropFrames(scene, *dropped, options.height, dir / "frames").ok());
  for (std::size_t f = 0; f < dropped->report.frames.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%04zu.png", f);
    EXPECT_GT(std::filesystem::file_size(dir / "frames" / name), 100u) << name;
  }
  const auto written = std::distance(std::filesystem::directory_iterator(dir / "frames"), {});
  EXPECT_EQ(static_cast<std::size_t>(written), dropped->report.frames.size());

  test::writeFile(dir / "a-file", "not a folder");
  const Status blocked = saveDropFrames(scene, *dropped, options.height, dir / "a-file" / "frames");
  ASSERT_FALSE(blocked.ok());
  EXPECT_EQ(blocked.error().code, ErrorCode::kIo);
  EXPECT_NE(blocked.error().message.find("a-file"), std::string::npos) << blocked.error().message;
}

}  // namespace
}  // namespace shapedb::haptics
