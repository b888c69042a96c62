#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <shapedb/core/adapt.h>
#include <shapedb/core/fidelity.h>
#include <shapedb/core/index.h>
#include <shapedb/core/link.h>
#include <shapedb/core/live_index.h>
#include <shapedb/core/orientation.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/io/build.h>
#include <shapedb/io/store.h>
#include <shapedb/volume/correction.h>

namespace shapedb::io {

/// The most candidates a geometry correction morphs (QueryOptions::correctionCandidates): each is a morph
/// on the query's critical path, and a search for more than this many is not a query any more.
inline constexpr int kMaxCorrectionCandidates = 100;

/// What Database::query does beyond matching.
struct QueryOptions {
  core::DescriptorKind descriptor = core::DescriptorKind::kCentroidVoxel;
  core::SearchOptions search;  ///< k, method
  core::OrientationOptions orientation;
  core::Material material = core::materialPresets()[0];  ///< steel
  /// Accept a surface that bounds no well-defined solid (open, as a scan with holes is; non-manifold;
  /// inconsistently oriented): its mass properties from the paper's vertex point masses (§4.1), which
  /// give a shell's inertia, larger than the solid's (about 5/3 for a sphere). The descriptors need only
  /// the surface. The answer says so: massProperties.isApproximate, and a warning in physics->warnings.
  /// A closed surface is computed exactly either way. false: such a surface is an error (kNotClosed,
  /// kNonManifold, kInconsistentOrientation).
  bool approximate = false;
  /// Fetch the best match's physical data, adapt it to the query (size, frame, material) and link the
  /// query's vertices to its tets. false: matching only.
  bool adapt = true;
  bool link = true;  ///< with adapt
  /// With adapt: the entry's modes stretched to the query's second moments before they are adapted
  /// (core/stretch.h). Off by default: it costs ~1 ms a query (a 3m × 3m eigenproblem) and, the first
  /// time an entry is adapted, its stretch basis (~25 ms; cached with its data), and on the benchmark
  /// it narrows the worst errors more than the median (docs/architecture.md).
  /// Linear-tet databases only (supportsStretchCorrection): an error otherwise.
  bool stretchCorrection = false;
  /// With adapt, uncorrected and unstretched: the answer's eigenvalues are blended from the spectra of
  /// the first this many matches (the search finds at least as many), weighted by 1/distance, those
  /// beyond core::kSpectrumReach times the nearest's distance left out (core::blendSpectra); its mode
  /// shapes, tets and collision compound stay the nearest entry's. The query's own shape (a match at a
  /// distance near 0, its learned entry say) answers alone. Against the 1,400-entry default database,
  /// three took the median first-frequency error of the nearest tier from 5.9 % to 3.0 % on plate
  /// fragments, 4.7 % to 4.1 % on sphere fragments, 6.2 % to 6.1 % on a scanned figure's and 52.6 % to
  /// 44.6 % on real meshes, and its p90 down on all four (docs/accuracy.md, "The nearest tier's
  /// spectrum"). Each further match costs reading its eigenvalues, not its data. 1: the nearest entry's
  /// own spectrum, as the paper has it.
  int neighbours = 3;
  /// With adapt: the geometry correction, the second tier of the answer (volume/correction.h): the best
  /// entry's tets morphed onto the query's own surface and their modes computed again there, before they
  /// are adapted and linked. Tens of milliseconds where the nearest entry takes one: run it on a worker
  /// thread beside an interactive loop. Where the morph cannot keep every tet positive, the entry's own
  /// data stand and physics->warnings says why. Not with stretchCorrection (this replaces it).
  bool correct = false;
  volume::CorrectionOptions correction;
  /// With correct: the entries of the first this many matches (the search finds at least as many) are
  /// each morphed onto the query, and the one whose morphed tets reach the query's surface best (the
  /// smallest mean distance from the query's vertices to them; a morph whose tets stray across a gap of
  /// the query, volume::kStrayShareWarning, only if all do) is the one whose modes are computed and
  /// given: the nearest descriptor is not always the shape that morphs best. Each further candidate costs
  /// one morph, a fraction of the modes' cost. On the benchmark, three took the median first-frequency
  /// error on real meshes from 24 % to 17 % and on fracture fragments from 5.9 % to 5.3 % and 3.7 % to
  /// 3.3 % (docs/architecture.md, "Which entry is morphed"). 1: the best match only.
  int correctionCandidates = 3;  ///< 1 to kMaxCorrectionCandidates
  /// With correct: where the best of the candidates' morphs leaves much of the query unfilled (its mass
  /// scale over volume::kMassScaleWarning: a part of the object that entry has no tets for, such as a
  /// thin plate's expanse around a ring's rim), more entries are morphed: the three nearest by shape
  /// alone (the descriptor without its moment term, since the morph's prestretch gives the query's
  /// proportions) and the nearest box entry (a box fills the hull of any object), each unless it was a
  /// candidate already. The best of their morphs that draw no warning (fill the query, stray across no
  /// gap) answers instead; if none does, the candidates' answer and its warning stand. Its match then
  /// follows the search's k best in QueryResult::matches (a shape-alone match's distance has no moment
  /// term). Up to four more morphs, on those queries only.
  bool correctionFallback = true;
  /// A fidelity report for each of the first search.k matches (with correct, at least the candidates) and
  /// the answered one; the further matches a spectrum is blended from (neighbours) get none. Fetches each
  /// reported match's tet mesh.
  bool fidelity = true;
  core::FidelityOptions fidelityOptions;
};

/// Wall time of each stage of one query, microseconds.
struct QueryTimes {
  double validate = 0.0;        ///< per-face checks and the closed-surface check (analyzeTopology)
  double massProperties = 0.0;  ///< exact mass properties (surface integrals) + normalize
  double describe = 0.0;        ///< every orientation candidate
  double search = 0.0;
  double fetch = 0.0;    ///< physical data from the cache or the file (with the entry's locator)
  double correct = 0.0;  ///< the geometry correction: morph and modes (QueryOptions::correct)
  double adapt = 0.0;
  double link = 0.0;
  double fidelity = 0.0;
  double total = 0.0;
};

struct MatchReport {
  core::Match match;
  const EntryRecord* entry = nullptr;  ///< owned by the Database
  std::optional<core::Fidelity> fidelity;
  /// With fidelity: how wrong this match's own data, uncorrected, would probably make the first non-rigid
  /// frequency (core/error_model.h's nearest-entry estimate on this match's fidelity report; the link's
  /// share of outside vertices is known for the answered match only, and counts as 0 here). Ranks the
  /// candidates; the answer's own estimate is QueryResult::predictedFrequencyError.
  std::optional<double> predictedFrequencyError{};
};

/// Everything a query found: the query's own mass properties (unit density) and frame, the k best
/// matches best first, and for the answered one (the best, unless the geometry correction chose among
/// several: answered) its physical data adapted to the query and linked to it.
struct QueryResult {
  core::MassProperties massProperties;
  core::Normalization normalization;
  std::vector<MatchReport> matches;
  /// The index in matches of the match whose data the answer carries: 0, unless the geometry correction
  /// chose another of its candidates (QueryOptions::correctionCandidates), or one of its fallback entries,
  /// added after the search's matches (QueryOptions::correctionFallback).
  std::size_t answered = 0;
  const MatchReport& answeredMatch() const { return matches[answered]; }
  std::shared_ptr<const core::PhysicalData> entryPhysics;  ///< the answered match's, canonical frame
  /// With QueryOptions::correct, what the correction did (also when it failed: then only the reason in
  /// physics->warnings, and this is empty).
  std::optional<volume::CorrectionReport> correction;
  /// With adapt: the answered match's data (or, corrected, the data of its tets morphed onto the query) in
  /// the query's frame, size and material.
  std::optional<core::AdaptedPhysics> physics;
  /// With adapt: the weight of each of the first matches whose spectra physics->eigenvalues were blended
  /// from (QueryOptions::neighbours), summing to 1; {1} when the answer is one entry's alone (one
  /// neighbour, a match at distance 0, the stretch correction), empty when it is the geometry
  /// correction's.
  std::vector<double> spectrumWeights;
  /// With adapt: a locator of the answer's tets in their canonical frame (physics->placement carries the
  /// query's frame there): the corrected tets' when corrected, else the entry's own, shared with the cache.
  /// What contact with the object is located in (the haptic loop's), as the link is.
  std::shared_ptr<const core::TetLocator> locator;
  core::SurfaceLink link;  ///< with QueryOptions::link
  /// With fidelity, adapt and link: how wrong the answer's first non-rigid frequency probably is
  /// (core/error_model.h; 0.1 is 10 %), from the answered match's fidelity report, the share of the query's
  /// vertices outside its tets and, corrected, the morph's remaining distance. None for a surface of
  /// several solids, or with cavities answered by a generated entry: the model was fitted on single solids
  /// without cavities (physics->warnings says which).
  std::optional<double> predictedFrequencyError;
  /// Orientations tried (the search skips those its index sees alike).
  std::size_t orientationCandidates = 0;
  QueryTimes times;
};

/// An open database: every entry's descriptors in in-RAM indexes (one per kind opened), its physical data
/// read on demand through a bounded cache. Thread-safe: concurrent searches and physics reads, and, opened
/// with OpenOptions::learn, entries learned beside them (learn).
class Database {
 public:
  struct OpenOptions {
    /// Entries' physical data kept in RAM, each with its point locator, least recently used dropped first.
    /// 256 holds a fracture burst's (200 fragments match about 160 entries of the default database), so
    /// that the next burst finds them (bench/burst_bench.cpp: a warm burst 212 → 154 ms against 64); a
    /// cached entry of the default database takes 551 KB on average, so about 140 MB when full. An entry
    /// a geometry correction has morphed also keeps what the next correction with it reuses (its
    /// volume::MorphPlan and volume::ModalPlan): about 0.3-0.4 MB more on the default database (35 MB over
    /// the 106 entries Bob's 50 fragments morph).
    std::size_t cacheEntries = 256;
    /// If set, the file must have been built with these descriptor parameters (grid size, sampling).
    std::optional<core::DescriptorOptions> expectDescriptor;
    /// Open for learning too (learn(), io/enrich.h): a second, writable connection to the file beside the
    /// reading one. Errors then include a writable Store::open's (a read-only file or folder).
    bool learn = false;
    /// The descriptor kinds whose indexes are built at open, each from its own descriptors in the file: a
    /// query by another kind is then an error. All three by default; `query`, `haptic`, `sound` and `drop`
    /// open with the one they search by, and read a third of what they did.
    std::vector<core::DescriptorKind> descriptors{core::DescriptorKind::kMoment, core::DescriptorKind::kVoxel,
                                                  core::DescriptorKind::kCentroidVoxel};
  };
  /// Errors: Store::open's, kInvalidArgument (expectDescriptor differs: the message says how; no
  /// descriptor kind to index), kParse (a corrupted descriptor).
  static Result<Database> open(const std::filesystem::path& path, const OpenOptions& options);
  static Result<Database> open(const std::filesystem::path& path) { return open(path, OpenOptions{}); }

