#pragma once

// Polygons as a reader found them, before triangulation and validation: flat storage (one index array
// and one offset per polygon), so that a file of ten million faces costs two arrays, not ten million.

#include <cstdint>
#include <limits>
#include <vector>

#include <shapedb/core/triangle_mesh.h>

namespace shapedb::io::detail {

struct RawPolygons {
  static constexpr std::uint32_t kInvalidIndex = std::numeric_limits<std::uint32_t>::max();

  std::vector<core::Vec3> vertices;
  std::vector<std::uint32_t> corners;  ///< every polygon's vertex indices, one after another
  std::vector<std::size_t> ends{};     ///< polygon f is corners[ends[f-1] (0 for f = 0), ends[f])

  /// Closes the polygon made of the corners pushed since the last call.
  void endPolygon() { ends.push_back(corners.size()); }
  std::size_t polygonCount() const { return ends.size(); }
  std::size_t begin(std::size_t f) const { return f == 0 ? 0 : ends[f - 1]; }
};

}  // namespace shapedb::io::detail
