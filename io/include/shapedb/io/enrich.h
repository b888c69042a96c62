#pragma once
// A database that learns: objects whose nearest entry is not good enough are computed exactly in the
// background (the build's own pipeline: guarded TetGen, modes, collision, sound data) and added to the
// database as `learned` entries, while queries go on. The next time the object, or one like it, is
// queried, it matches its own entry.

#include <cstddef>
#include <future>
#include <memory>
#include <string>

#include <shapedb/core/index.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/io/build.h>
#include <shapedb/io/database.h>
#include <shapedb/volume/entry.h>

namespace shapedb::io {

/// A key for a surface as given: 16 hexadecimal digits of a 64-bit hash of its vertex coordinates and
/// faces. The same file gives the same key; the same object moved, scaled or remeshed does not, and need
/// not: its descriptor finds its learned entry anyway. What keeps an object from being computed twice.
std::string surfaceKey(const core::TriangleMesh& mesh);
/// The name the learned entry of `mesh` goes by: "learned-" and its surfaceKey.
std::string learnedName(const core::TriangleMesh& mesh);

/// One object learned (or found learned already).
struct Learned {
  core::EntryId id = 0;
  std::string name;           ///< learnedName of the surface
  bool computed = false;      ///< false: the database held it already (learned earlier, by any run)
  double seconds = 0.0;       ///< computed: from submit to published (waiting in the queue included)
  volume::StageTimes stages;  ///< computed: the entry's own stages, seconds
};

struct EnricherOptions {
  /// Objects computed at once, each on a thread of its own (the haptic loop's machine has other work:
  /// one by default). An object's computation uses that thread only, as a build's entries do.
  int workers = 1;
  /// A surface of more triangles is simplified to this many first (volume::surfaceForEntry: no vertex
  /// further than 1e-3 of the object's size from the surface). 0: never.
  std::size_t maxTriangles = 4000;
};

/// Computes submitted objects' entries in the background and learns them into a Database
/// (Database::learn): written to the file, then searchable. An object is computed once: a surface whose
/// learned entry the database holds, or that is queued or being computed, is not queued again (its
/// future is the earlier one's). A failed object keeps its error: resubmitted, it fails again at once.
///
/// Thread-safe: submit from any thread. Destroying the Enricher finishes the objects being computed and
/// abandons those still queued (their futures hold kCancelled); nothing committed is lost either way.
class Enricher {
 public:
  /// `database` must be opened with Database::OpenOptions::learn and outlive the Enricher.
  explicit Enricher(Database& database, const EnricherOptions& options = {});
  Enricher(const Enricher&) = delete;
  Enricher& operator=(const Enricher&) = delete;
  ~Enricher();

  /// Queues `mesh` (closed and oriented, any frame and size) unless it is known (above). The future
  /// holds the learned entry, or why there is none: the mesh's errors (volume::computeEntry's; TetGen runs
  /// guarded), Database::learn's. Query the mesh again for its exact data: it matches its entry.
  std::shared_future<Result<Learned>> submit(const NamedMesh& mesh);

  /// Objects queued or being computed.
  std::size_t pending() const;
  /// Blocks until nothing is queued or being computed.
  void wait() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> mImpl;
};

}  // namespace shapedb::io
