#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <shapedb/core/disjoint_sets.h>
#include <shapedb/core/topology.h>

namespace shapedb::core {
namespace {

bool hasRepeatedVertex(const TriangleMesh::Triangle& t) {
  return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

/// Whether the corner of `t` across its longest edge lies within relativeHeight × that edge's length of
/// its line (twice the area is the longest edge times that height).
bool isThin(const TriangleMesh& mesh, const TriangleMesh::Triangle& t, double relativeHeight) {
  const Vec3& a = mesh.vertices[t[0]];
  const Vec3& b = mesh.vertices[t[1]];
  const Vec3& c = mesh.vertices[t[2]];
  const double longestSq = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return (b - a).cross(c - a).norm() <= relativeHeight * longestSq;
}

constexpr double kZeroAreaHeight = 1e-12;

// Zero area relative to the triangle's own size: twice the area below 1e-12 of its longest edge squared.
bool hasZeroArea(const TriangleMesh& mesh, const TriangleMesh::Triangle& t) {
  return isThin(mesh, t, kZeroAreaHeight);
}

std::string plural(std::size_t n, const std::string& noun, const std::string& nouns = "") {
  return std::to_string(n) + " " + (n == 1 ? noun : nouns.empty() ? noun + "s" : nouns);
}

// One edge shared by `count` half-edges; `sameDirection`: it has two and they run the same way.
void countEdge(std::size_t count, bool sameDirection, TopologyReport& report) {
  ++report.edgeCount;
  if (count == 1) ++report.boundaryEdges;
  if (count > 2) ++report.nonManifoldEdges;
  if (count == 2 && sameDirection) ++report.inconsistentEdges;
}

// Referenced and unreferenced vertices, and components: the distinct roots among referenced vertices.
void countVertices(const std::vector<char>& referenced, DisjointSets& sets, TopologyReport& report) {
  std::vector<char> isRoot(referenced.size(), 0);
  for (std::uint32_t v = 0; v < referenced.size(); ++v) {
    if (!referenced[v]) {
      ++report.unreferencedVertices;
      continue;
    }
    ++report.vertexCount;
    const std::uint32_t root = sets.find(v);
    if (!isRoot[root]) ++report.components;
    isRoot[root] = 1;
  }
}

}  // namespace

TopologyReport analyzeTopology(const TriangleMesh& mesh) {
  TopologyReport report;
  report.triangleCount = mesh.triangles.size();
  const std::size_t vertexCount = mesh.vertices.size();

  // Bucket the half-edges by their lower vertex (a counting sort, O(F + V)): bucket v holds, for each
  // half-edge {v, w} with v < w, the entry 2w + (direction v → w). An edge's half-edges then share a
  // bucket and, once the bucket is sorted, sit next to each other. Buckets are small (about three
  // edges per vertex on a triangle mesh), so sorting them costs little whatever the vertex order.
  std::vector<std::size_t> bucketStart(vertexCount + 1, 0);
  std::vector<char> referenced(vertexCount, 0);
  for (const auto& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = t[i], b = t[(i + 1) % 3];
      referenced[a] = 1;
      if (a != b) ++bucketStart[std::min(a, b) + 1];
    }
  }
  for (std::size_t v = 0; v < vertexCount; ++v)
    bucketStart[v + 1] += bucketStart[v];
  std::vector<std::uint64_t> entries(bucketStart[vertexCount]);
  {
    std::vector<std::size_t> cursor(bucketStart.begin(), bucketStart.end() - 1);
    for (const auto& t : mesh.triangles) {
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t a = t[i], b = t[(i + 1) % 3];
        if (a == b) continue;
        entries[cursor[std::min(a, b)]++] = (std::uint64_t{std::max(a, b)} << 1) | (a < b ? 1u : 0u);
      }
    }
  }

  // Classify each edge by how many half-edges share it, and in which directions.
  DisjointSets sets(vertexCount);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const auto first = entries.begin() + static_cast<std::ptrdiff_t>(bucketStart[v]);
    const auto last = entries.begin() + static_cast<std::ptrdiff_t>(bucketStart[v + 1]);
    std::sort(first, last);
    for (auto begin = first; begin != last;) {
      const std::uint64_t upper = *begin >> 1;
      auto end = begin + 1;
      while (end != last && (*end >> 1) == upper)
        ++end;
      const auto count = static_cast<std::size_t>(end - begin);
      countEdge(count, count == 2 && begin[0] == begin[1], report);
      sets.unite(static_cast<std::uint32_t>(v), static_cast<std::uint32_t>(upper));
      begin = end;
    }
  }

  countVertices(referenced, sets, report);
  return report;
}

