#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/index.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/families.h>

namespace shapedb::io {

/// The version of the file layout below. A file of another version is refused, never guessed at.
inline constexpr int kSchemaVersion = 1;

/// The curved families' surface resolution for entries of `order` elements. Quadratic: 12 segments and 6
/// stacks (16 and 8 until 2026-11-27), which take a third to a half of the curved entries' tets and of
/// their modes' cost against 16 and 8, the modes still within about 2 % of the same surface meshed three
/// times finer (docs/accuracy.md); a 12-sided section holds 95.5 % of its circle's area (the entry is the
/// polygon: its data are that shape's). Shells and limbed bodies keep 16 segments, which their thin walls
/// and limbs need. Linear: 24 and 12, as databases of linear tets have always been built.
volume::ShapeResolution entryResolution(volume::ElementOrder order);

/// A family's own TetGen volume bound: its tets' largest share of the solid's volume, in place of the
/// entry options' (volume::TetrahedralizeOptions::maxVolumeFraction).
using FamilyVolumeFractions = std::map<volume::Family, double>;

/// The families meshed coarser than the rest for entries of `order` elements. Quadratic: stones at 3/100
/// (the others at 1/100). A stone is compact and smooth: at 1/100 six of them were within 0.7 % of the
/// same surfaces meshed three times finer, far inside the aim of 2 % (median) and 5 % (worst) the other
/// families are held to; at 3/100 they have about half the tets and are within 1.4 %, and a correction
/// that morphs one takes about half the time (docs/accuracy.md). Linear: none.
FamilyVolumeFractions entryVolumeFractions(volume::ElementOrder order);

/// A volume bound a family may have: a share of the solid's volume in (0, 1].
inline bool validVolumeFraction(double fraction) {
  return fraction > 0.0 && fraction <= 1.0;
}

/// What a database was built with. Stored in the file; every entry of a file shares them. The defaults
/// are those of `shapedb build`: quadratic tets (withElements).
struct BuildParameters {
  volume::EntryOptions entry;
  /// Surface resolution of the curved families (entryResolution of the entry's elements).
  volume::ShapeResolution resolution = entryResolution(volume::ElementOrder::kQuadratic);
  /// Families meshed with a volume bound of their own (entryVolumeFractions of the entry's elements);
  /// entries of the others, and user and learned entries, take entry.tetgen's.
  FamilyVolumeFractions volumeFractions = entryVolumeFractions(volume::ElementOrder::kQuadratic);
  std::vector<volume::Family> families;  ///< of the generated catalog
  /// Each family's share of the catalog (volume::buildCatalog), as many as families; empty: even (the
  /// files built before weights existed).
  std::vector<unsigned> weights;
  std::size_t entries = 1400;  ///< size of the generated catalog
};

/// `parameters` for a database of `order` elements: the entry's elements and TetGen bounds
/// (volume::withElements), and the surface resolution and families' volume bounds that go with them
/// (entryResolution, entryVolumeFractions).
BuildParameters withElements(BuildParameters parameters, volume::ElementOrder order);

/// The options an entry of `family` is computed with: `parameters.entry`, with the family's own volume
/// bound if it has one.
volume::EntryOptions entryOptionsFor(const BuildParameters& parameters, volume::Family family);

/// The parameters as JSON text (stored in the file's meta table), and back.
std::string toJson(const BuildParameters& parameters);
Result<BuildParameters> parseBuildParameters(const std::string& json);

/// One entry's bookkeeping (its physical data live in their own blobs).
struct EntryRecord {
  core::EntryId id = 0;
  std::string name;  ///< "box-00017", or the file name of a user entry
  volume::Family family = volume::Family::kUser;
  core::Vec3 params = core::Vec3::Zero();
  std::string source;  ///< user entries: the file it came from
  std::size_t nodes = 0, tets = 0;
  volume::StageTimes times;
};

/// An entry that failed to build, kept so that a resumed build does not retry it forever and `info` can
/// say why.
struct FailureRecord {
  std::string name;
  std::string message;
};

/// What Store::check found: SQLite's own integrity check, and every blob against its checksum.
struct IntegrityReport {
  /// A blob whose bytes no longer match their checksum.
  struct Damage {
    core::EntryId entry = 0;
    std::string name;  ///< the entry's name ("entry N" for a blob of no entry)
    std::string part;  ///< "tet mesh", "modes", ..., or "centroid-voxel descriptor"
  };
  std::vector<std::string> sqliteProblems;  ///< PRAGMA integrity_check's lines, if it found anything
  std::vector<Damage> damaged;
  std::size_t blobsChecked = 0;
  bool ok() const { return sqliteProblems.empty() && damaged.empty(); }
};

/// An entry's blobs as the file stores them: its three descriptors (by DescriptorKind), then the five parts
/// of its physical data (tet mesh, mass properties, modes, collision, sound).
struct EncodedEntry {
  std::array<std::vector<std::uint8_t>, 3> descriptors;
  std::array<std::vector<std::uint8_t>, 5> physics;
};
EncodedEntry encodeEntry(const volume::EntryData& data);

/// The database file (SQLite, WAL mode): schema version and application id in the header, the build
/// parameters and bookkeeping in `meta`, then `entries`, `descriptors` (one blob per entry and kind),
/// `physics` (one blob per entry and part: tet mesh, mass properties, modes, collision, sound) and
/// `failures`. Every blob has a CRC-32 beside it, checked on read.
///
/// A file is untrusted input (databases are passed around): it is opened with SQLite's defences for
/// such files (defensive mode, no trusted schema, bounded lengths, nothing attached), and a file whose
/// schema holds an object shapedb does not create (a trigger, a view, a table or index of its own) is
/// refused before anything reads it.
///
/// Thread-safe: one connection in SQLite's serialized mode; writes are one transaction per call.
class Store {
 public:
  /// A new file. Errors: kIo if it exists or cannot be created.
  static Result<Store> create(const std::filesystem::path& path, const BuildParameters& parameters);
  /// An existing file. Errors: kIo (missing, unreadable; `writable` and the file is read-only), kParse
  /// (not SQLite, another application's file, another schema version, unreadable parameters, a schema
  /// object shapedb does not create, named).
  static Result<Store> open(const std::filesystem::path& path, bool writable = false);

  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;
  ~Store();

