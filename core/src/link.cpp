#include <algorithm>

#include <tbb/parallel_for.h>

#include <shapedb/core/link.h>

namespace shapedb::core {

SurfaceLink linkSurface(const TetLocator& locator, const Placement& placement,
                        std::span<const Vec3> vertices) {
  SurfaceLink link;
  link.locations.resize(vertices.size());
  // Consecutive vertices are usually neighbours: each run carries the last boundary face found.
  const auto run = [&](std::size_t begin, std::size_t end) {
    TetLocator::Hint hint;
    for (std::size_t i = begin; i < end; ++i)
      link.locations[i] = locator.locate(placement.toEntry(vertices[i]), hint);
  };
  if (vertices.size() >= 1024) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices.size(), 256),
                      [&](const auto& r) { run(r.begin(), r.end()); });
  } else {
    run(0, vertices.size());
  }
  for (TetLocation& l : link.locations)
    if (!l.inside()) {
      l.distance *= placement.scale;
      ++link.outsideCount;
      link.maxOutsideDistance = std::max(link.maxOutsideDistance, l.distance);
    }
  return link;
}

void deformSurface(const SurfaceLink& link, const TetMesh& tetMesh,
                   const Eigen::Ref<const Eigen::VectorXd>& u, std::span<const Vec3> rest,
                   std::vector<Vec3>& out) {
  out.resize(rest.size());
  for (std::size_t i = 0; i < rest.size(); ++i) {
    const TetLocation& l = link.locations[i];
    Vec3 x = rest[i];
    for (int k = 0; k < 4; ++k)
      x += l.weights[k] * u.segment<3>(3 * static_cast<Eigen::Index>(tetMesh.tets[l.tet][k]));
    out[i] = x;
  }
}

}  // namespace shapedb::core