TopologyReport analyzeTopologyBySorting(const TriangleMesh& mesh) {
  TopologyReport report;
  report.triangleCount = mesh.triangles.size();

  // Each half-edge as (undirected key, direction); sorting groups the half-edges of an edge together.
  struct HalfEdge {
    std::uint64_t key;
    bool forward;
  };
  std::vector<HalfEdge> halfEdges;
  halfEdges.reserve(3 * mesh.triangles.size());
  DisjointSets sets(mesh.vertices.size());
  std::vector<char> referenced(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = t[i], b = t[(i + 1) % 3];
      referenced[a] = 1;
      if (a == b) continue;
      halfEdges.push_back({(std::uint64_t{std::min(a, b)} << 32) | std::max(a, b), a < b});
      sets.unite(a, b);
    }
  }
  std::sort(halfEdges.begin(), halfEdges.end(),
            [](const HalfEdge& l, const HalfEdge& r) { return l.key < r.key; });

  // Classify each edge by how many half-edges share it, and in which directions.
  for (std::size_t begin = 0; begin < halfEdges.size();) {
    std::size_t end = begin + 1;
    while (end < halfEdges.size() && halfEdges[end].key == halfEdges[begin].key)
      ++end;
    const std::size_t count = end - begin;
    countEdge(count, count == 2 && halfEdges[begin].forward == halfEdges[begin + 1].forward, report);
    begin = end;
  }

  countVertices(referenced, sets, report);
  return report;
}

Status requireClosedOriented(const TopologyReport& topology) {
  if (topology.boundaryEdges > 0)
    return Error{ErrorCode::kNotClosed,
                 "mesh is not closed (" + plural(topology.boundaryEdges, "boundary edge") + ")"};
  if (topology.nonManifoldEdges > 0)
    return Error{ErrorCode::kNonManifold,
                 "mesh is not manifold (" + plural(topology.nonManifoldEdges, "edge") + " with 3+ faces)"};
  if (topology.inconsistentEdges > 0)
    return Error{ErrorCode::kInconsistentOrientation, "mesh is not consistently oriented (" +
                                                          plural(topology.inconsistentEdges, "edge") +
                                                          " traversed twice in the same direction)"};
  return Ok{};
}

std::size_t flipZeroAreaFaces(TriangleMesh& mesh) {
  return flipThinFaces(mesh, kZeroAreaHeight);
}

std::size_t flipThinFaces(TriangleMesh& mesh, double relativeHeight) {
  const auto thin = [&](const TriangleMesh::Triangle& t) { return isThin(mesh, t, relativeHeight); };
  const auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; };
  std::size_t flipped = 0;
  // A pass flips each thin face it can, touching each triangle once; the next pass sees the edges
  // the last one made (a second filler on the same edge flips against the first one's result).
  for (bool progress = true; progress;) {
    progress = false;
    std::unordered_map<std::uint64_t, std::uint32_t> triangleOf;  // directed edge → its triangle
    triangleOf.reserve(3 * mesh.triangles.size());
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        triangleOf.emplace(key(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]), t);
    std::vector<char> touched(mesh.triangles.size(), 0);
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      if (touched[t] || hasRepeatedVertex(mesh.triangles[t]) || !thin(mesh.triangles[t])) continue;
      // The middle corner is the one across the longest edge: the face is (a, b, m), wound a → b → m.
      const TriangleMesh::Triangle& f = mesh.triangles[t];
      int middle = 0;
      double longest = -1.0;
      for (int k = 0; k < 3; ++k) {
        const double length = (mesh.vertices[f[(k + 1) % 3]] - mesh.vertices[f[(k + 2) % 3]]).squaredNorm();
        if (length > longest) {
          longest = length;
          middle = k;
        }
      }
      if (!(longest > 0.0)) continue;  // coincident corners: the weld's to merge, not a flip's
      const std::uint32_t m = f[middle], a = f[(middle + 1) % 3], b = f[(middle + 2) % 3];
      const auto across = triangleOf.find(key(b, a));
      if (across == triangleOf.end() || across->second == t || touched[across->second]) continue;
      const std::uint32_t u = across->second;
      const TriangleMesh::Triangle& g = mesh.triangles[u];
      const std::uint32_t x = g[0] != a && g[0] != b ? g[0] : g[1] != a && g[1] != b ? g[1] : g[2];
      if (x == m || triangleOf.contains(key(m, x)) || triangleOf.contains(key(x, m))) continue;
      const TriangleMesh::Triangle first{m, a, x}, second{x, b, m};
      if (thin(first) || thin(second)) continue;
      mesh.triangles[t] = first;
      mesh.triangles[u] = second;
      // The map follows, so that a later flip of this pass sees the edge m–x made here.
      triangleOf.erase(key(a, b));
      triangleOf.erase(key(b, a));
      for (const auto& [from, to, in] :
           {std::tuple{m, a, t}, {a, x, t}, {x, m, t}, {x, b, u}, {b, m, u}, {m, x, u}})
        triangleOf[key(from, to)] = in;
      touched[t] = touched[u] = 1;
      ++flipped;
      progress = true;
    }
  }
  return flipped;
}

