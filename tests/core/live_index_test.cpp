// LiveIndex against its oracle: one Index, searched by brute force, of the base and every entry
// published. Core only and random descriptors (no meshes), so that it builds fast enough to run under
// ThreadSanitizer too.
#include <algorithm>
#include <atomic>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/live_index.h>

namespace shapedb::core {
namespace {

constexpr int kGrid = 10;

DescriptorOptions liveOptions(DescriptorKind kind) {
  DescriptorOptions o;
  o.kind = kind;
  o.gridSize = kGrid;
  return o;
}

// A random descriptor: a box of cells with some of them dropped, random centroids, random moments. Few
// distinct boxes, so that distances tie now and then and the tie-break by id is exercised too.
Descriptor randomLiveDescriptor(DescriptorKind kind, std::mt19937_64& rng) {
  Descriptor d;
  d.kind = kind;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  d.moments = Vec3(0.05 + unit(rng), 0.05 + unit(rng), 0.05 + unit(rng));
  std::sort(d.moments.data(), d.moments.data() + 3);
  if (kind == DescriptorKind::kMoment) return d;
  d.gridSize = kGrid;
  d.cellSize = 1.0 / kGrid;
  std::uniform_int_distribution<int> corner(0, 4), extent(2, 5);
  const int x0 = corner(rng), y0 = corner(rng), z0 = corner(rng);
  const int nx = extent(rng), ny = extent(rng), nz = extent(rng);
  for (int k = z0; k < z0 + nz; ++k)
    for (int j = y0; j < y0 + ny; ++j)
      for (int i = x0; i < x0 + nx; ++i)
        if (unit(rng) < 0.9) d.cells.push_back(linearCell(i, j, k, kGrid));
  if (d.cells.empty()) d.cells.push_back(linearCell(x0, y0, z0, kGrid));
  for (std::size_t c = 0; c < d.cells.size(); ++c) {
    d.centroids.emplace_back(unit(rng), unit(rng), unit(rng));
    d.weights.push_back(1.0);
  }
  return d;
}

using Entries = std::vector<std::pair<EntryId, Descriptor>>;

Index indexOf(DescriptorKind kind, const Entries& entries) {
  IndexBuilder builder(liveOptions(kind));
  for (const auto& [id, d] : entries)
    EXPECT_TRUE(builder.add(id, d).ok());
  auto index = std::move(builder).build();
  EXPECT_TRUE(index.ok());
  return std::move(index).value();
}

std::vector<Match> searchLive(const LiveIndex& index, const std::vector<Descriptor>& candidates,
                              const SearchOptions& options) {
  auto r = index.search(candidates, options);
  EXPECT_TRUE(r.ok()) << (r ? "" : r.error().message);
  return r ? std::move(r).value() : std::vector<Match>{};
}

bool sameMatches(const std::vector<Match>& a, const std::vector<Match>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].entry != b[i].entry || a[i].distance != b[i].distance || a[i].candidate != b[i].candidate)
      return false;
  return true;
}

std::string describeMatches(const std::vector<Match>& matches) {
  std::string s;
  for (const Match& m : matches)
    s += std::to_string(m.entry) + "@" + std::to_string(m.distance) + " ";
  return s;
}

// A base of 150 entries and batches of 1-4 entries added one after the other; ids interleave with the
// base's, so the merge has to order them.
struct LiveFixture {
  DescriptorKind kind;
  Entries base;
  std::vector<Entries> batches;
  LiveFixture(DescriptorKind k, int batchCount, std::uint64_t seed) : kind(k) {
    std::mt19937_64 rng(seed);
    for (EntryId id = 0; id < 150; ++id)
      base.emplace_back(2 * id, randomLiveDescriptor(kind, rng));
    std::uniform_int_distribution<int> size(1, 4);
    EntryId next = 1;
    for (int b = 0; b < batchCount; ++b) {
      Entries batch;
      for (int i = size(rng); i > 0; --i, next += 2)
        batch.emplace_back(next, randomLiveDescriptor(kind, rng));
      batches.push_back(std::move(batch));
    }
  }
  // Everything published after the first `count` batches, searched by brute force: the oracle.
  Index oracle(std::size_t count) const {
    Entries all = base;
    for (std::size_t b = 0; b < count; ++b)
      all.insert(all.end(), batches[b].begin(), batches[b].end());
    return indexOf(kind, all);
  }
};

class LiveIndexKinds : public ::testing::TestWithParam<DescriptorKind> {};

