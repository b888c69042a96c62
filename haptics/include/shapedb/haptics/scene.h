#pragma once

// Scenes from files and augmentation from a shape database: what turns the loop of loop.h into
// `shapedb haptic`. Part of shapedb::haptics_io (the loop itself needs only core).

#include <filesystem>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/haptics/loop.h>
#include <shapedb/io/database.h>
#include <shapedb/io/enrich.h>
#include <shapedb/io/mesh_io.h>

namespace shapedb::haptics {

/// Every mesh file (OBJ, PLY, OFF, STL, glTF) directly in `directory`, in name order, each an object in the
/// world frame (metres) named after its file. A file that does not read is an error naming it; a mesh
/// that reads but cannot be queried (say, open) is loaded, and its augmentation fails in the loop with
/// that reason. Each file is read with `options` (its unit, welding). Errors: kIo (not a directory, or no
/// mesh in it), and loadMesh's.
Result<std::vector<SceneObject>> loadScene(const std::filesystem::path& directory,
                                           const io::LoadOptions& options = {});

/// Augmentation by the database (Algorithm 1): query, fetch, adapt to `options.material`, link. The
/// contact locator is the answer's (QueryResult::locator): the entry's own, shared through the database's
/// cache, or with options.correct the corrected tets'. `options.adapt` and
/// `options.link` are forced on. The database must outlive the function; it is safe to call from
/// several workers at once.
AugmentFunction databaseAugmenter(const io::Database& database, io::QueryOptions options);

/// databaseAugmenter, and each object's exact data learned meanwhile: the object goes to `enricher`
/// (which learns into `database`, opened with Database::OpenOptions::learn), and once its entry is
/// learned the object is queried again and those data replace the first (AugmentedObject::upgrade). An
/// object whose first match is a learned entry at a distance of round-off (itself, or a copy of it
/// elsewhere in the scene, learned before) gets no upgrade. The database, the enricher and the scene's
/// objects must outlive the loop.
/// `above` > 0: only objects whose answer's predicted first-frequency error (QueryResult::
/// predictedFrequencyError; the fidelity report is then computed) is above it are learned.
AugmentFunction learningAugmenter(const io::Database& database, io::Enricher& enricher,
                                  io::QueryOptions options, double above = 0.0);

}  // namespace shapedb::haptics
