#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <shapedb/core/index.h>

namespace shapedb::core {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kProfileBins = 16;
constexpr std::uint32_t kLeafSlots = 16;  // entries per leaf of a bucket's cluster tree
constexpr int kBlocksPerAxis = 4;         // the coarse 4³ block grid of the third bound
// An odd number of levels, so that a centroid coordinate of exactly 0.5 (a wall that crosses its cell,
// a face on the plane of symmetry) falls in the middle of a level rather than on the edge between two:
// with 32, round-off of either sign split such coordinates between levels 15 and 16, and the same
// shape described in a frame reversed along that axis quantized differently. 0 and 1 (a face on a
// cell plane) fall inside levels 0 and 30.
constexpr int kQuantLevels = 31;
constexpr int kMaxSquaredCode = 3 * (kQuantLevels - 1) * (kQuantLevels - 1);
constexpr std::size_t kLeafSize = 8;

// Centroid terms are summed as integers in units of 2⁻¹⁶: exact, order-free, and a one-cycle add
// where a floating-point sum would chain its latency through every cell.
constexpr double kTermUnit = 1.0 / 65536.0;

// ‖Δ‖ / √3 in units of kTermUnit for every squared distance between two quantized centroids.
const std::array<std::uint32_t, kMaxSquaredCode + 1>& centroidDistanceTable() {
  static const auto table = [] {
    std::array<std::uint32_t, kMaxSquaredCode + 1> t{};
    for (int i = 0; i <= kMaxSquaredCode; ++i)
      t[static_cast<std::size_t>(i)] =
          static_cast<std::uint32_t>(std::lround(std::sqrt(i) / (kQuantLevels * std::sqrt(3.0)) / kTermUnit));
    return t;
  }();
  return table;
}

inline int squaredCodeDistance(std::uint16_t a, std::uint16_t b) {
  const int dx = (a & 31) - (b & 31), dy = ((a >> 5) & 31) - ((b >> 5) & 31),
            dz = ((a >> 10) & 31) - ((b >> 10) & 31);
  return dx * dx + dy * dy + dz * dz;
}

/// Filled-cell counts of a voxel descriptor per part of four partitions of its grid: the slabs along
/// x, y and z (16 bins each, bytes 0-47) and a 4³ block grid (bytes 48-111). Any partition bounds
/// eq. (5) and (6) from below.
constexpr std::size_t kSlabBytes = 3 * kProfileBins;
constexpr std::size_t kProfileBytes = kSlabBytes + kBlocksPerAxis * kBlocksPerAxis * kBlocksPerAxis;
using CountProfile = std::array<std::uint8_t, kProfileBytes>;

// The parts of the four partitions below that each cell of an N³ grid falls in: its x, y and z slab
// (16 bins each; with N > 16 adjacent slabs share a bin), as indices into a profile's slab counts, and
// its block of the coarse 4³ grid. One table per grid size, made once.
using CellParts = std::array<std::uint8_t, 4>;
const std::vector<CellParts>& cellParts(int n) {
  static std::array<std::once_flag, kMaxGridSize + 1> made;
  static std::array<std::vector<CellParts>, kMaxGridSize + 1> tables;
  const auto size = static_cast<std::size_t>(n);
  std::call_once(made[size], [&] {
    const auto bin = [n](int i, int bins) { return i * bins / std::max(n, bins); };
    std::vector<CellParts>& table = tables[size];
    table.resize(size * size * size);
    for (std::uint32_t cell = 0; cell < table.size(); ++cell) {
      const std::array<int, 3> ijk = cellCoordinates(cell, n);
      for (int axis = 0; axis < 3; ++axis)
        table[cell][static_cast<std::size_t>(axis)] = static_cast<std::uint8_t>(
            axis * kProfileBins + bin(ijk[static_cast<std::size_t>(axis)], kProfileBins));
      table[cell][3] = static_cast<std::uint8_t>(
          bin(ijk[0], kBlocksPerAxis) +
          kBlocksPerAxis * (bin(ijk[1], kBlocksPerAxis) + kBlocksPerAxis * bin(ijk[2], kBlocksPerAxis)));
    }
  });
  return tables[size];
}

// Filled cells per part of four partitions of the grid: slabs along x, y and z and a coarse 4³ block
// grid (cellParts). Counts saturate at 255, which keeps |a − b| ≤ the true difference, so the bounds
// stay valid.
CountProfile countProfile(const std::uint64_t* bits, int n) {
  std::array<int, 48> slabs{};
  std::array<int, 64> blocks{};
  const int cells = n * n * n;
  const std::vector<CellParts>& parts = cellParts(n);
  for (int w = 0; w * 64 < cells; ++w)
    for (std::uint64_t word = bits[w]; word != 0; word &= word - 1) {
      const CellParts& p = parts[static_cast<std::size_t>(w * 64 + std::countr_zero(word))];
      ++slabs[p[0]];
      ++slabs[p[1]];
      ++slabs[p[2]];
      ++blocks[p[3]];
    }
  CountProfile out{};
  for (std::size_t i = 0; i < slabs.size(); ++i)
    out[i] = static_cast<std::uint8_t>(std::min(slabs[i], 255));
  for (std::size_t i = 0; i < blocks.size(); ++i)
    out[kSlabBytes + i] = static_cast<std::uint8_t>(std::min(blocks[i], 255));
  return out;
}

// Σ |a[i] − b[i]| over N bytes (N a multiple of 16): psadbw where the target has SSE2.
template <std::size_t N>
std::uint32_t absoluteDifferenceSum(const std::uint8_t* a, const std::uint8_t* b) {
  static_assert(N % 16 == 0);
#if defined(__SSE2__)
  __m128i sum = _mm_setzero_si128();
  for (std::size_t i = 0; i < N; i += 16) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i));
    const __m128i y = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i));
    sum = _mm_add_epi64(sum, _mm_sad_epu8(x, y));
  }
  return static_cast<std::uint32_t>(_mm_cvtsi128_si32(sum) + _mm_extract_epi16(sum, 4));
#else
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < N; ++i)
    sum += static_cast<std::uint32_t>(std::abs(int{a[i]} - int{b[i]}));
  return sum;
#endif
}

// Eq. (5) from the exclusive count x and the total s = n_a + n_b: x / union, union = (s + x) / 2.
// Written as 2x / (s + x) so that the bound (the same function of a smaller x) is ≤ it in floating point.
inline double jaccard(std::uint32_t exclusive, std::uint32_t total) {
  return total + exclusive == 0 ? 0.0 : 2.0 * exclusive / (static_cast<double>(total) + exclusive);
}