TEST_P(LiveIndexKinds, AnswersAsOneIndexOfTheBaseAndEveryEntryAdded) {
  const LiveFixture f(GetParam(), 25, 7);
  LiveIndex live(indexOf(f.kind, f.base));
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> pickK(1, 8), pickCandidates(1, 3);
  for (std::size_t b = 0; b <= f.batches.size(); ++b) {
    if (b > 0) {
      ASSERT_TRUE(live.add(f.batches[b - 1]).ok());
    }
    const Index oracle = f.oracle(b);
    ASSERT_EQ(live.size(), oracle.size());
    for (int q = 0; q < 8; ++q) {
      std::vector<Descriptor> candidates;
      for (int c = pickCandidates(rng); c > 0; --c)
        candidates.push_back(randomLiveDescriptor(f.kind, rng));
      SearchOptions options;
      options.k = pickK(rng);
      options.momentWeight = q % 2 == 0 ? 1.0 : 0.0;
      options.method = SearchMethod::kBruteForce;
      auto expected = oracle.search(candidates, options);
      ASSERT_TRUE(expected.ok());
      for (SearchMethod method : {SearchMethod::kBruteForce, SearchMethod::kPruned}) {
        options.method = method;
        const std::vector<Match> got = searchLive(live, candidates, options);
        EXPECT_TRUE(sameMatches(got, *expected))
            << "after " << b << " batches, " << toString(method) << ": " << describeMatches(got)
            << " expected " << describeMatches(*expected);
      }
    }
  }
}

TEST_P(LiveIndexKinds, AFailedAddPublishesNothing) {
  const LiveFixture f(GetParam(), 2, 8);
  LiveIndex live(indexOf(f.kind, f.base));
  ASSERT_TRUE(live.add(f.batches[0]).ok());
  const std::size_t before = live.size();

  Entries bad = f.batches[1];
  Descriptor wrongKind = bad.front().second;
  wrongKind.kind = f.kind == DescriptorKind::kMoment ? DescriptorKind::kVoxel : DescriptorKind::kMoment;
  bad.emplace_back(9999, wrongKind);
  const Status refused = live.add(bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("9999"), std::string::npos) << refused.error().message;
  EXPECT_EQ(live.size(), before);

  const Status twice = live.add(f.batches[0]);  // the same ids again
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().message.find("added twice"), std::string::npos) << twice.error().message;
  EXPECT_EQ(live.size(), before);
  EXPECT_TRUE(live.add(f.batches[1]).ok());  // and the index still takes good entries
}

// The must-show of learning: searches running while entries are added return, every one of them,
// exactly what brute force returns over the entries published at some moment during that search (a
// search sees a publication whole or not at all). Run by the tsan preset too.
TEST_P(LiveIndexKinds, SearchesBesideAddsSeeEachPublicationWholeOrNotAtAll) {
  constexpr int kBatches = 40, kQueries = 12;
  const LiveFixture f(GetParam(), kBatches, 9);
  std::mt19937_64 rng(13);
  std::vector<std::vector<Descriptor>> queries(kQueries);
  for (auto& q : queries)
    q.push_back(randomLiveDescriptor(f.kind, rng));
  SearchOptions options;
  options.k = 3;
  // Every answer a search may give: per number of batches published, per query.
  std::vector<std::size_t> sizes;
  std::vector<std::vector<std::vector<Match>>> expected;
  for (std::size_t b = 0; b <= kBatches; ++b) {
    const Index oracle = f.oracle(b);
    sizes.push_back(oracle.size());
    auto& level = expected.emplace_back();
    SearchOptions brute = options;
    brute.method = SearchMethod::kBruteForce;
    for (const auto& q : queries)
      level.push_back(oracle.search(q, brute).value());
  }

  LiveIndex live(indexOf(f.kind, f.base));
  std::atomic<bool> adding{true};
  std::atomic<int> searches{0}, wrong{0};
  const auto searcher = [&](int seed) {
    std::mt19937_64 local(static_cast<std::uint64_t>(seed));
    std::uniform_int_distribution<int> pick(0, kQueries - 1);
    SearchOptions o = options;
    o.parallel = false;
    while (adding.load() || searches.load() < 200) {
      const int q = pick(local);
      const std::size_t before = live.size();
      auto got = live.search(queries[static_cast<std::size_t>(q)], o);
      const std::size_t after = live.size();
      ++searches;
      bool seen = false;
      for (std::size_t b = 0; b < sizes.size() && got; ++b)
        if (sizes[b] >= before && sizes[b] <= after &&
            sameMatches(*got, expected[b][static_cast<std::size_t>(q)]))
          seen = true;
      if (!seen) ++wrong;
    }
  };
  std::thread a(searcher, 1), b(searcher, 2);
  for (const Entries& batch : f.batches) {
    EXPECT_TRUE(live.add(batch).ok());
    std::this_thread::yield();
  }
  adding = false;
  a.join();
  b.join();
  EXPECT_EQ(wrong.load(), 0) << "of " << searches.load() << " searches";
  EXPECT_EQ(live.size(), sizes.back());
}

INSTANTIATE_TEST_SUITE_P(Descriptors, LiveIndexKinds,
                         ::testing::Values(DescriptorKind::kMoment, DescriptorKind::kVoxel,
                                           DescriptorKind::kCentroidVoxel),
                         [](const ::testing::TestParamInfo<DescriptorKind>& p) {
                           return p.param == DescriptorKind::kMoment  ? std::string("Moment")
                                  : p.param == DescriptorKind::kVoxel ? std::string("Voxel")
                                                                      : std::string("CentroidVoxel");
                         });

}  // namespace
}  // namespace shapedb::core