  Database(Database&&) noexcept;
  Database& operator=(Database&&) noexcept;
  ~Database();

  const BuildParameters& parameters() const;
  /// Whether QueryOptions::stretchCorrection can be used: its basis (core/stretch.h) is that of linear
  /// tets, and a database of quadratic ones stores their modes at the corners only.
  bool supportsStretchCorrection() const;
  /// The entries the file held when it was opened, in id order.
  const std::vector<EntryRecord>& entries() const;
  /// The entries learned through this Database since it was opened, in the order they were published.
  std::vector<EntryRecord> learnedEntries() const;
  /// Every entry searched now: entries() and learnedEntries().
  std::size_t size() const;
  /// Any entry, learned ones included, by id or by name; nullptr if there is none. The pointer stays
  /// valid as long as the Database.
  const EntryRecord* entry(core::EntryId id) const;
  const EntryRecord* entry(std::string_view name) const;
  /// Whether the index of `kind` was built at open (OpenOptions::descriptors).
  bool hasIndex(core::DescriptorKind kind) const;
  /// The index of one descriptor kind: the file's entries and those learned since.
  /// Precondition: hasIndex(kind).
  const core::LiveIndex& index(core::DescriptorKind kind) const;

  /// Adds an entry computed elsewhere (io/enrich.h computes them) as a `learned` entry: written to the file
  /// in one transaction (a crash loses it whole or keeps it whole), then published to the indexes. A
  /// query that starts after learn() returns can match it; one running meanwhile sees it or does not,
  /// never a part of it. Queries do not wait for it; learns wait for each other.
  /// `data` must have been computed with parameters().entry (volume::computeEntry) for its data and
  /// descriptors to mean what the others' do. One process at a time may learn into a file.
  /// Errors: kInvalidArgument (not opened with OpenOptions::learn; the name is taken), Store::write's.
  Result<core::EntryId> learn(const std::string& name, const std::string& source,
                              const volume::EntryData& data);