// Σ max(0, least[i] − q[i], q[i] − most[i]) over N bytes: the least Σ |q[i] − e[i]| over any e with
// least ≤ e ≤ most, bytewise.
template <std::size_t N>
std::uint32_t distanceToRangeSum(const std::uint8_t* q, const std::uint8_t* least, const std::uint8_t* most) {
  static_assert(N % 16 == 0);
#if defined(__SSE2__)
  __m128i sum = _mm_setzero_si128();
  for (std::size_t i = 0; i < N; i += 16) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q + i));
    const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(least + i));
    const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(most + i));
    // At most one of the two saturated differences is non-zero, so their sum fits a byte.
    const __m128i outside = _mm_add_epi8(_mm_subs_epu8(x, hi), _mm_subs_epu8(lo, x));
    sum = _mm_add_epi64(sum, _mm_sad_epu8(outside, _mm_setzero_si128()));
  }
  return static_cast<std::uint32_t>(_mm_cvtsi128_si32(sum) + _mm_extract_epi16(sum, 4));
#else
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < N; ++i)
    sum += static_cast<std::uint32_t>(std::max({0, int{least[i]} - int{q[i]}, int{q[i]} - int{most[i]}}));
  return sum;
#endif
}

inline std::uint32_t absoluteDifference(std::uint32_t a, std::uint32_t b) {
  return a > b ? a - b : b - a;
}

// Marks each cell's bit in the occupancy words.
void packOccupancy(const std::vector<std::uint32_t>& cells, std::uint64_t* words) {
  for (std::uint32_t cell : cells)
    words[cell / 64] |= std::uint64_t{1} << (cell % 64);
}

// The logarithms the moment term compares; a moment is positive for any solid (the floor keeps a
// degenerate one finite).
Vec3 logMoments(const Vec3& moments) {
  return moments.cwiseMax(std::numeric_limits<double>::min()).array().log().matrix();
}

// Bytes a vector holds, capacity included; of a vector of vectors (the centroid chunks), theirs too.
template <class T>
std::size_t bytesOf(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}
template <class T>
std::size_t bytesOf(const std::vector<std::vector<T>>& chunks) {
  std::size_t bytes = chunks.capacity() * sizeof(std::vector<T>);
  for (const std::vector<T>& chunk : chunks)
    bytes += bytesOf(chunk);
  return bytes;
}

inline bool isGrid(DescriptorKind kind) {
  return kind != DescriptorKind::kMoment;
}

}  // namespace

std::uint16_t quantizeCentroid(const Vec3& centroid) {
  std::uint16_t code = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int q =
        std::clamp(static_cast<int>(std::floor(centroid[axis] * kQuantLevels)), 0, kQuantLevels - 1);
    code = static_cast<std::uint16_t>(code | (q << (5 * axis)));
  }
  return code;
}

Vec3 dequantizeCentroid(std::uint16_t code) {
  return Vec3((code & 31) + 0.5, ((code >> 5) & 31) + 0.5, ((code >> 10) & 31) + 0.5) / kQuantLevels;
}

const char* toString(SearchMethod method) {
  switch (method) {
    case SearchMethod::kBruteForce:
      return "brute-force";
    case SearchMethod::kPruned:
      return "pruned";
    case SearchMethod::kBuckets:
      return "buckets";
  }
  return "unknown";
}

// The index's arrays (the layout the header describes) and the search's workings. Built once by
// IndexBuilder, then shared, read-only, by every copy of the Index and every searching thread.
struct Index::Impl {
  struct Query;
  class TopK;
  /// A node of a bucket's cluster tree: consecutive slots of the bucket, and the range of what their
  /// bounds compare. A leaf holds up to kLeafSlots slots; an inner node, its two children's.
  struct Cluster {
    std::uint32_t begin = 0, end = 0;    ///< slots
    std::int32_t left = -1, right = -1;  ///< children, -1 for a leaf
    std::uint32_t count = 0;             ///< its bucket's filled-cell count
    std::array<float, 3> lowest{};       ///< least ln moment per axis, rounded down
    std::array<float, 3> highest{};      ///< greatest, rounded up
    CountProfile least, most;            ///< per part of every partition
  };

  explicit Impl(const DescriptorOptions& options);
  std::size_t size() const { return mIds.size(); }
  std::size_t memoryBytes() const;
  Result<std::vector<Match>> search(std::span<const Descriptor> candidates, const SearchOptions& options,
                                    SearchStats* stats) const;

  const std::uint8_t* profile(std::size_t slot) const { return &mProfiles[slot * kProfileBytes]; }
  const std::uint16_t* centroids(std::size_t slot) const {
    const std::uint64_t at = mCentroidAt[slot];
    return mCentroidChunks[at >> 32].data() + (at & 0xffffffffu);
  }
  /// Starts loading what gridDistance reads of the entry in `slot`: its occupancy, and the first of
  /// its centroids.
  void prefetchRecord(std::size_t slot) const {
    const auto* bits = reinterpret_cast<const char*>(&mBits[slot * mWords]);
    for (std::size_t at = 0; at < mWords * sizeof(std::uint64_t); at += 64)
      __builtin_prefetch(bits + at);
    if (mOptions.kind != DescriptorKind::kCentroidVoxel) return;
    const auto* first = reinterpret_cast<const char*>(centroids(slot));
    const std::size_t bytes = std::min<std::size_t>(mCounts[slot] * sizeof(std::uint16_t), 512);
    for (std::size_t at = 0; at < bytes; at += 64)
      __builtin_prefetch(first + at);
  }
  /// `codes`: the descriptor's centroids quantized (centroid-voxel; empty for the other kinds).
  Query prepare(const Descriptor& descriptor, const std::vector<std::uint16_t>& codes, int candidate,
                double momentWeight) const;
  double momentTerm(const Query& q, std::size_t slot) const;
  double gridDistance(const Query& q, std::size_t slot, double threshold, double moments) const;
  double gridBound(const Query& q, std::size_t slot, double moments) const;
  double clusterBound(const Query& q, std::int32_t cluster, double threshold,
                      std::uint32_t* exclusive = nullptr) const;
  double countBound(const Query& q, std::uint32_t count) const;
  double mismatchDistance(std::uint32_t exclusive, std::uint32_t total) const;
  void searchGridPruned(const Query& q, TopK& top, SearchStats& stats, bool parallel) const;
  void compareInFull(const Query& q, std::size_t slot, TopK& top) const;
  void searchGridBuckets(const Query& q, int radius, TopK& top, SearchStats& stats) const;
  void searchMomentTree(const Vec3& q, int candidate, TopK& top, SearchStats& stats) const;

