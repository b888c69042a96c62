#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <functional>

namespace shapedb::core {

/// A fixed split of n items into consecutive chunks for a parallel sum that does not depend on the
/// threads: the chunks depend on n alone (one per kSize items, at most kMaxChunks, at least one), each
/// chunk is summed in item order, and the chunks' sums are added in chunk order. So a large mesh's
/// integrals or descriptor are the same to the bit on one thread as on many (and a mesh under
/// 2 × kSize items is summed exactly as a plain loop would).
struct Chunks {
  static constexpr std::size_t kSize = 2048, kMaxChunks = 8;
  std::size_t items = 0;
  std::size_t count = 1;  ///< 1 to kMaxChunks

  explicit Chunks(std::size_t n) : items(n), count(std::clamp<std::size_t>(n / kSize, 1, kMaxChunks)) {}
  std::size_t begin(std::size_t chunk) const { return chunk * (items / count); }
  std::size_t end(std::size_t chunk) const {
    return chunk + 1 == count ? items : (chunk + 1) * (items / count);
  }

  /// Runs f(chunk, begin, end) for every chunk, in parallel (TBB) when there are several.
  void run(const std::function<void(std::size_t, std::size_t, std::size_t)>& f) const;

  /// The sum over the chunks of partial(begin, end), each computed as run() does and added in chunk
  /// order. T: copyable, with +=.
  template <typename T, typename F>
  T sum(F&& partial) const {
    std::array<T, kMaxChunks> parts{};
    run([&](std::size_t c, std::size_t first, std::size_t last) { parts[c] = partial(first, last); });
    T total = parts[0];
    for (std::size_t c = 1; c < count; ++c)
      total += parts[c];
    return total;
  }
};

}  // namespace shapedb::core