std::vector<Shell> findShells(const TriangleMesh& mesh) {
  DisjointSets sets(mesh.vertices.size());
  for (const auto& t : mesh.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  std::vector<Shell> shells;
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> shellOf(mesh.vertices.size(), kNone);  // by a set's representative
  std::vector<Vec3> origin;  // each shell's first vertex: its volume summed about a point of its own
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    std::uint32_t& shell = shellOf[sets.find(t[0])];
    if (shell == kNone) {
      shell = static_cast<std::uint32_t>(shells.size());
      shells.emplace_back();
      origin.push_back(mesh.vertices[t[0]]);
    }
    const Vec3& o = origin[shell];
    const Vec3 a = mesh.vertices[t[0]] - o, b = mesh.vertices[t[1]] - o, c = mesh.vertices[t[2]] - o;
    shells[shell].triangles.push_back(static_cast<std::uint32_t>(f));
    shells[shell].volume += a.dot(b.cross(c)) / 6.0;
  }
  double total = 0.0;
  for (const Shell& shell : shells)
    total += shell.volume;
  for (Shell& shell : shells)
    shell.cavity = (shell.volume > 0.0) != (total > 0.0);
  return shells;
}

ShellCount countShells(const std::vector<Shell>& shells) {
  ShellCount out;
  double solidVolume = 0.0, largest = 0.0;
  for (const Shell& shell : shells) {
    if (shell.cavity) {
      ++out.cavities;
      continue;
    }
    ++out.solids;
    solidVolume += std::abs(shell.volume);
    largest = std::max(largest, std::abs(shell.volume));
  }
  if (solidVolume > 0.0) out.largestSolidShare = largest / solidVolume;
  return out;
}

MeshDefects findDefects(const TriangleMesh& mesh) {
  MeshDefects d;
  d.vertexCount = mesh.vertices.size();
  d.triangleCount = mesh.triangles.size();
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (mesh.vertices[v].allFinite()) continue;
    if (d.nonFiniteVertices++ == 0) d.firstNonFiniteVertex = v;
  }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const auto outside =
        std::find_if(t.begin(), t.end(), [&](std::uint32_t i) { return i >= d.vertexCount; });
    if (outside != t.end()) {
      if (d.outOfRangeIndices++ == 0) {
        d.firstOutOfRangeFace = f;
        d.firstOutOfRangeIndex = *outside;
      }
      continue;
    }
    const bool repeated = hasRepeatedVertex(t);
    if (!repeated && !hasZeroArea(mesh, t)) continue;
    if (d.repeatedVertexFaces + d.zeroAreaFaces == 0) {
      d.firstDegenerateFace = f;
      d.firstDegenerateIsRepeated = repeated;
    }
    ++(repeated ? d.repeatedVertexFaces : d.zeroAreaFaces);
  }
  return d;
}

Status checkDefects(const MeshDefects& d, const ValidationOptions& options) {
  if (d.triangleCount == 0) return Error{ErrorCode::kEmptyMesh, "mesh has no faces"};
  if (d.nonFiniteVertices > 0)
    return Error{ErrorCode::kNonFinite,
                 "vertex " + std::to_string(d.firstNonFiniteVertex) + " has a non-finite coordinate"};
  if (d.outOfRangeIndices > 0)
    return Error{ErrorCode::kIndexOutOfRange,
                 "face " + std::to_string(d.firstOutOfRangeFace) + " refers to vertex " +
                     std::to_string(d.firstOutOfRangeIndex) + ", but the mesh has " +
                     plural(d.vertexCount, "vertex", "vertices")};
  const std::size_t degenerate = d.repeatedVertexFaces + d.zeroAreaFaces;
  if (degenerate > 0 && !options.allowDegenerateFaces)
    return Error{ErrorCode::kDegenerateFace,
                 plural(degenerate, "degenerate face") + " (first: face " +
                     std::to_string(d.firstDegenerateFace) + ", " +
                     (d.firstDegenerateIsRepeated ? "repeated vertex" : "zero area") + ")"};
  return Ok{};
}

Status validateMesh(const TriangleMesh& mesh, const ValidationOptions& options) {
  return checkDefects(findDefects(mesh), options);
}

std::size_t removeRepeatedVertexFaces(TriangleMesh& mesh) {
  const std::size_t before = mesh.triangles.size();
  std::erase_if(mesh.triangles, hasRepeatedVertex);
  return before - mesh.triangles.size();
}

}  // namespace shapedb::core