  DescriptorOptions mOptions;
  std::uint32_t mWords = 0;   ///< 64-bit words of occupancy per entry
  std::vector<EntryId> mIds;  ///< per slot
  /// Per slot: the moments in k-d tree order (moment kind), or their logarithms (voxel kinds, for the
  /// moment term).
  std::vector<Vec3> mMoments;
  // Voxel kinds, per slot.
  std::vector<std::uint32_t> mCounts;
  std::vector<std::uint64_t> mBits;
  std::vector<std::uint8_t> mProfiles;     ///< a CountProfile per slot
  std::vector<std::uint64_t> mCentroidAt;  ///< chunk << 32 | offset of the slot's first centroid
  std::vector<std::vector<std::uint16_t>> mCentroidChunks;
  std::vector<std::uint32_t> mBucketBegin;  ///< first slot of each filled-cell count, N³ + 2 entries
  std::vector<std::int32_t> mBucketRoot;    ///< root cluster of each filled-cell count, -1 if none
  std::vector<Cluster> mClusters;
  /// Per cluster, the cells filled in all of its entries (mWords words), then those filled in any.
  std::vector<std::uint64_t> mClusterBits;
  // Moment kind: the tree over mMoments.
  struct Node {
    std::uint32_t begin, end;
    std::int32_t left = -1, right = -1;  ///< children, -1 for a leaf
    int axis = 0;
    double split = 0.0;
  };
  std::vector<Node> mNodes;
};

// The query, expanded for fast comparison: dense centroids indexed by cell.
struct Index::Impl::Query {
  int candidate = 0;
  std::uint32_t count = 0;
  std::vector<std::uint64_t> bits;
  CountProfile profile;
  std::vector<std::uint16_t> dense;
  Vec3 moments = Vec3::Zero();
  Vec3 logMoments = Vec3::Zero();
  double momentWeight = 0.0;  // voxel kinds
};

// The k best (distance, entry) pairs seen, sorted; an entry appears once, with its best candidate.
class Index::Impl::TopK {
 public:
  explicit TopK(std::size_t k) : mK(k) { mItems.reserve(k + 1); }

  /// Anything whose lower bound exceeds this cannot enter.
  double threshold() const { return mItems.size() < mK ? kInfinity : mItems.back().distance; }

  void push(double distance, EntryId id, int candidate, double momentTerm = 0.0) {
    const auto before = [](const Match& a, const Match& b) {
      return a.distance < b.distance || (a.distance == b.distance && a.entry < b.entry);
    };
    for (auto it = mItems.begin(); it != mItems.end(); ++it) {
      if (it->entry != id) continue;
      if (distance < it->distance || (distance == it->distance && candidate < it->candidate)) {
        mItems.erase(it);
        break;
      }
      return;
    }
    Match m;
    m.entry = id;
    m.distance = distance;
    m.momentTerm = momentTerm;
    m.candidate = candidate;
    if (mItems.size() == mK && !before(m, mItems.back())) return;
    mItems.insert(std::upper_bound(mItems.begin(), mItems.end(), m, before), m);
    if (mItems.size() > mK) mItems.pop_back();
  }

  void merge(const TopK& other) {
    for (const Match& m : other.mItems)
      push(m.distance, m.entry, m.candidate, m.momentTerm);
  }

  std::vector<Match>& items() { return mItems; }
  std::size_t capacity() const { return mK; }

 private:
  std::size_t mK;
  std::vector<Match> mItems;
};

Index::Impl::Impl(const DescriptorOptions& options) : mOptions(options) {
  const int n = options.gridSize;
  mWords = isGrid(options.kind) ? static_cast<std::uint32_t>((n * n * n + 63) / 64) : 0;
  if (isGrid(options.kind)) {
    mBucketBegin.assign(static_cast<std::size_t>(n * n * n + 2), 0);
    mBucketRoot.assign(mBucketBegin.size() - 1, -1);
  }
}

std::size_t Index::Impl::memoryBytes() const {
  return bytesOf(mIds) + bytesOf(mMoments) + bytesOf(mCounts) + bytesOf(mBits) + bytesOf(mProfiles) +
         bytesOf(mCentroidAt) + bytesOf(mCentroidChunks) + bytesOf(mBucketBegin) + bytesOf(mBucketRoot) +
         bytesOf(mClusters) + bytesOf(mClusterBits) + bytesOf(mNodes);
}

Index::Impl::Query Index::Impl::prepare(const Descriptor& d, const std::vector<std::uint16_t>& codes,
                                        int candidate, double momentWeight) const {
  Query q;
  q.candidate = candidate;
  q.moments = d.moments;
  if (!isGrid(mOptions.kind)) return q;
  q.logMoments = logMoments(d.moments);
  q.momentWeight = momentWeight;
  q.count = static_cast<std::uint32_t>(d.cells.size());
  q.bits.assign(mWords, 0);
  packOccupancy(d.cells, q.bits.data());
  q.profile = countProfile(q.bits.data(), mOptions.gridSize);
  if (mOptions.kind == DescriptorKind::kCentroidVoxel) {
    q.dense.assign(static_cast<std::size_t>(mWords) * 64, 0);
    for (std::size_t i = 0; i < d.cells.size(); ++i)
      q.dense[d.cells[i]] = codes[i];
  }
  return q;
}

// w · Σ |ln mᵢ − ln m'ᵢ| between the query and the entry in `slot`, summed in axis order as clusterBound
// sums its bound (so that the bound, term by term no larger, is no larger in floating point either).
double Index::Impl::momentTerm(const Query& q, std::size_t slot) const {
  if (q.momentWeight == 0.0) return 0.0;
  const Vec3& m = mMoments[slot];
  return q.momentWeight * ((std::abs(q.logMoments[0] - m[0]) + std::abs(q.logMoments[1] - m[1])) +
                           std::abs(q.logMoments[2] - m[2]));
}