  const std::filesystem::path& path() const;
  const BuildParameters& parameters() const;

  /// Writes entries (and failures) in one transaction: all of them or none.
  /// Errors: kIo (disk full, read-only file, ...), kInvalidArgument (a duplicate id or name).
  Status write(std::span<const EntryRecord> records, std::span<const volume::EntryData> data,
               std::span<const FailureRecord> failures = {});
  /// The same, the entries already encoded (encodeEntry; computed elsewhere, say on another MPI rank).
  Status write(std::span<const EntryRecord> records, std::span<const EncodedEntry> data,
               std::span<const FailureRecord> failures = {});

  /// One entry's blobs as stored, every checksum verified: what a merge copies into another file with
  /// write (io/build.h), the very bytes a single build would have written. Errors: kInvalidArgument (no
  /// such entry), kParse (a blob damaged or missing, named), kIo.
  Result<EncodedEntry> encoded(core::EntryId id) const;

  Result<std::vector<EntryRecord>> entries() const;
  Result<std::vector<FailureRecord>> failures() const;
  /// Every entry's descriptor of one kind, in id order, checksums verified, each handed to `visit` as
  /// it is read (none is kept: an index of millions is built without the descriptors held twice).
  /// Stops at the first error, `visit`'s own included.
  Status forEachDescriptor(core::DescriptorKind kind,
                           const std::function<Status(core::EntryId, const core::Descriptor&)>& visit) const;
  /// One entry's physical data, checksums verified. Errors: kInvalidArgument (no such entry), kParse
  /// (a corrupted blob: the message names the entry and the part).
  Result<core::PhysicalData> physics(core::EntryId id) const;
  /// One entry's eigenvalues (unit density and Young's modulus, its canonical size: ModalData::eigenvalues),
  /// its modes' checksum verified, without decoding the rest of its data. Errors: as physics().
  Result<Eigen::VectorXd> eigenvalues(core::EntryId id) const;

  /// SQLite's integrity check, then every blob read and checked against its checksum (the whole file:
  /// seconds for the default database). Errors: kIo only where SQLite cannot read at all.
  Result<IntegrityReport> check() const;

  /// Checkpoints the write-ahead log into the file and leaves it in rollback-journal mode: one
  /// self-contained file, readable from a read-only folder or medium. The next write switches back
  /// to WAL. Fails (harmlessly: the file stays valid in WAL mode) while another connection has it open.
  Status finish();

  /// Free-form bookkeeping: "build_seconds", "status", "created".
  Status setMeta(const std::string& key, const std::string& value);
  std::optional<std::string> meta(const std::string& key) const;

 private:
  struct Impl;
  explicit Store(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> mImpl;
};

}  // namespace shapedb::io
