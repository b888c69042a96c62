#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include <shapedb/core/index.h>

#include "support/synthetic.h"
#include "support/test_support.h"

namespace shapedb::core {
namespace {

// Descriptors of `count` random shapes, the bases that jittered entries and queries are made from.
std::vector<Descriptor> baseDescriptors(DescriptorKind kind, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Descriptor> out;
  while (static_cast<int>(out.size()) < count) {
    Result<test::DescribedMesh> d =
        test::describeMesh(test::makeRandomShape(rng, 2), test::descriptorOptions(kind));
    if (d) out.push_back(d->descriptor);
  }
  return out;
}

// `count` jittered copies of the bases in turn, each with flips() cells switched and centroids moved by
// up to ±noise.
std::vector<Descriptor> jitteredEntries(const std::vector<Descriptor>& bases, int count, std::mt19937_64& rng,
                                        const std::function<int()>& flips, double noise) {
  std::vector<Descriptor> entries;
  for (int i = 0; i < count; ++i) {
    const int f = flips();
    entries.push_back(
        test::jitterDescriptor(bases[static_cast<std::size_t>(i) % bases.size()], rng, f, noise));
  }
  return entries;
}

// A query: one to three orientation candidates, each a jittered copy of one random base; and on every
// other query, copies of those put among them, as a round shape's turns often are: one the same, one whose
// centroids moved by far less than the index quantizes them to, one with a centroid moved by a tenth
// of its cell (which the pruned search must not take for the same).
std::vector<Descriptor> queryCandidates(const std::vector<Descriptor>& bases, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> flips(0, 10), pickCandidates(1, 3);
  std::uniform_int_distribution<std::size_t> pickBase(0, bases.size() - 1);
  const Descriptor& base = bases[pickBase(rng)];
  std::vector<Descriptor> candidates;
  for (int c = pickCandidates(rng); c > 0; --c)
    candidates.push_back(test::jitterDescriptor(base, rng, flips(rng) + 2, 0.2));
  if (std::bernoulli_distribution(0.5)(rng)) {
    std::vector<Descriptor> copies;
    for (int variant = 0; variant < 3; ++variant) {
      Descriptor copy = candidates[std::uniform_int_distribution<std::size_t>(0, candidates.size() - 1)(rng)];
      for (Vec3& c : copy.centroids) {
        if (variant == 1) c = (c.array() + 1e-12).min(1.0).matrix();
        if (variant == 2 && &c == &copy.centroids.front()) c = (c.array() + 0.1).min(1.0).matrix();
      }
      copies.push_back(std::move(copy));
    }
    for (Descriptor& copy : copies) {
      const auto at = std::uniform_int_distribution<std::size_t>(0, candidates.size())(rng);
      candidates.insert(candidates.begin() + static_cast<std::ptrdiff_t>(at), std::move(copy));
    }
  }
  return candidates;
}

Index buildIndex(DescriptorKind kind, const std::vector<Descriptor>& entries) {
  IndexBuilder builder(test::descriptorOptions(kind));
  for (std::size_t i = 0; i < entries.size(); ++i)
    EXPECT_TRUE(builder.add(static_cast<EntryId>(1000 + 7 * i), entries[i]).ok());
  Result<Index> index = std::move(builder).build();
  EXPECT_TRUE(index.ok());
  return std::move(index).value();
}

std::vector<Match> searchOrDie(const Index& index, std::span<const Descriptor> query, SearchOptions options,
                               SearchStats* stats = nullptr) {
  Result<std::vector<Match>> r = index.search(query, options, stats);
  EXPECT_TRUE(r.ok()) << (r ? "" : r.error().message);
  return r ? std::move(r).value() : std::vector<Match>{};
}

void expectSameMatches(const std::vector<Match>& a, const std::vector<Match>& b, const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].entry, b[i].entry) << where << " rank " << i;
    EXPECT_EQ(a[i].distance, b[i].distance) << where << " rank " << i;
    EXPECT_EQ(a[i].candidate, b[i].candidate) << where << " rank " << i;
  }
}