// Eq. (5) or (6) between the query and the entry in `slot`, on quantized centroids, plus `moments` (its
// moment term). Stops early, with a partial value that already exceeds `threshold`, once the entry
// cannot be closer than it: the partial sums only grow, and the same arithmetic on a larger sum never
// gives a smaller result.
double Index::Impl::gridDistance(const Query& q, std::size_t slot, double threshold, double moments) const {
  const std::uint64_t* bits = &mBits[slot * mWords];
  std::uint32_t exclusive = 0;
  for (std::uint32_t w = 0; w < mWords; ++w)
    exclusive += static_cast<std::uint32_t>(std::popcount(bits[w] ^ q.bits[w]));
  const std::uint32_t total = mCounts[slot] + q.count;
  const double mismatches = mismatchDistance(exclusive, total) + moments;
  // Eq. (5) is the mismatches alone; for eq. (6) they may already put the entry beyond the threshold.
  if (mOptions.kind == DescriptorKind::kVoxel || total == 0 || mismatches > threshold) return mismatches;

  // Eq. (6): walk the cells filled in both; an entry's centroids are stored in cell order, so a
  // cell's centroid is at the rank of its bit among the entry's bits.
  const auto value = [&](std::uint64_t terms) {
    return (static_cast<double>(exclusive) + static_cast<double>(terms) * kTermUnit) / total + moments;
  };
  const auto& table = centroidDistanceTable();
  const std::uint16_t* entryCentroids = centroids(slot);
  std::uint64_t terms = 0;
  std::uint32_t rank = 0;
  for (std::uint32_t w = 0; w < mWords; ++w) {
    const std::uint64_t entryWord = bits[w];
    const std::uint16_t* queryCodes = &q.dense[w * 64];
    for (std::uint64_t both = entryWord & q.bits[w]; both != 0; both &= both - 1) {
      const int bit = std::countr_zero(both);
      const auto index =
          rank + static_cast<std::uint32_t>(std::popcount(entryWord & ((std::uint64_t{1} << bit) - 1)));
      terms += table[static_cast<std::size_t>(squaredCodeDistance(entryCentroids[index], queryCodes[bit]))];
    }
    rank += static_cast<std::uint32_t>(std::popcount(entryWord));
    if ((w & 3) == 3 && value(terms) > threshold) return value(terms);
  }
  return value(terms);
}

// A lower bound of gridDistance from counts alone: the cells filled in exactly one grid number at
// least Σ |count_a − count_b| over the parts of any partition of the grid (slabs, blocks); plus the
// entry's moment term `moments`, the same value gridDistance adds.
double Index::Impl::gridBound(const Query& q, std::size_t slot, double moments) const {
  const std::uint8_t* a = profile(slot);
  const std::uint8_t* b = q.profile.data();
  std::uint32_t best = absoluteDifferenceSum<kProfileBytes - kSlabBytes>(a + kSlabBytes, b + kSlabBytes);
  for (int axis = 0; axis < 3; ++axis)
    best =
        std::max(best, absoluteDifferenceSum<kProfileBins>(a + axis * kProfileBins, b + axis * kProfileBins));
  best = std::max(best, absoluteDifference(mCounts[slot], q.count));
  return mismatchDistance(best, mCounts[slot] + q.count) + moments;
}

// A lower bound of gridDistance for every slot of a cluster (its slots share one filled-cell count): a
// cell filled in the query and in none of the entries, or in all of them and not in the query, is
// filled in one grid only; each part's count differs from the query's at least by its distance to the
// cluster's range of that part; each ln moment differs at least by its distance to the cluster's
// range. Summed in the same order as gridDistance and momentTerm sum theirs, term by term no larger,
// so no larger in floating point either. Returns as soon as the terms so far exceed `threshold`.
double Index::Impl::clusterBound(const Query& q, std::int32_t index, double threshold,
                                 std::uint32_t* exclusive) const {
  const Cluster& cluster = mClusters[static_cast<std::size_t>(index)];
  const std::uint32_t count = cluster.count;
  double moments = 0.0;
  if (q.momentWeight != 0.0) {
    const auto outside = [&](int axis) {
      const double x = q.logMoments[axis];
      const auto a = static_cast<std::size_t>(axis);
      return std::max(
          {0.0, static_cast<double>(cluster.lowest[a]) - x, x - static_cast<double>(cluster.highest[a])});
    };
    moments = q.momentWeight * ((outside(0) + outside(1)) + outside(2));
  }
  // The cheapest terms first: the moments and the count may already put the cluster past the threshold.
  std::uint32_t best = absoluteDifference(count, q.count);
  if (exclusive) *exclusive = best;
  if (const double bound = mismatchDistance(best, count + q.count) + moments; bound > threshold) return bound;
  const std::uint64_t* all = &mClusterBits[static_cast<std::size_t>(index) * 2 * mWords];
  const std::uint64_t* any = all + mWords;
  std::uint32_t surely = 0;
  for (std::uint32_t w = 0; w < mWords; ++w)
    surely +=
        static_cast<std::uint32_t>(std::popcount(q.bits[w] & ~any[w]) + std::popcount(all[w] & ~q.bits[w]));
  best = std::max(best, surely);
  if (exclusive) *exclusive = best;
  if (const double bound = mismatchDistance(best, count + q.count) + moments; bound > threshold) return bound;
  const std::uint8_t* b = q.profile.data();
  const std::uint8_t* least = cluster.least.data();
  const std::uint8_t* most = cluster.most.data();
  best = std::max(best, distanceToRangeSum<kProfileBytes - kSlabBytes>(b + kSlabBytes, least + kSlabBytes,
                                                                       most + kSlabBytes));
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t at = static_cast<std::size_t>(axis) * kProfileBins;
    best = std::max(best, distanceToRangeSum<kProfileBins>(b + at, least + at, most + at));
  }
  if (exclusive) *exclusive = best;
  return mismatchDistance(best, count + q.count) + moments;
}

// The bound for every entry with `count` filled cells: |count − n_q| cells are filled in one only
// (the moment term, ≥ 0, left out).
double Index::Impl::countBound(const Query& q, std::uint32_t count) const {
  return mismatchDistance(absoluteDifference(count, q.count), count + q.count);
}

// The distance with `exclusive` cells filled in one grid only and no centroid term, `total` = n₁ + n₂:
// eq. (5) itself, or eq. (6) without its centroid terms. Distances and bounds all go through it, so a
// bound (a smaller count) never exceeds its distance in floating point.
double Index::Impl::mismatchDistance(std::uint32_t exclusive, std::uint32_t total) const {
  if (mOptions.kind == DescriptorKind::kVoxel) return jaccard(exclusive, total);
  return total == 0 ? 0.0 : static_cast<double>(exclusive) / total;
}

