#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/result.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// A database entry's identifier (its row in the store).
using EntryId = std::uint32_t;

/// One search result.
struct Match {
  EntryId entry = 0;
  /// What the search ranks by, smaller is closer: the descriptor's similarity (eq. 4, 5 or 6), plus for
  /// the voxel kinds the moment term below.
  double distance = 0.0;
  /// The part of `distance` that compares proportions (voxel kinds): SearchOptions::momentWeight ·
  /// Σᵢ |ln(mᵢ/m'ᵢ)| over the sorted canonical moments of query and entry; 0 for the moment kind.
  /// distance − momentTerm is the descriptor's own similarity.
  double momentTerm = 0.0;
  int candidate = 0;  ///< which query candidate (orientation) reached that distance
  /// That candidate's rotation, candidateFromCanonical of the query: entry canonical ≈ orientation · T.
  Mat3 orientation = Mat3::Identity();
};

/// How the index is searched. All methods but kBuckets return exactly the brute-force answer.
enum class SearchMethod {
  kBruteForce,  ///< every entry (TBB-parallel): the oracle
  kPruned,      ///< exact: provable lower bounds skip entries that cannot enter the k best
  kBuckets,     ///< the paper's §5 heuristic: only entries within ±r filled cells of the query; may miss.
                ///< Voxel kinds only: a moment index is always searched exactly (its k-d tree)
};

struct SearchOptions {
  int k = 1;                                    ///< number of matches, best first; ≥ 1
  SearchMethod method = SearchMethod::kPruned;  ///<
  int bucketRadius = 6;                         ///< kBuckets: r, the paper's 6
  /// Use TBB within the search: brute force always, pruned search once its nearest buckets are done and
  /// more remain. Off for many concurrent small queries. The answer does not depend on it.
  bool parallel = true;
  /// Voxel kinds: the weight w of the moment term added to eq. (5) or (6), w · Σᵢ |ln(mᵢ/m'ᵢ)| (the
  /// principal moments of the unit-volume shapes, ascending). The occupancy grid says which shape, the
  /// moments how it is proportioned, and an entry adapted by uniform scaling keeps its own proportions:
  /// on fracture fragments the grid alone picked entries 8-9 % off in their first frequency, the sum
  /// (w = 1, both terms dimensionless) 4-5 % (docs/architecture.md). 0: the paper's distance alone.
  /// Both terms are ≥ 0, so the grid's lower bounds still bound the sum: the search stays exact.
  double momentWeight = 1.0;
  /// When not empty, the search considers these entries only (ascending, no repeats; ids the index does
  /// not hold are ignored): the nearest of one family, say. Each of them is compared in full, whatever
  /// `method`, so the answer is exact and its cost grows with the index (a pass over every entry's id)
  /// plus the entries listed.
  std::span<const EntryId> among = {};
};

/// What a search did, for benchmarks and tests.
struct SearchStats {
  std::size_t distanceEvaluations = 0;    ///< full descriptor distances computed
  std::size_t boundEvaluations = 0;       ///< per-entry (or per-node) lower bounds computed
  std::size_t groupBoundEvaluations = 0;  ///< voxel kinds: lower bounds of a cluster of entries computed
};

/// The descriptors of every database entry in RAM, in a compact layout, with k-nearest search.
///
/// Layout (voxel kinds): entries sorted by filled-cell count into buckets of equal count, and within a
/// bucket into a tree of clusters of similar proportions (a k-d tree over their moments, up to 16
/// entries a leaf); per entry the occupancy bit-packed (⌈N³/64⌉ words), its filled-cell counts per slab
/// and per block (the lower bounds), the logarithms of its moments (the moment term), and for
/// centroid-voxel the centroid of each filled cell quantized to 31 levels per axis (5 bits, 2 bytes a
/// centroid; 0.5 is the middle of a level, so a centroid there is robust to round-off). Per cluster,
/// the range of each of those counts and moments: one bound for all its entries, so that a search
/// skips most of a bucket without looking at its entries.
/// Moment descriptors: a k-d tree over the three moments.
///
/// Distances are those of core::descriptorDistance on the quantized centroids (each coordinate moves
/// by at most 1/62 of a cell), plus the moment term for the voxel kinds (SearchOptions::momentWeight),
/// for every search method alike. Ties break by entry id, so results do not
/// depend on the method's order of work or on the thread count.
///
/// Immutable once built; search is thread-safe. Build it with IndexBuilder.
class Index {
 public:
  /// An empty index of descriptors with these options.
  explicit Index(const DescriptorOptions& options = {});

