#pragma once
// Building a database file: the catalog computed entry by entry in parallel and committed in batches
// (buildDatabase), and user meshes added to a built file (addToDatabase). Querying it is database.h's.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>
#include <shapedb/io/store.h>
#include <shapedb/volume/entry.h>

namespace shapedb::io {

/// Where a build stands, for progress displays. Reported after each entry is computed.
struct BuildProgress {
  std::size_t done = 0;     ///< entries finished in this run (built or failed)
  std::size_t total = 0;    ///< entries this run has to do
  std::size_t failed = 0;   ///< of `done`
  std::size_t skipped = 0;  ///< already in the file when the run started (resume)
  double elapsedSeconds = 0.0;
  std::string lastName;
};

/// One of `count` disjoint parts of a catalog: the entries whose catalog index i has i mod count = index
/// (interleaved, so that every part holds its share of each family and of the costly entries). A part is
/// built into a file of its own, anywhere (a Slurm array task, a Kubernetes indexed job); mergeDatabases
/// joins the parts into the database one build would have made.
struct Shard {
  std::size_t index = 0;  ///< 0 to count − 1
  std::size_t count = 1;  ///< 1: the whole catalog
  bool whole() const { return count == 1; }
  bool holds(std::size_t catalogIndex) const { return catalogIndex % count == index; }
  friend bool operator==(const Shard&, const Shard&) = default;
};
/// "K/N" (0 ≤ K < N ≤ 1,000,000), as toString writes it. Errors: kInvalidArgument saying what is wrong.
Result<Shard> parseShard(std::string_view text);
std::string toString(const Shard& shard);

struct BuildOptions {
  BuildParameters parameters;  ///< for a new file; a resumed build uses the file's own
  /// The part of the catalog to build (a new file records it; a resumed build continues the file's own).
  Shard shard;
  int threads = 0;             ///< 0: all cores
  std::size_t batchSize = 16;  ///< entries per transaction: what a crash can cost
  /// Continue the build in an existing file: entries already in it (or recorded as failed) are skipped.
  bool resume = false;
  /// With resume: called with the file once it is open, before anything is computed; an error ends the
  /// build with it (a command line refusing parameters that differ from the file's, say).
  std::function<Status(const Store& file)> checkResume;
  std::function<void(const BuildProgress&)> progress;  ///< called from one thread at a time
};

/// What a build run did.
struct BuildReport {
  std::size_t built = 0, failed = 0, skipped = 0;
  double seconds = 0.0;             ///< wall time of this run
  volume::StageTimes stageSeconds;  ///< summed over the entries built (CPU-seconds per stage)
};

/// Builds (or, with resume, continues building) the database file at `path`: the catalog of the
/// parameters' families, each entry computed by volume::computeEntry in parallel (TBB) and committed in
/// order, batch by batch. A killed build loses at most the batches not yet committed; resuming redoes
/// them and nothing else, so a resumed build holds exactly what a clean one does. An entry that fails (a
/// shape TetGen refuses, say) is recorded with its reason and the build goes on.
/// Errors: kIo (file exists without resume, or missing with resume; disk), kInvalidArgument (parameters).
Result<BuildReport> buildDatabase(const std::filesystem::path& path, const BuildOptions& options);

/// The part a database file holds (its `shard` meta; a file without one holds the whole catalog).
/// Errors: kParse for an unreadable value.
Result<Shard> storedShard(const Store& store);

/// What a merge did.
struct MergeReport {
  std::size_t entries = 0, failures = 0, shards = 0;
  double seconds = 0.0;
};

/// Joins the shards of one catalog (each built with BuildOptions::shard, all complete) into a new file
/// `out`: their entries with their ids, records and blobs as stored (checksums verified on the way),
/// their failures, and the parameters they share: the database a single build with those parameters
/// would have made, build times aside. Written beside `out` and renamed onto it at the end, so that `out`
/// is whole or absent. Errors: kIo (`out` exists; a shard cannot be read), kInvalidArgument (shards of
/// other parameters, other counts, one part twice or a part missing, a shard not completely built or
/// holding entries outside its part: the message names the files), and Store's.
Result<MergeReport> mergeDatabases(
    const std::filesystem::path& out, std::span<const std::filesystem::path> shards,
    const std::function<void(std::size_t done, std::size_t total)>& progress = {});

/// A user mesh to add: its surface and the name it goes by (the file's name, by default).
struct NamedMesh {
  std::string name;
  std::string source;
  core::TriangleMesh mesh;
};

struct AddOptions {
  /// A surface of more triangles is computed on its simplification to this many
  /// (volume::surfaceForEntry, as enrich's), 0: as given.
  std::size_t maxTriangles = 4000;
  /// Called as each mesh's entry is computed or fails (a large one takes minutes), one call at a time,
  /// from the thread that computed it: the mesh's index and its result.
  std::function<void(std::size_t mesh, const Result<volume::EntryData>& computed)> computed;
};

/// Adds meshes to an existing database as `user` entries, computed with the file's parameters and
/// written in one transaction: all or none. Returns their ids. TetGen runs guarded (these meshes come
/// from outside). Errors: the first mesh that fails, named; kInvalidArgument for a name already present.
Result<std::vector<core::EntryId>> addToDatabase(const std::filesystem::path& path,
                                                 std::span<const NamedMesh> meshes,
                                                 const AddOptions& options = {});

}  // namespace shapedb::io