// Buckets of equal filled-cell count, visited outward from the query's count in order of their bound;
// a side stops when its bound exceeds the k-th best distance (the bounds grow monotonically outward).
// Within a bucket, its cluster tree is walked depth first, the nearer child (by bound) first, and a
// cluster whose bound exceeds the k-th best is skipped whole; the entries of the leaves reached are
// bounded one by one. With `parallel`, once the nearest buckets have set a threshold, the buckets still
// within it are scanned by TBB tasks that share the least of their k-th bests: each is an upper bound of
// the final k-th best, so pruning against it stays exact, and merging the lists gives the same answer as
// one thread.
void Index::Impl::searchGridPruned(const Query& q, TopK& top, SearchStats& stats, bool parallel) const {
  const auto maxCount = static_cast<std::int64_t>(mBucketBegin.size()) - 2;
  std::int64_t up = std::min<std::int64_t>(q.count, maxCount + 1), down = up - 1;
  const auto scan = [&](std::int64_t count, TopK& local, SearchStats& st, double shared) {
    const std::int32_t root = mBucketRoot[static_cast<std::size_t>(count)];
    if (root < 0) return;
    struct Pending {
      std::int32_t cluster;
      double bound;
      std::uint32_t exclusive;  // the least count of cells filled in one grid only, over its entries
    };
    std::array<Pending, 128> stack;  // a tree of < 2³² slots is < 32 deep; one sibling waits per level
    std::size_t depth = 0;
    stack[depth] = {root, 0.0, 0};
    stack[depth].bound = clusterBound(q, root, std::min(shared, local.threshold()), &stack[depth].exclusive);
    ++depth;
    ++st.groupBoundEvaluations;
    while (depth > 0) {
      const Pending pending = stack[--depth];
      if (pending.bound > std::min(shared, local.threshold())) continue;
      const Cluster& cluster = mClusters[static_cast<std::size_t>(pending.cluster)];
      if (cluster.left >= 0) {
        // Both children's loads at once, rather than one after the other: the walk is bound by memory.
        for (const std::int32_t child : {cluster.left, cluster.right}) {
          const auto* record = reinterpret_cast<const char*>(&mClusters[static_cast<std::size_t>(child)]);
          for (std::size_t at = 0; at < sizeof(Cluster); at += 64)
            __builtin_prefetch(record + at);
          const auto* bits =
              reinterpret_cast<const char*>(&mClusterBits[static_cast<std::size_t>(child) * 2 * mWords]);
          for (std::size_t at = 0; at < 2 * mWords * sizeof(std::uint64_t); at += 64)
            __builtin_prefetch(bits + at);
        }
        const double threshold = std::min(shared, local.threshold());
        Pending left{cluster.left, 0.0, 0}, right{cluster.right, 0.0, 0};
        left.bound = clusterBound(q, cluster.left, threshold, &left.exclusive);
        right.bound = clusterBound(q, cluster.right, threshold, &right.exclusive);
        st.groupBoundEvaluations += 2;
        // A leaf that may be opened: its entries' moments and counts start loading now.
        for (const Pending& child : {left, right}) {
          const Cluster& c = mClusters[static_cast<std::size_t>(child.cluster)];
          if (c.left >= 0 || child.bound > threshold) continue;
          const auto* moments = reinterpret_cast<const char*>(&mMoments[c.begin]);
          for (std::size_t at = 0; at < (c.end - c.begin) * sizeof(Vec3); at += 64)
            __builtin_prefetch(moments + at);
          const auto* profiles = reinterpret_cast<const char*>(profile(c.begin));
          for (std::size_t at = 0; at < (c.end - c.begin) * kProfileBytes; at += 64)
            __builtin_prefetch(profiles + at);
        }
        // The farther below the nearer, so that the nearer is taken first.
        const bool leftFirst = left.bound <= right.bound;
        stack[depth++] = leftFirst ? right : left;
        stack[depth++] = leftFirst ? left : right;
        continue;
      }
      // Every entry of the leaf has at least its `exclusive` cells filled in one grid only: with the
      // entry's own moment term, that rules many out before their counts are read.
      const double leafMismatch = mismatchDistance(pending.exclusive, cluster.count + q.count);
      // First the bounds of the whole leaf, fetching the records of the entries they leave in, then
      // their distances: the loads of several entries overlap, where one after the other each distance
      // would wait for its own.
      struct Survivor {
        std::size_t slot;
        double bound, moments;
      };
      std::array<Survivor, kLeafSlots> survivors;
      std::size_t survivorCount = 0;
      const double leafThreshold = std::min(shared, local.threshold());
      for (std::size_t slot = cluster.begin; slot < cluster.end; ++slot) {
        ++st.boundEvaluations;
        const double moments = momentTerm(q, slot);
        if (leafMismatch + moments > leafThreshold) continue;
        const double bound = gridBound(q, slot, moments);
        if (bound > leafThreshold) continue;
        prefetchRecord(slot);
        survivors[survivorCount++] = {slot, bound, moments};
      }
      for (std::size_t i = 0; i < survivorCount; ++i) {
        const Survivor& s = survivors[i];
        const double threshold = std::min(shared, local.threshold());
        if (s.bound > threshold) continue;
        ++st.distanceEvaluations;
        local.push(gridDistance(q, s.slot, threshold, s.moments), mIds[s.slot], q.candidate, s.moments);
      }
    }
  };
  const auto slotsOf = [&](std::int64_t count) {
    const auto c = static_cast<std::size_t>(count);
    return std::size_t{mBucketBegin[c + 1] - mBucketBegin[c]};
  };
  // The next bucket in bound order, or -1 when no bucket left can hold a match.
  const auto next = [&](double threshold) -> std::int64_t {
    const double upBound = up <= maxCount ? countBound(q, static_cast<std::uint32_t>(up)) : kInfinity;
    const double downBound = down >= 0 ? countBound(q, static_cast<std::uint32_t>(down)) : kInfinity;
    if (std::min(upBound, downBound) == kInfinity || std::min(upBound, downBound) > threshold) return -1;
    return upBound <= downBound ? up++ : down--;
  };

  constexpr std::size_t kSequentialSlots = 8192;
  std::size_t scanned = 0;
  for (std::int64_t c = next(top.threshold()); c >= 0; c = next(top.threshold())) {
    scan(c, top, stats, kInfinity);
    scanned += slotsOf(c);
    if (parallel && scanned >= kSequentialSlots) break;
  }
  if (!parallel || scanned < kSequentialSlots) return;

  // The buckets left within the threshold, scanned in parallel.
  std::vector<std::int64_t> buckets;
  for (std::int64_t c = next(top.threshold()); c >= 0; c = next(top.threshold()))
    if (slotsOf(c) > 0) buckets.push_back(c);
  if (buckets.empty()) return;
  std::atomic<double> shared{top.threshold()};
  struct Part {
    TopK top;
    SearchStats stats;
  };
  const std::size_t k = top.capacity();
  const Part found = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, buckets.size(), 1), Part{TopK(k), {}},
      [&](const tbb::blocked_range<std::size_t>& r, Part part) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          scan(buckets[i], part.top, part.stats, shared.load(std::memory_order_relaxed));
          // Publish this task's k-th best if it lowers the shared threshold.
          double seen = shared.load(std::memory_order_relaxed);
          const double mine = part.top.threshold();
          while (mine < seen && !shared.compare_exchange_weak(seen, mine, std::memory_order_relaxed)) {
          }
        }
        return part;
      },
      [](Part a, const Part& b) {
        a.top.merge(b.top);
        a.stats.boundEvaluations += b.stats.boundEvaluations;
        a.stats.groupBoundEvaluations += b.stats.groupBoundEvaluations;
        a.stats.distanceEvaluations += b.stats.distanceEvaluations;
        return a;
      });
  top.merge(found.top);
  stats.boundEvaluations += found.stats.boundEvaluations;
  stats.groupBoundEvaluations += found.stats.groupBoundEvaluations;
  stats.distanceEvaluations += found.stats.distanceEvaluations;
}

