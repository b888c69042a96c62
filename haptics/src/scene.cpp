#include <chrono>
#include <future>
#include <string>
#include <system_error>

#include <shapedb/haptics/scene.h>
#include <shapedb/io/mesh_io.h>

namespace shapedb::haptics {

namespace fs = std::filesystem;

Result<std::vector<SceneObject>> loadScene(const fs::path& directory, const io::LoadOptions& options) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec))
    return Error{ErrorCode::kIo, directory.string() + ": not a directory (a scene is a directory of meshes)"};
  Result<std::vector<fs::path>> files = io::listMeshFiles(directory);
  if (!files) return files.error();

  std::vector<SceneObject> objects;
  objects.reserve(files->size());
  for (const fs::path& file : *files) {
    Result<io::LoadedMesh> loaded = io::loadMesh(file, options);
    if (!loaded) return loaded.error();  // names the file
    objects.push_back({file.filename().string(), std::move(loaded->mesh)});
  }
  return objects;
}

AugmentFunction databaseAugmenter(const io::Database& database, io::QueryOptions options) {
  options.adapt = true;
  options.link = true;
  return [&database, options](const SceneObject& object) -> Result<AugmentedObject> {
    Result<io::QueryResult> result = database.query(object.mesh, options);
    if (!result) return withContext(result.error(), object.name);
    if (result->matches.empty() || !result->physics)
      return Error{ErrorCode::kInvalidArgument, object.name + ": the database gave no match"};
    const io::MatchReport& best = result->matches.front();
    Result<std::shared_ptr<const core::TetLocator>> locator = database.locator(best.match.entry);
    if (!locator) return withContext(locator.error(), object.name);
    AugmentedObject augmented;
    augmented.source = best.entry ? best.entry->name : std::to_string(best.match.entry);
    augmented.physics = std::move(*result->physics);
    augmented.link = std::move(result->link);
    augmented.locator = std::move(*locator);
    augmented.locatorFrame = augmented.physics.placement;
    return augmented;
  };
}

AugmentFunction learningAugmenter(const io::Database& database, io::Enricher& enricher,
                                  io::QueryOptions options) {
  AugmentFunction nearest = databaseAugmenter(database, options);
  return [&enricher, nearest](const SceneObject& object) -> Result<AugmentedObject> {
    Result<AugmentedObject> first = nearest(object);
    if (!first) return first;
    if (first->source == io::learnedName(object.mesh)) return first;  // learned already: nothing better
    const std::shared_future<Result<io::Learned>> learned =
        enricher.submit({object.name, object.name, object.mesh});
    const SceneObject* scene = &object;  // the scene outlives the loop
    first->upgrade =
        Upgrade{[learned] { return learned.wait_for(std::chrono::seconds(0)) == std::future_status::ready; },
                [learned, nearest, scene]() -> Result<std::optional<AugmentedObject>> {
                  if (!learned.get()) return learned.get().error();
                  Result<AugmentedObject> exact = nearest(*scene);  // matches its learned entry now
                  if (!exact) return exact.error();
                  return std::optional<AugmentedObject>(std::move(exact).value());
                }};
    return first;
  };
}

}  // namespace shapedb::haptics