// Pruned search against brute force: `queries` random queries against `entryCount` jittered entries,
// with k from 1 to 10, one to six orientation candidates per query (some of them alike), and moment
// weights 0, 1 and 5.
void expectPrunedEqualsBruteForce(DescriptorKind kind, int entryCount, int queries) {
  const std::vector<Descriptor> bases = baseDescriptors(kind, 150, 42);
  std::mt19937_64 rng(99);
  std::uniform_int_distribution<int> flips(0, 10), pickK(1, 10);
  const std::vector<Descriptor> entries = jitteredEntries(
      bases, entryCount, rng, [&] { return flips(rng); }, 0.15);
  const Index index = buildIndex(kind, entries);
  ASSERT_EQ(index.size(), static_cast<std::size_t>(entryCount));

  SearchStats pruned, brute;
  for (int q = 0; q < queries; ++q) {
    const std::vector<Descriptor> candidates = queryCandidates(bases, rng);
    SearchOptions options;
    options.k = pickK(rng);
    options.momentWeight = q % 3 == 0 ? 0.0 : q % 3 == 1 ? 1.0 : 5.0;  // the paper's distance, ours, more
    options.method = SearchMethod::kBruteForce;
    const std::vector<Match> expected = searchOrDie(index, candidates, options, &brute);
    options.method = SearchMethod::kPruned;
    expectSameMatches(searchOrDie(index, candidates, options, &pruned), expected,
                      "query " + std::to_string(q));
    // One thread gives what many do: on every tenth query (the pruned scan alone is most of this
    // test's time at scale).
    if (q % 10 == 0) {
      options.parallel = false;
      expectSameMatches(searchOrDie(index, candidates, options), expected,
                        "query " + std::to_string(q) + ", one thread");
    }
    if (::testing::Test::HasFailure()) break;
  }
  std::cout << "  " << toString(kind) << ": pruned search computed " << pruned.distanceEvaluations
            << " distances, " << pruned.boundEvaluations << " entry bounds, " << pruned.groupBoundEvaluations
            << " group bounds; brute force " << brute.distanceEvaluations << " distances\n";
  EXPECT_LT(pruned.distanceEvaluations, brute.distanceEvaluations / 4);
}

class IndexAtScale : public ::testing::TestWithParam<DescriptorKind> {};
class IndexSmall : public ::testing::TestWithParam<DescriptorKind> {};

// The must-show: 10,000 random queries against 20,000 entries (release builds; the sanitizer preset
// runs IndexSmall). The centroid-voxel descriptor takes 1,000: its brute force and weakly pruned scans
// made it the longest test of the suite by far (43 s at 3,000 queries, the longest of CI's release
// stage), and its randomized agreement is also checked by IndexSmall and the live-index tests.
TEST_P(IndexAtScale, PrunedEqualsBruteForce) {
  expectPrunedEqualsBruteForce(GetParam(), 20000,
                               GetParam() == DescriptorKind::kCentroidVoxel ? 1000 : 10000);
}
TEST_P(IndexSmall, PrunedEqualsBruteForce) {
  expectPrunedEqualsBruteForce(GetParam(), 2000, 300);
}

// A search among some entries of an index answers as brute force over an index of those entries alone,
// whatever the method asked; an unsorted list is refused.
TEST_P(IndexSmall, SearchAmongSomeEntriesEqualsAnIndexOfThoseAlone) {
  const DescriptorKind kind = GetParam();
  const std::vector<Descriptor> bases = baseDescriptors(kind, 40, 7);
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> flips(0, 10), pickK(1, 6);
  const std::vector<Descriptor> entries = jitteredEntries(
      bases, 600, rng, [&] { return flips(rng); }, 0.15);
  const Index index = buildIndex(kind, entries);
  for (int trial = 0; trial < 20; ++trial) {
    // A random subset, by buildIndex's ids, and one id the index does not hold (ignored).
    std::vector<EntryId> among;
    IndexBuilder builder(test::descriptorOptions(kind));
    const double share = trial % 2 == 0 ? 0.05 : 0.5;
    for (std::size_t i = 0; i < entries.size(); ++i)
      if (std::bernoulli_distribution(share)(rng)) {
        among.push_back(static_cast<EntryId>(1000 + 7 * i));
        ASSERT_TRUE(builder.add(among.back(), entries[i]).ok());
      }
    among.push_back(1);
    std::sort(among.begin(), among.end());
    Result<Index> alone = std::move(builder).build();
    ASSERT_TRUE(alone.ok());

    const std::vector<Descriptor> candidates = queryCandidates(bases, rng);
    SearchOptions options;
    options.k = pickK(rng);
    options.momentWeight = trial % 3 == 0 ? 0.0 : 1.0;
    options.method = SearchMethod::kBruteForce;
    const std::vector<Match> expected = searchOrDie(*alone, candidates, options);
    options.among = among;
    for (SearchMethod method : {SearchMethod::kBruteForce, SearchMethod::kPruned, SearchMethod::kBuckets}) {
      options.method = method;
      expectSameMatches(
          searchOrDie(index, candidates, options), expected,
          "trial " + std::to_string(trial) + ", method " + std::to_string(static_cast<int>(method)));
    }
  }
  std::vector<EntryId> unsorted = {1007, 1000};
  SearchOptions options;
  options.among = unsorted;
  EXPECT_FALSE(index.search(entries.front(), options).ok());
  std::vector<EntryId> repeated = {1000, 1000};
  options.among = repeated;
  EXPECT_FALSE(index.search(entries.front(), options).ok());
}