// The entry in `slot` against the query, its whole distance with no bound to stop it, offered to `top`.
void Index::Impl::compareInFull(const Query& q, std::size_t slot, TopK& top) const {
  if (!isGrid(mOptions.kind)) {
    top.push(momentDistance(q.moments, mMoments[slot]), mIds[slot], q.candidate);
    return;
  }
  const double moments = momentTerm(q, slot);
  top.push(gridDistance(q, slot, kInfinity, moments), mIds[slot], q.candidate, moments);
}

// Paper §5: only the entries whose filled-cell count is within ±r of the query's, all compared.
void Index::Impl::searchGridBuckets(const Query& q, int radius, TopK& top, SearchStats& stats) const {
  const auto maxCount = static_cast<std::int64_t>(mBucketBegin.size()) - 2;
  const std::int64_t first = std::max<std::int64_t>(0, static_cast<std::int64_t>(q.count) - radius);
  const std::int64_t last = std::min<std::int64_t>(maxCount, static_cast<std::int64_t>(q.count) + radius);
  for (std::int64_t c = first; c <= last; ++c)
    for (std::size_t slot = mBucketBegin[static_cast<std::size_t>(c)];
         slot < mBucketBegin[static_cast<std::size_t>(c) + 1]; ++slot) {
      ++stats.distanceEvaluations;
      compareInFull(q, slot, top);
    }
}

// Nearest moments in the k-d tree: the nearer child first, the farther one only if the squared
// distance to its splitting plane does not exceed the k-th best.
void Index::Impl::searchMomentTree(const Vec3& q, int candidate, TopK& top, SearchStats& stats) const {
  if (mNodes.empty()) return;
  std::int32_t stack[128];
  int depth = 0;
  stack[depth++] = 0;
  while (depth > 0) {
    const Node& node = mNodes[static_cast<std::size_t>(stack[--depth])];
    ++stats.boundEvaluations;
    if (node.left < 0) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        ++stats.distanceEvaluations;
        top.push(momentDistance(q, mMoments[i]), mIds[i], candidate);
      }
      continue;
    }
    const double diff = q[node.axis] - node.split;
    const std::int32_t nearChild = diff < 0.0 ? node.left : node.right;
    const std::int32_t farChild = diff < 0.0 ? node.right : node.left;
    // Depth-first: push the far child first (visited later), after checking it can still matter.
    if (diff * diff <= top.threshold()) stack[depth++] = farChild;
    stack[depth++] = nearChild;
  }
}

Result<std::vector<Match>> Index::Impl::search(std::span<const Descriptor> candidates,
                                               const SearchOptions& options, SearchStats* stats) const {
  if (candidates.empty())
    return Error{ErrorCode::kInvalidArgument, "search needs at least one query descriptor"};
  if (options.k < 1) return Error{ErrorCode::kInvalidArgument, "k must be at least 1"};
  if (!(options.momentWeight >= 0.0 && std::isfinite(options.momentWeight)))
    return Error{ErrorCode::kInvalidArgument, "the moment weight must be finite and at least 0"};
  for (const Descriptor& d : candidates)
    if (Status valid = validateDescriptor(d, mOptions); !valid)
      return Error{valid.error().code, "query " + valid.error().message};
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  const auto k = static_cast<std::size_t>(options.k);
  // A candidate that the index sees as an earlier one (the same cells, quantized centroids and moments:
  // often most turns of a round shape) has that one's distance to every entry and loses its ties to it:
  // the pruned searches leave it out. Brute force, the oracle, compares every candidate.
  const bool everyCandidate = !options.among.empty() || options.method == SearchMethod::kBruteForce;
  std::vector<std::vector<std::uint16_t>> codes(candidates.size());  // centroid-voxel: as the index has them
  const auto alike = [&](std::size_t a, std::size_t b) {
    return candidates[a].moments == candidates[b].moments && candidates[a].cells == candidates[b].cells &&
           codes[a] == codes[b];
  };
  std::vector<Query> queries;
  queries.reserve(candidates.size());
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (mOptions.kind == DescriptorKind::kCentroidVoxel)
      for (const Vec3& centroid : candidates[c].centroids)
        codes[c].push_back(quantizeCentroid(centroid));
    bool seen = false;
    for (std::size_t e = 0; e < c && !seen && !everyCandidate; ++e)
      seen = alike(e, c);
    if (!seen) queries.push_back(prepare(candidates[c], codes[c], static_cast<int>(c), options.momentWeight));
  }

  if (!std::is_sorted(options.among.begin(), options.among.end(), std::less_equal<>()))
    return Error{ErrorCode::kInvalidArgument,
                 "the entries to search among must be ascending, without repeats"};

  TopK top(k);
  const bool grid = isGrid(mOptions.kind);
  if (!options.among.empty()) {
    // Only the entries listed, each against every candidate, as brute force compares them.
    for (std::size_t slot = 0; slot < size(); ++slot) {
      if (!std::binary_search(options.among.begin(), options.among.end(), mIds[slot])) continue;
      for (const Query& q : queries) {
        ++st.distanceEvaluations;
        compareInFull(q, slot, top);
      }
    }
  } else if (options.method == SearchMethod::kBruteForce) {
    // The oracle: every entry, its least distance over the candidates.
    const auto scan = [&](const tbb::blocked_range<std::size_t>& range, TopK part) {
      for (std::size_t slot = range.begin(); slot != range.end(); ++slot)
        for (const Query& q : queries)
          compareInFull(q, slot, part);
      return part;
    };
    const tbb::blocked_range<std::size_t> all(0, size(), 1024);
    if (options.parallel) {
      top = tbb::parallel_reduce(all, TopK(k), scan, [](TopK a, const TopK& b) {
        a.merge(b);
        return a;
      });
    } else {
      top = scan(all, TopK(k));
    }
    st.distanceEvaluations += size() * queries.size();
  } else {
    // One shared k-best across candidates: pruning against it is safe, since the final k-th best
    // can only be smaller.
    for (const Query& q : queries) {
      if (!grid) {
        searchMomentTree(q.moments, q.candidate, top, st);
      } else if (options.method == SearchMethod::kPruned) {
        searchGridPruned(q, top, st, options.parallel);
      } else {
        searchGridBuckets(q, options.bucketRadius, top, st);
      }
    }
  }
  std::vector<Match> out = std::move(top.items());
  for (Match& m : out)
    m.orientation = candidates[static_cast<std::size_t>(m.candidate)].orientation;
  return out;
}

