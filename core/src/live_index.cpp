#include <algorithm>
#include <tuple>

#include <shapedb/core/live_index.h>

namespace shapedb::core {

LiveIndex::LiveIndex(Index base)
    : mBase(std::move(base)),
      mAdded(mBase.options()),
      mSegment(std::make_shared<const Index>(mBase.options())) {}

Status LiveIndex::add(std::span<const std::pair<EntryId, Descriptor>> entries) {
  std::lock_guard lock(mAddMutex);
  IndexBuilder next = mAdded;  // kept unchanged if anything fails
  for (const auto& [id, descriptor] : entries)
    if (Status st = next.add(id, descriptor); !st) return st;
  auto segment = IndexBuilder(next).build();
  if (!segment) return segment.error();
  mAdded = std::move(next);
  auto published = std::make_shared<const Index>(std::move(segment).value());
  std::lock_guard publish(mPublishMutex);
  mSegment = std::move(published);
  return Ok{};
}

std::shared_ptr<const Index> LiveIndex::published() const {
  std::lock_guard lock(mPublishMutex);
  return mSegment;
}

std::size_t LiveIndex::size() const {
  return mBase.size() + published()->size();
}

Result<std::vector<Match>> LiveIndex::search(std::span<const Descriptor> candidates,
                                             const SearchOptions& options, SearchStats* stats) const {
  auto matches = mBase.search(candidates, options, stats);
  if (!matches) return matches;
  const std::shared_ptr<const Index> segment = published();
  if (segment->size() == 0) return matches;
  auto added = segment->search(candidates, options, stats);
  if (!added) return added;
  // Both lists are each part's k best; the whole's k best are among them. Same order as Index: distance,
  // then entry id.
  matches->insert(matches->end(), added->begin(), added->end());
  std::sort(matches->begin(), matches->end(), [](const Match& a, const Match& b) {
    return std::tie(a.distance, a.entry) < std::tie(b.distance, b.entry);
  });
  if (matches->size() > static_cast<std::size_t>(options.k))
    matches->resize(static_cast<std::size_t>(options.k));
  return matches;
}

}  // namespace shapedb::core