const auto kKinds =
    ::testing::Values(DescriptorKind::kMoment, DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel);
std::string kindName(const ::testing::TestParamInfo<DescriptorKind>& param) {
  return param.param == DescriptorKind::kMoment  ? "Moment"
         : param.param == DescriptorKind::kVoxel ? "Voxel"
                                                 : "CentroidVoxel";
}
INSTANTIATE_TEST_SUITE_P(Descriptors, IndexSmall, kKinds, kindName);
INSTANTIATE_TEST_SUITE_P(Descriptors, IndexAtScale, kKinds, kindName);

TEST(Index, BruteForceGivesTheSameAnswerOnOneAndManyThreads) {
  const std::vector<Descriptor> bases = baseDescriptors(DescriptorKind::kCentroidVoxel, 20, 3);
  std::mt19937_64 rng(4);
  const std::vector<Descriptor> entries = jitteredEntries(
      bases, 5000, rng, [] { return 3; }, 0.1);
  const Index index = buildIndex(DescriptorKind::kCentroidVoxel, entries);
  for (int q = 0; q < 20; ++q) {
    const Descriptor query = test::jitterDescriptor(bases[static_cast<std::size_t>(q)], rng, 4, 0.1);
    SearchOptions options;
    options.k = 8;
    options.method = SearchMethod::kBruteForce;
    options.parallel = false;
    const std::vector<Match> serial = searchOrDie(index, std::span(&query, 1), options);
    options.parallel = true;
    expectSameMatches(searchOrDie(index, std::span(&query, 1), options), serial,
                      "query " + std::to_string(q));
  }
}

TEST(Index, QuantizedDistanceStaysWithinACentroidStepOfTheExactOne) {
  const std::vector<Descriptor> entries = baseDescriptors(DescriptorKind::kCentroidVoxel, 60, 8);
  const Index index = buildIndex(DescriptorKind::kCentroidVoxel, entries);
  SearchOptions all;
  all.k = static_cast<int>(entries.size());
  all.method = SearchMethod::kBruteForce;
  for (std::size_t q = 0; q < 10; ++q) {
    const std::vector<Match> matches = searchOrDie(index, std::span(&entries[q], 1), all);
    ASSERT_EQ(matches.size(), entries.size());
    for (const Match& m : matches) {
      const Descriptor& entry = entries[(m.entry - 1000) / 7];
      const double exact = centroidVoxelDistance(entries[q], entry);
      // Each quantized coordinate moves by ≤ 1/62 cell, so each centroid term by ≤ 2 · (√3/62) / √3.
      EXPECT_NEAR(m.distance - m.momentTerm, exact, 1.0 / 31.0 + 1e-6);
      // The moment term, w = 1: Σ |ln mᵢ − ln m'ᵢ|.
      const double moments = (entries[q].moments.array().log() - entry.moments.array().log()).abs().sum();
      EXPECT_NEAR(m.momentTerm, moments, 1e-12 * (1.0 + moments));
    }
    EXPECT_EQ(matches.front().entry, 1000 + 7 * q);
    EXPECT_LT(matches.front().distance, 1.0 / 64.0);
  }
}

// Centroid coordinates that shapes make exact (0.5 for a wall crossing its cell, 0 and 1 for a face on a
// cell plane) must not sit on the edge between two levels, where round-off of either sign decides.
TEST(Index, CentroidsAtTheMiddleAndEdgesOfACellQuantizeTheSameWhateverTheRoundOff) {
  for (double exact : {0.0, 0.5, 1.0})
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 below = Vec3::Constant(0.3), above = below;
      below[axis] = std::clamp(exact - 1e-14, 0.0, 1.0);
      above[axis] = std::clamp(exact + 1e-14, 0.0, 1.0);
      EXPECT_EQ(quantizeCentroid(below), quantizeCentroid(above)) << exact << " on axis " << axis;
      // Reversing the axis maps the coordinate to 1 − itself, and its level to the mirror level.
      Vec3 mirrored = below;
      mirrored[axis] = 1.0 - below[axis];
      const int level = quantizeCentroid(below) >> (5 * axis) & 31;
      EXPECT_EQ(quantizeCentroid(mirrored) >> (5 * axis) & 31, 30 - level) << exact << " on axis " << axis;
    }
}