Index::Index(const DescriptorOptions& options) : mImpl(std::make_shared<const Impl>(options)) {}
Index::Index(std::shared_ptr<const Impl> impl) : mImpl(std::move(impl)) {}

const DescriptorOptions& Index::options() const {
  return mImpl->mOptions;
}
std::size_t Index::size() const {
  return mImpl->size();
}
std::size_t Index::memoryBytes() const {
  return mImpl->memoryBytes();
}
Result<std::vector<Match>> Index::search(std::span<const Descriptor> candidates, const SearchOptions& options,
                                         SearchStats* stats) const {
  return mImpl->search(candidates, options, stats);
}

namespace {

// Centroids per chunk (2 MiB): an entry's never straddle two, and a chunk, once full, never moves.
constexpr std::size_t kCentroidChunk = std::size_t{1} << 20;

// Reorders `values`, records of `width` elements, in place so that the record at `order[slot]` comes to
// `slot` (`order` a permutation), one cycle at a time: one record of extra memory.
template <class T>
void permute(std::vector<T>& values, std::size_t width, const std::vector<std::uint32_t>& order) {
  std::vector<bool> done(order.size(), false);
  std::vector<T> held(width);
  for (std::size_t start = 0; start < order.size(); ++start) {
    if (done[start]) continue;
    std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(start * width), width, held.begin());
    for (std::size_t to = start;;) {
      done[to] = true;
      const std::size_t from = order[to];
      T* destination = values.data() + to * width;
      if (from == start) {
        std::copy_n(held.begin(), width, destination);
        break;
      }
      std::copy_n(values.data() + from * width, width, destination);
      to = from;
    }
  }
}

