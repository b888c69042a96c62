#pragma once
// The parts of a database build that do not depend on where entries are computed: the file opened or
// created and what is left to do (BuildSession), one catalog entry computed (computeCatalogEntry), and a
// computed entry as bytes, to be sent from the rank that computed it to the one that writes (toWire,
// fromWire). buildDatabase computes on this process's cores; the MPI build (build_mpi.cpp) on other ranks.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/io/build.h>
#include <shapedb/io/store.h>
#include <shapedb/volume/families.h>

namespace shapedb::io::detail {

/// One catalog entry's outcome: computed (encoded as the file stores it) or failed with a reason.
struct ComputedEntry {
  EntryRecord record;  ///< id = the catalog index
  std::optional<EncodedEntry> data;
  std::optional<FailureRecord> failure;
};

/// The catalog entry at `index`, computed with the parameters' pipeline (volume::computeEntry).
ComputedEntry computeCatalogEntry(const std::vector<volume::ShapeSpec>& catalog, std::size_t index,
                                  const BuildParameters& parameters);

/// A computed entry as bytes and back (the blobs as they are, so the file gets the same bytes).
/// fromWire's errors: kParse for bytes that are not one.
std::vector<std::uint8_t> toWire(const ComputedEntry& entry);
Result<ComputedEntry> fromWire(const void* data, std::size_t size);

/// A build in progress on the file: opened (resume) or created with the options' parameters, the
/// catalog's entries left to do, and the writer that commits computed entries in batches and reports
/// progress. Entries may arrive in any order.
class BuildSession {
 public:
  /// Errors: buildDatabase's.
  static Result<BuildSession> start(const std::filesystem::path& path, const BuildOptions& options);
  BuildSession(BuildSession&&) noexcept;
  BuildSession& operator=(BuildSession&&) noexcept;
  ~BuildSession();

  const BuildParameters& parameters() const;
  const std::vector<volume::ShapeSpec>& catalog() const;
  /// Catalog indices still to compute (in this file's part), ascending.
  const std::vector<std::size_t>& todo() const;
  /// Takes one computed entry; commits a batch once full. False once a write has failed: stop computing.
  bool accept(ComputedEntry entry);
  /// Commits what is left and marks the file complete. Errors: the first write's that failed.
  Result<BuildReport> finish();

 private:
  struct State;
  explicit BuildSession(std::unique_ptr<State> state);
  std::unique_ptr<State> mState;
};

}  // namespace shapedb::io::detail
