#pragma once
// Which nodes share an element with which: the sparsity of every matrix the volume module assembles
// (the FEM's K and M, the morph's mesh-motion stiffness). Private to the volume module.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace shapedb::volume::detail {

/// Per node, the nodes that share an element with it, itself included, ascending (CSR: node v's are
/// nodes[start[v], start[v + 1])).
struct NodeNeighbours {
  std::vector<std::uint32_t> start;
  std::vector<std::uint32_t> nodes;
};

/// NodeNeighbours of `nodeCount` nodes and elements of N nodes each: each node's elements by counting,
/// the nodes of those marked once each, then sorted node by node (a node has a few dozen neighbours).
/// Sorting every node pair of every element at once instead cost a few percent of a correction's modes,
/// and 28 times as long for a morph's tets.
template <std::size_t N>
NodeNeighbours nodeNeighbours(std::size_t nodeCount,
                              const std::vector<std::array<std::uint32_t, N>>& elements) {
  std::vector<std::size_t> elementsAt(nodeCount + 1, 0);
  for (const auto& e : elements)
    for (std::uint32_t a : e)
      ++elementsAt[a + 1];
  for (std::size_t i = 0; i < nodeCount; ++i)
    elementsAt[i + 1] += elementsAt[i];
  std::vector<std::uint32_t> incident(elementsAt[nodeCount]);
  {
    std::vector<std::size_t> next(elementsAt.begin(), elementsAt.end() - 1);
    for (std::size_t i = 0; i < elements.size(); ++i)
      for (std::uint32_t a : elements[i])
        incident[next[a]++] = static_cast<std::uint32_t>(i);
  }
  constexpr std::uint32_t kUnmarked = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> markedBy(nodeCount, kUnmarked);
  NodeNeighbours out;
  out.start.assign(nodeCount + 1, 0);
  out.nodes.reserve(elementsAt[nodeCount] * N / 4);
  for (std::size_t b = 0; b < nodeCount; ++b) {
    const std::size_t first = out.nodes.size();
    for (std::size_t k = elementsAt[b]; k < elementsAt[b + 1]; ++k)
      for (std::uint32_t a : elements[incident[k]])
        if (markedBy[a] != b) {
          markedBy[a] = static_cast<std::uint32_t>(b);
          out.nodes.push_back(a);
        }
    std::sort(out.nodes.begin() + static_cast<std::ptrdiff_t>(first), out.nodes.end());
    out.start[b + 1] = static_cast<std::uint32_t>(out.nodes.size());
  }
  return out;
}

}  // namespace shapedb::volume::detail