TEST(Index, TiesBreakByEntryId) {
  const std::vector<Descriptor> bases = baseDescriptors(DescriptorKind::kVoxel, 1, 12);
  IndexBuilder builder(test::descriptorOptions(DescriptorKind::kVoxel));
  for (EntryId id : {50u, 7u, 31u, 2u, 19u})
    ASSERT_TRUE(builder.add(id, bases[0]).ok());
  Result<Index> index = std::move(builder).build();
  ASSERT_TRUE(index.ok());
  for (SearchMethod method : {SearchMethod::kBruteForce, SearchMethod::kPruned, SearchMethod::kBuckets}) {
    SearchOptions options;
    options.k = 3;
    options.method = method;
    const std::vector<Match> m = searchOrDie(*index, std::span(&bases[0], 1), options);
    ASSERT_EQ(m.size(), 3u);
    EXPECT_EQ(m[0].entry, 2u);
    EXPECT_EQ(m[1].entry, 7u);
    EXPECT_EQ(m[2].entry, 19u);
  }
}

// Many entries alike, with ids in no order, fill buckets with several groups of identical bounds: the
// k best, ties broken by id, are still brute force's, on one thread and on many.
TEST(Index, TiesAcrossGroupsBreakByEntryId) {
  const std::vector<Descriptor> bases = baseDescriptors(DescriptorKind::kCentroidVoxel, 3, 13);
  std::mt19937_64 rng(14);
  std::vector<EntryId> ids(300);
  std::iota(ids.begin(), ids.end(), EntryId{1});
  std::shuffle(ids.begin(), ids.end(), rng);
  IndexBuilder builder(test::descriptorOptions(DescriptorKind::kCentroidVoxel));
  for (std::size_t i = 0; i < ids.size(); ++i)
    ASSERT_TRUE(
        builder.add(ids[i], i % 3 == 0 ? test::jitterDescriptor(bases[i % 3], rng, 1, 0.0) : bases[i % 3])
            .ok());
  Result<Index> index = std::move(builder).build();
  ASSERT_TRUE(index.ok());
  for (const Descriptor& query : bases)
    for (int k : {1, 17, 40}) {
      SearchOptions options;
      options.k = k;
      options.method = SearchMethod::kBruteForce;
      const std::vector<Match> expected = searchOrDie(*index, std::span(&query, 1), options);
      options.method = SearchMethod::kPruned;
      for (bool parallel : {true, false}) {
        options.parallel = parallel;
        expectSameMatches(searchOrDie(*index, std::span(&query, 1), options), expected,
                          "k " + std::to_string(k) + (parallel ? "" : ", one thread"));
      }
    }
}

TEST(Index, PaperBucketsMissWhatTheExactSearchFinds) {
  const std::vector<Descriptor> bases = baseDescriptors(DescriptorKind::kCentroidVoxel, 100, 21);
  std::mt19937_64 rng(22);
  const std::vector<Descriptor> entries = jitteredEntries(
      bases, 3000, rng, [] { return 6; }, 0.15);
  const Index index = buildIndex(DescriptorKind::kCentroidVoxel, entries);
  std::map<int, int> misses;
  const int queries = 300;
  for (int q = 0; q < queries; ++q) {
    const Descriptor query = test::jitterDescriptor(bases[static_cast<std::size_t>(q % 100)], rng, 20, 0.2);
    SearchOptions options;
    const EntryId exact = searchOrDie(index, std::span(&query, 1), options).front().entry;
    options.method = SearchMethod::kBuckets;
    for (int r : {0, 2, 6, 1000}) {
      options.bucketRadius = r;
      const std::vector<Match> m = searchOrDie(index, std::span(&query, 1), options);
      if (m.empty() || m.front().entry != exact) ++misses[r];
    }
  }
  for (int r : {0, 2, 6})
    std::cout << "  buckets ±" << r << ": top-1 missed on " << misses[r] << " of " << queries << " queries\n";
  EXPECT_EQ(misses[1000], 0);  // a radius covering every count is a full scan
  EXPECT_GT(misses[0], 0);
  EXPECT_GE(misses[0], misses[2]);
  EXPECT_GE(misses[2], misses[6]);
}