  /// The k most similar entries to `mesh` (any frame, any size) by the descriptor `kind`: exact mass
  /// properties → normalize → describe every orientation candidate → exact search.
  Result<std::vector<core::Match>> match(const core::TriangleMesh& mesh, core::DescriptorKind kind,
                                         const core::SearchOptions& search = {}) const;

  /// Algorithm 1 of the paper, whole: match `mesh` (any frame, any size; closed and oriented), then
  /// fetch, adapt and link the best match and report the fidelity of the matches asked for. Thread-safe: many
  /// threads may query at once (each keeps its own descriptor scratch).
  /// Errors: the mesh's (validateMesh, computeMassProperties: open or degenerate surfaces), the
  /// material's, Store::physics's.
  Result<QueryResult> query(const core::TriangleMesh& mesh, const QueryOptions& options = {}) const;

  /// A burst of queries at one instant (the fragments of a fracture, the files of one `shapedb query`):
  /// every mesh answered exactly as query() answers it alone, the meshes spread over the machine's cores
  /// (TBB, one task per mesh; each query's own parallel stages share the same workers), the results in
  /// input order. A mesh that fails has its error in its own slot and the others go on. Thread-safe as
  /// query() is; each result's times are its own query's wall times, overlapping the others'.
  std::vector<Result<QueryResult>> queryMany(std::span<const core::TriangleMesh> meshes,
                                             const QueryOptions& options = {}) const;
  /// One entry's physical data, from the cache or the file. Errors: Store::physics's.
  Result<std::shared_ptr<const core::PhysicalData>> physics(core::EntryId id) const;
  /// Cache statistics: hits and misses since open.
  std::array<std::size_t, 2> cacheStats() const;

 private:
  struct Impl;
  explicit Database(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> mImpl;
};

}  // namespace shapedb::io
