#pragma once
// An index that takes new entries while it is searched: a database's catalog, fixed when it is opened,
// and the entries learned since (io/enrich.h), each publication seen whole or not at all.

#include <cstddef>
#include <memory>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

#include <shapedb/core/index.h>

namespace shapedb::core {

/// A fixed base Index and a segment of entries added since, searched as one.
///
/// add() builds a new segment beside the published one (the entries added before and the new ones) and
/// then publishes it by swapping one pointer, so a search sees every entry of an add() or none of them,
/// and never waits for one: it copies the pointer under a lock held for that copy only, then searches
/// the segment it got. The answer is exactly what one Index of the base and the published entries would
/// give (best first, ties by entry id): each part is searched for its k best and the two lists merged.
///
/// Rebuilding the segment costs time and memory in proportion to the entries added: meant for entries
/// learned one by one (thousands), not for a second catalog.
///
/// Thread-safe: any number of searches beside one add() at a time (others wait their turn).
class LiveIndex {
 public:
  explicit LiveIndex(Index base);

  /// Adds entries, all published together. Errors (nothing is added): kInvalidArgument for a descriptor
  /// of another kind, sampling or grid size, or an id already added. Ids are not checked against the
  /// base's (an Index does not keep them): the caller's ids are unique, as a database's rows are.
  Status add(std::span<const std::pair<EntryId, Descriptor>> entries);

  /// As Index::search, over the base and the entries published when the search starts.
  Result<std::vector<Match>> search(std::span<const Descriptor> candidates, const SearchOptions& options = {},
                                    SearchStats* stats = nullptr) const;

  const DescriptorOptions& options() const { return mBase.options(); }
  const Index& base() const { return mBase; }
  /// Entries published so far: the base's and those added.
  std::size_t size() const;

 private:
  std::shared_ptr<const Index> published() const;

  const Index mBase;
  std::mutex mAddMutex;  ///< one add() at a time
  IndexBuilder mAdded;   ///< every entry added, compacted (under mAddMutex)
  mutable std::mutex mPublishMutex;
  std::shared_ptr<const Index> mSegment;  ///< the added entries' index (under mPublishMutex)
};

}  // namespace shapedb::core
