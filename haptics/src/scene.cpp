#include <chrono>
#include <future>
#include <optional>
#include <string>
#include <system_error>

#include <shapedb/haptics/scene.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/families.h>

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

namespace {

/// A learned entry this close to an object (descriptor distance) is the object itself, moved or scaled:
/// the same surface anywhere matches its entry at round-off, a different one at 1e-3 or more.
constexpr double kSelfDistance = 1e-6;

/// An object's data from the database's answer to it; `best`, if given, gets the answer's best match.
Result<AugmentedObject> augmentFrom(const io::Database& database, const io::QueryOptions& options,
                                    const SceneObject& object, io::MatchReport* best = nullptr,
                                    std::optional<double>* predictedError = nullptr) {
  Result<io::QueryResult> result = database.query(object.mesh, options);
  if (!result) return withContext(result.error(), object.name);
  if (result->matches.empty() || !result->physics)
    return Error{ErrorCode::kInvalidArgument, object.name + ": the database gave no match"};
  const io::MatchReport& match = result->answeredMatch();
  AugmentedObject augmented;
  augmented.source = match.entry ? match.entry->name : std::to_string(match.match.entry);
  augmented.physics = std::move(*result->physics);
  augmented.link = std::move(result->link);
  // The answer's own: the corrected tets' where the geometry correction ran, not the entry's.
  augmented.locator = std::move(result->locator);
  augmented.locatorFrame = augmented.physics.placement;
  if (best) *best = match;
  if (predictedError) *predictedError = result->predictedFrequencyError;
  return augmented;
}

}  // namespace

AugmentFunction databaseAugmenter(const io::Database& database, io::QueryOptions options) {
  options.adapt = true;
  options.link = true;
  return [&database, options](const SceneObject& object) { return augmentFrom(database, options, object); };
}

AugmentFunction learningAugmenter(const io::Database& database, io::Enricher& enricher,
                                  io::QueryOptions options, double above) {
  options.adapt = true;
  options.link = true;
  if (above > 0.0) options.fidelity = true;  // the predicted error's evidence
  return [&database, &enricher, options, above](const SceneObject& object) -> Result<AugmentedObject> {
    io::MatchReport best;
    std::optional<double> predicted;
    Result<AugmentedObject> first = augmentFrom(database, options, object, &best, &predicted);
    if (!first) return first;
    // Learned already, here or elsewhere in the scene (a copy of it moved): nothing better to come.
    if (best.entry && best.entry->family == volume::Family::kLearned && best.match.distance < kSelfDistance)
      return first;
    if (above > 0.0 && predicted && *predicted <= above) return first;  // good enough as it is
    const std::shared_future<Result<io::Learned>> learned =
        enricher.submit({object.name, object.name, object.mesh});
    const SceneObject* scene = &object;  // the scene outlives the loop
    first->upgrade = Upgrade{
        [learned] { return learned.wait_for(std::chrono::seconds(0)) == std::future_status::ready; },
        [learned, &database, options, scene]() -> Result<std::optional<AugmentedObject>> {
          if (!learned.get()) return learned.get().error();
          Result<AugmentedObject> exact = augmentFrom(database, options, *scene);  // its learned entry now
          if (!exact) return exact.error();
          return std::optional<AugmentedObject>(std::move(exact).value());
        }};
    return first;
  };
}

}  // namespace shapedb::haptics