// Orders order[begin, end) (entries of one bucket, slots once reordered) into a cluster tree, appended
// to `clusters`: a k-d split along the widest axis of the ln moments, at a multiple of kLeafSlots (so
// that leaves are full), the median by (value, id) for determinism. Returns the root's index; children
// come after their parent. Their ranges are filled in later, from the reordered slots.
template <class Cluster>
std::int32_t arrangeClusters(std::vector<std::uint32_t>& order, std::uint32_t begin, std::uint32_t end,
                             const std::vector<Vec3>& logMoments, const std::vector<EntryId>& ids,
                             std::vector<Cluster>& clusters) {
  const auto self = static_cast<std::int32_t>(clusters.size());
  clusters.emplace_back();
  clusters.back().begin = begin;
  clusters.back().end = end;
  if (end - begin <= kLeafSlots) return self;
  Vec3 lo = Vec3::Constant(kInfinity), hi = -lo;
  for (std::uint32_t i = begin; i < end; ++i) {
    lo = lo.cwiseMin(logMoments[order[i]]);
    hi = hi.cwiseMax(logMoments[order[i]]);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const std::uint32_t leaves = (end - begin + kLeafSlots - 1) / kLeafSlots;
  const std::uint32_t mid = begin + (leaves + 1) / 2 * kLeafSlots;
  const auto at = [&order](std::uint32_t i) { return order.begin() + static_cast<std::ptrdiff_t>(i); };
  std::nth_element(at(begin), at(mid), at(end), [&](std::uint32_t a, std::uint32_t b) {
    return logMoments[a][axis] < logMoments[b][axis] ||
           (logMoments[a][axis] == logMoments[b][axis] && ids[a] < ids[b]);
  });
  const std::int32_t left = arrangeClusters(order, begin, mid, logMoments, ids, clusters);
  const std::int32_t right = arrangeClusters(order, mid, end, logMoments, ids, clusters);
  clusters[static_cast<std::size_t>(self)].left = left;
  clusters[static_cast<std::size_t>(self)].right = right;
  return self;
}

float roundedDown(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float roundedUp(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace

IndexBuilder::IndexBuilder(const DescriptorOptions& options) : mOptions(options) {
  const int n = options.gridSize;
  mWords = isGrid(options.kind) ? static_cast<std::uint32_t>((n * n * n + 63) / 64) : 0;
}

void IndexBuilder::reserve(std::size_t entries) {
  mIds.reserve(entries);
  mMoments.reserve(entries);
  if (!isGrid(mOptions.kind)) return;
  mCounts.reserve(entries);
  mBits.reserve(entries * mWords);
  mProfiles.reserve(entries * kProfileBytes);
  if (mOptions.kind == DescriptorKind::kCentroidVoxel) mCentroidAt.reserve(entries);
}

std::size_t IndexBuilder::memoryBytes() const {
  return bytesOf(mIds) + bytesOf(mMoments) + bytesOf(mCounts) + bytesOf(mBits) + bytesOf(mProfiles) +
         bytesOf(mCentroidAt) + bytesOf(mCentroidChunks);
}

Status IndexBuilder::add(EntryId id, const Descriptor& d) {
  if (Status valid = validateDescriptor(d, mOptions); !valid)
    return Error{valid.error().code, "entry " + std::to_string(id) + ": " + valid.error().message};
  mIds.push_back(id);
  if (!isGrid(d.kind)) {
    mMoments.push_back(d.moments);
    return Ok{};
  }
  mMoments.push_back(logMoments(d.moments));
  mCounts.push_back(static_cast<std::uint32_t>(d.cells.size()));
  const std::size_t base = mBits.size();
  mBits.resize(base + mWords, 0);
  packOccupancy(d.cells, &mBits[base]);
  const CountProfile profile = countProfile(&mBits[base], mOptions.gridSize);
  mProfiles.insert(mProfiles.end(), profile.begin(), profile.end());
  if (mOptions.kind != DescriptorKind::kCentroidVoxel) return Ok{};
  if (mCentroidChunks.empty() || mCentroidChunks.back().size() + d.centroids.size() > kCentroidChunk) {
    mCentroidChunks.emplace_back();
    mCentroidChunks.back().reserve(std::max(kCentroidChunk, d.centroids.size()));
  }
  std::vector<std::uint16_t>& chunk = mCentroidChunks.back();
  mCentroidAt.push_back((mCentroidChunks.size() - 1) << 32 | chunk.size());
  for (const Vec3& c : d.centroids)
    chunk.push_back(quantizeCentroid(c));
  return Ok{};
}

Result<Index> IndexBuilder::build() && {
  const std::size_t count = mIds.size();
  {
    std::vector<EntryId> sorted = mIds;
    std::sort(sorted.begin(), sorted.end());
    if (auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end())
      return Error{ErrorCode::kInvalidArgument, "entry " + std::to_string(*dup) + " added twice"};
  }
  auto impl = std::make_shared<Index::Impl>(mOptions);
  Index::Impl& index = *impl;
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), std::uint32_t{0});

  if (!isGrid(mOptions.kind)) {
    // k-d tree: split the widest axis at the median, (value, id) ordered for determinism.
    if (count > 0) index.mNodes.push_back({0, static_cast<std::uint32_t>(count)});
    struct Range {
      std::uint32_t begin, end;
      std::int32_t node;
    };
    std::vector<Range> work;
    if (count > 0) work.push_back({0, static_cast<std::uint32_t>(count), 0});
    while (!work.empty()) {
      const Range r = work.back();
      work.pop_back();
      if (r.end - r.begin <= kLeafSize) continue;
      Vec3 lo = Vec3::Constant(kInfinity), hi = -lo;
      for (std::uint32_t i = r.begin; i < r.end; ++i) {
        lo = lo.cwiseMin(mMoments[order[i]]);
        hi = hi.cwiseMax(mMoments[order[i]]);
      }
      int axis = 0;
      (hi - lo).maxCoeff(&axis);
      const std::uint32_t mid = r.begin + (r.end - r.begin) / 2;
      std::nth_element(order.begin() + r.begin, order.begin() + mid, order.begin() + r.end,
                       [&](std::uint32_t a, std::uint32_t b) {
                         return mMoments[a][axis] < mMoments[b][axis] ||
                                (mMoments[a][axis] == mMoments[b][axis] && mIds[a] < mIds[b]);
                       });
      const auto left = static_cast<std::int32_t>(index.mNodes.size());
      index.mNodes.push_back({r.begin, mid});
      index.mNodes.push_back({mid, r.end});
      Index::Impl::Node& node = index.mNodes[static_cast<std::size_t>(r.node)];
      node.left = left;
      node.right = left + 1;
      node.axis = axis;
      node.split = mMoments[order[mid]][axis];
      work.push_back({r.begin, mid, left});
      work.push_back({mid, r.end, left + 1});
    }
    permute(mIds, 1, order);
    permute(mMoments, 1, order);
    index.mIds = std::move(mIds);
    index.mMoments = std::move(mMoments);
    return Index(std::move(impl));
  }

  // Voxel kinds: slots sorted by (filled count, id) into buckets of equal count, each bucket arranged
  // into a cluster tree; then every array reordered in place (the centroids stay where they are: each slot
  // knows where its own start).
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return mCounts[a] < mCounts[b] || (mCounts[a] == mCounts[b] && mIds[a] < mIds[b]);
  });
  for (std::size_t begin = 0; begin < count;) {
    std::size_t end = begin;
    while (end < count && mCounts[order[end]] == mCounts[order[begin]])
      ++end;
    index.mBucketRoot[mCounts[order[begin]]] =
        arrangeClusters(order, static_cast<std::uint32_t>(begin), static_cast<std::uint32_t>(end), mMoments,
                        mIds, index.mClusters);
    begin = end;
  }
  permute(mIds, 1, order);
  permute(mMoments, 1, order);
  permute(mCounts, 1, order);
  permute(mBits, mWords, order);
  permute(mProfiles, kProfileBytes, order);
  if (mOptions.kind == DescriptorKind::kCentroidVoxel) permute(mCentroidAt, 1, order);
  order = {};
  index.mIds = std::move(mIds);
  index.mMoments = std::move(mMoments);
  index.mCounts = std::move(mCounts);
  index.mBits = std::move(mBits);
  index.mProfiles = std::move(mProfiles);
  index.mCentroidAt = std::move(mCentroidAt);
  index.mCentroidChunks = std::move(mCentroidChunks);

  for (std::size_t slot = 0; slot < count; ++slot)
    ++index.mBucketBegin[index.mCounts[slot] + 1];
  for (std::size_t c = 1; c < index.mBucketBegin.size(); ++c)
    index.mBucketBegin[c] += index.mBucketBegin[c - 1];
  // The clusters' ranges, leaves from their slots, inner nodes from their children (which follow them).
  const std::size_t words = mWords;
  index.mClusterBits.assign(index.mClusters.size() * 2 * words, 0);
  for (std::size_t c = index.mClusters.size(); c-- > 0;) {
    Index::Impl::Cluster& cluster = index.mClusters[c];
    std::uint64_t* all = &index.mClusterBits[c * 2 * words];
    std::uint64_t* any = all + words;
    if (cluster.left >= 0) {
      const auto l = static_cast<std::size_t>(cluster.left), r = static_cast<std::size_t>(cluster.right);
      const Index::Impl::Cluster& a = index.mClusters[l];
      const Index::Impl::Cluster& b = index.mClusters[r];
      cluster.count = a.count;
      for (std::size_t w = 0; w < words; ++w) {
        all[w] = index.mClusterBits[l * 2 * words + w] & index.mClusterBits[r * 2 * words + w];
        any[w] =
            index.mClusterBits[l * 2 * words + words + w] | index.mClusterBits[r * 2 * words + words + w];
      }
      for (std::size_t i = 0; i < kProfileBytes; ++i) {
        cluster.least[i] = std::min(a.least[i], b.least[i]);
        cluster.most[i] = std::max(a.most[i], b.most[i]);
      }
      for (std::size_t axis = 0; axis < 3; ++axis) {
        cluster.lowest[axis] = std::min(a.lowest[axis], b.lowest[axis]);
        cluster.highest[axis] = std::max(a.highest[axis], b.highest[axis]);
      }
      continue;
    }
    cluster.count = index.mCounts[cluster.begin];
    cluster.least.fill(255);
    cluster.most.fill(0);
    std::fill_n(all, words, ~std::uint64_t{0});
    Vec3 lo = Vec3::Constant(kInfinity), hi = -lo;
    for (std::uint32_t slot = cluster.begin; slot < cluster.end; ++slot) {
      for (std::size_t w = 0; w < words; ++w) {
        all[w] &= index.mBits[slot * words + w];
        any[w] |= index.mBits[slot * words + w];
      }
      const std::uint8_t* p = index.profile(slot);
      for (std::size_t i = 0; i < kProfileBytes; ++i) {
        cluster.least[i] = std::min(cluster.least[i], p[i]);
        cluster.most[i] = std::max(cluster.most[i], p[i]);
      }
      lo = lo.cwiseMin(index.mMoments[slot]);
      hi = hi.cwiseMax(index.mMoments[slot]);
    }
    for (std::size_t axis = 0; axis < 3; ++axis) {
      cluster.lowest[axis] = roundedDown(lo[static_cast<Eigen::Index>(axis)]);
      cluster.highest[axis] = roundedUp(hi[static_cast<Eigen::Index>(axis)]);
    }
  }
  return Index(std::move(impl));
}

}  // namespace shapedb::core
