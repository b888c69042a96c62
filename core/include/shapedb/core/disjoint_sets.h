#pragma once
// Disjoint sets (union-find) over the elements 0 … n−1: which elements a series of joins connects, in
// nearly constant time a join. What counts a surface's components and a tet mesh's face-connected
// pieces, and groups a surface's boundary edges into loops.

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace shapedb::core {

class DisjointSets {
 public:
  /// n elements, each a set of its own.
  explicit DisjointSets(std::size_t n) : mParent(n), mSize(n, 1), mSets(n) {
    std::iota(mParent.begin(), mParent.end(), 0u);
  }

  /// The representative of x's set: the same for every element of one set (path halving on the way).
  std::uint32_t find(std::uint32_t x) {
    while (mParent[x] != x)
      x = mParent[x] = mParent[mParent[x]];
    return x;
  }

  /// Joins the sets of a and b (the smaller under the larger, so that paths stay short on meshes of
  /// millions of vertices); false if they were one already.
  bool unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (mSize[a] > mSize[b]) std::swap(a, b);
    mParent[a] = b;
    mSize[b] += mSize[a];
    --mSets;
    return true;
  }

  std::size_t size() const { return mParent.size(); }
  /// How many sets there are.
  std::size_t sets() const { return mSets; }

 private:
  std::vector<std::uint32_t> mParent;
  std::vector<std::uint32_t> mSize;  ///< elements under each representative
  std::size_t mSets;
};

}  // namespace shapedb::core