  /// The k entries nearest to the query (k or fewer if the index is smaller), best first, ties by
  /// entry id. With several candidates (the query under each orientation candidate, as
  /// volume::Describer::describeCandidates makes them) an entry's distance is the least over the
  /// candidates, and the match records which candidate gave it (the lowest on ties).
  /// Errors: kInvalidArgument if no candidate, k < 1, or a candidate of another kind, sampling or
  /// grid size than the index.
  Result<std::vector<Match>> search(std::span<const Descriptor> candidates, const SearchOptions& options = {},
                                    SearchStats* stats = nullptr) const;
  Result<std::vector<Match>> search(const Descriptor& query, const SearchOptions& options = {},
                                    SearchStats* stats = nullptr) const {
    return search(std::span<const Descriptor>(&query, 1), options, stats);
  }

  const DescriptorOptions& options() const;
  std::size_t size() const;
  /// Bytes held by the index's arrays.
  std::size_t memoryBytes() const;

 private:
  friend class IndexBuilder;
  struct Impl;  // the layout above and the search's workings: index.cpp
  explicit Index(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> mImpl;  ///< shared by copies: an index never changes once built
};

/// Collects entries and builds an Index. One per build; not thread-safe.
///
/// The entries are compacted as they are added, into the arrays the Index searches, and build() reorders
/// those arrays in place and hands them over: at no time is the index held twice. reserve() spares the
/// fixed-size arrays their growth; the centroids grow in chunks that are never moved.
class IndexBuilder {
 public:
  explicit IndexBuilder(const DescriptorOptions& options);

  /// Makes room for this many entries in all, so that adding them moves nothing.
  void reserve(std::size_t entries);

  /// Adds one entry; the descriptor is compacted at once and not kept.
  /// Errors: kInvalidArgument for a descriptor of another kind, sampling or grid size.
  Status add(EntryId id, const Descriptor& descriptor);
  std::size_t size() const { return mIds.size(); }
  /// Bytes held so far (capacity included).
  std::size_t memoryBytes() const;

  /// The index of every entry added. Errors: kInvalidArgument if an id was added twice.
  Result<Index> build() &&;

 private:
  DescriptorOptions mOptions;
  std::uint32_t mWords = 0;
  std::vector<EntryId> mIds;
  std::vector<Vec3> mMoments;              ///< the moments (moment kind) or their logarithms (voxel kinds)
  std::vector<std::uint32_t> mCounts;      ///< voxel kinds: filled cells
  std::vector<std::uint64_t> mBits;        ///< voxel kinds: occupancy, mWords words each
  std::vector<std::uint8_t> mProfiles;     ///< voxel kinds: the counts the lower bounds compare
  std::vector<std::uint64_t> mCentroidAt;  ///< centroid-voxel: chunk << 32 | offset of the first centroid
  std::vector<std::vector<std::uint16_t>> mCentroidChunks;  ///< the quantized centroids
};

/// A centroid in its cell's unit cube, quantized to 31 levels per axis, 5 bits each (x in the low bits).
std::uint16_t quantizeCentroid(const Vec3& centroid);
Vec3 dequantizeCentroid(std::uint16_t code);

const char* toString(SearchMethod method);

}  // namespace shapedb::core