TEST(Index, RejectsMismatchedQueriesAndDuplicateIds) {
  const std::vector<Descriptor> bases = baseDescriptors(DescriptorKind::kVoxel, 2, 30);
  const Index index = buildIndex(DescriptorKind::kVoxel, bases);
  Descriptor other = bases[0];
  other.kind = DescriptorKind::kCentroidVoxel;
  EXPECT_EQ(index.search(other).error().code, ErrorCode::kInvalidArgument);
  other = bases[0];
  other.gridSize = 12;
  EXPECT_EQ(index.search(other).error().code, ErrorCode::kInvalidArgument);
  other = bases[0];
  other.sampling = Sampling::kVertices;
  EXPECT_EQ(index.search(other).error().code, ErrorCode::kInvalidArgument);
  SearchOptions zero;
  zero.k = 0;
  EXPECT_EQ(index.search(bases[0], zero).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(index.search(std::span<const Descriptor>()).error().code, ErrorCode::kInvalidArgument);

  // Malformed descriptors (as a corrupted file could hold) are refused, not indexed out of bounds.
  IndexBuilder strict(test::descriptorOptions(DescriptorKind::kVoxel));
  Descriptor bad = bases[0];
  bad.cells.push_back(1000);
  EXPECT_NE(strict.add(1, bad).error().message.find("outside the grid"), std::string::npos);
  EXPECT_NE(index.search(bad).error().message.find("outside the grid"), std::string::npos);
  bad = bases[0];
  std::swap(bad.cells[0], bad.cells[1]);
  EXPECT_NE(strict.add(1, bad).error().message.find("ascending"), std::string::npos);
  bad = bases[0];
  bad.kind = DescriptorKind::kCentroidVoxel;
  bad.centroids.pop_back();
  IndexBuilder centroidBuilder(test::descriptorOptions(DescriptorKind::kCentroidVoxel));
  EXPECT_NE(centroidBuilder.add(1, bad).error().message.find("centroids for"), std::string::npos);
  bad.centroids.push_back(Vec3(0.5, 1.5, 0.5));
  EXPECT_NE(centroidBuilder.add(1, bad).error().message.find("outside its cell"), std::string::npos);
  bad = bases[0];
  bad.moments[1] = std::nan("");
  EXPECT_NE(strict.add(1, bad).error().message.find("not finite"), std::string::npos);
  // A builder for a grid no descriptor may have (its tables would be out of range) takes no entry.
  DescriptorOptions huge = test::descriptorOptions(DescriptorKind::kVoxel);
  huge.gridSize = kMaxGridSize + 1;
  IndexBuilder tooLarge(huge);
  bad = bases[0];
  bad.gridSize = huge.gridSize;
  EXPECT_NE(tooLarge.add(1, bad).error().message.find("outside [2, 64]"), std::string::npos);

  IndexBuilder builder(test::descriptorOptions(DescriptorKind::kVoxel));
  ASSERT_TRUE(builder.add(4, bases[0]).ok());
  ASSERT_TRUE(builder.add(4, bases[1]).ok());
  Result<Index> dup = std::move(builder).build();
  ASSERT_FALSE(dup.ok());
  EXPECT_NE(dup.error().message.find("entry 4 added twice"), std::string::npos);
}

TEST(Index, EmptyIndexFindsNothingAndSmallIndexReturnsEverything) {
  const std::vector<Descriptor> bases = baseDescriptors(DescriptorKind::kMoment, 3, 31);
  for (DescriptorKind kind : {DescriptorKind::kMoment, DescriptorKind::kVoxel}) {
    const Index empty(test::descriptorOptions(kind));
    Descriptor q = bases[0];
    q.kind = kind;
    if (kind == DescriptorKind::kVoxel) q.gridSize = 10;
    Result<std::vector<Match>> none = empty.search(q);
    ASSERT_TRUE(none.ok());
    EXPECT_TRUE(none->empty());
  }
  const Index index = buildIndex(DescriptorKind::kMoment, bases);
  SearchOptions options;
  options.k = 10;
  EXPECT_EQ(searchOrDie(index, std::span(&bases[1], 1), options).size(), 3u);
}

}  // namespace
}  // namespace shapedb::core
