#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <shapedb/volume/collision.h>
#include <shapedb/volume/openvdb_runtime.h>

#include "level_set.h"

namespace shapedb::volume {
namespace {

using core::CollisionShape;
using core::Vec3;

/// The solid sampled at voxel centres: signed distance (negative inside) on a dense grid.
struct Samples {
  Vec3 origin;       ///< centre of voxel (0, 0, 0)
  double voxel = 0;  ///< voxel side
  int n[3] = {0, 0, 0};
  std::vector<float> distance;  ///< x fastest
  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(n[0]) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * k);
  }
  Vec3 center(int i, int j, int k) const { return origin + voxel * Vec3(i, j, k); }
  /// Signed distance at the voxel nearest to p; outside the grid: positive (outside the solid).
  double distanceAt(const Vec3& p) const {
    const Vec3 c = (p - origin) / voxel;
    const int i = static_cast<int>(std::lround(c.x())), j = static_cast<int>(std::lround(c.y())),
              k = static_cast<int>(std::lround(c.z()));
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return voxel;
    return distance[index(i, j, k)];
  }
};

Samples sampleSolid(const core::TriangleMesh& surface, int resolution) {
  initializeOpenVdb();
  const core::Bounds bounds = core::computeBounds(surface);
  Samples s;
  // `resolution` voxels along the largest extent, and at least 6 across the smallest: a thin plate or
  // needle must still have voxels inside it (and OpenVDB's sign flood needs some thickness).
  s.voxel = std::min(bounds.extent().maxCoeff() / resolution, bounds.extent().minCoeff() / 6.0);
  const int pad = 2;  // room for compound overshoot around the solid
  for (int a = 0; a < 3; ++a)
    s.n[a] = static_cast<int>(std::ceil(bounds.extent()[a] / s.voxel)) + 2 * pad;
  s.origin = bounds.center() - 0.5 * s.voxel * Vec3(s.n[0] - 1, s.n[1] - 1, s.n[2] - 1);

  // OpenVDB's voxel centres at index (i, j, k) are origin + voxel·(i, j, k): a transform with that origin.
  auto transform = openvdb::math::Transform::createLinearTransform(s.voxel);
  transform->postTranslate(openvdb::Vec3d(s.origin.x(), s.origin.y(), s.origin.z()));
  const detail::OpenVdbMesh vdb = detail::toOpenVdb(surface);
  // The interior band covers the whole solid: distances everywhere inside, for the inscribed spheres.
  const float interior = static_cast<float>(bounds.extent().maxCoeff() / s.voxel);
  const auto grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *transform, vdb.points, vdb.triangles, std::vector<openvdb::Vec4I>{}, 3.0f, interior);
  const auto accessor = grid->getConstAccessor();
  s.distance.resize(static_cast<std::size_t>(s.n[0]) * s.n[1] * s.n[2]);
  for (int k = 0; k < s.n[2]; ++k)
    for (int j = 0; j < s.n[1]; ++j)
      for (int i = 0; i < s.n[0]; ++i)
        s.distance[s.index(i, j, k)] = accessor.getValue(openvdb::Coord(i, j, k));
  return s;
}

/// The greedy fit's state: which voxels the compound covers so far.
class Fitter {
 public:
  Fitter(const Samples& samples, const CollisionOptions& options) : s(samples), mOptions(options) {
    mCovered.assign(s.distance.size(), 0);
    for (float d : s.distance)
      mInside += d < 0.0f ? 1 : 0;
  }
  std::size_t insideCount() const { return mInside; }

  /// Net gain of adding `shape`: new inside voxels − penalty × new outside voxels.
  double gain(const CollisionShape& shape) const {
    double g = 0.0;
    forEachVoxelIn(shape, [&](std::size_t v) {
      if (mCovered[v]) return;
      g += s.distance[v] < 0.0f ? 1.0 : -mOptions.overshootPenalty;
    });
    return g;
  }
  void add(const CollisionShape& shape) {
    forEachVoxelIn(shape, [&](std::size_t v) {
      if (mCovered[v]) return;
      mCovered[v] = 1;
      (s.distance[v] < 0.0f ? mCoveredInside : mCoveredOutside) += 1;
    });
  }
  double coverage() const { return static_cast<double>(mCoveredInside) / static_cast<double>(mInside); }
  double overshoot() const { return static_cast<double>(mCoveredOutside) / static_cast<double>(mInside); }

  /// The deepest inside voxel not yet covered, or false when every inside voxel is covered.
  bool deepestUncovered(int& ci, int& cj, int& ck) const {
    float best = 0.0f;
    for (int k = 0; k < s.n[2]; ++k)
      for (int j = 0; j < s.n[1]; ++j)
        for (int i = 0; i < s.n[0]; ++i) {
          const std::size_t v = s.index(i, j, k);
          if (!mCovered[v] && s.distance[v] < best) {
            best = s.distance[v];
            ci = i, cj = j, ck = k;
          }
        }
    return best < 0.0f;
  }

 private:
  template <typename F>
  void forEachVoxelIn(const CollisionShape& shape, F&& f) const {
    // The shape's bounding box in voxel indices, then the exact test per voxel centre.
    const Vec3 half = shape.halfSpan();
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int>(std::floor((shape.center[a] - half[a] - s.origin[a]) / s.voxel)));
      hi[a] = std::min(s.n[a] - 1,
                       static_cast<int>(std::ceil((shape.center[a] + half[a] - s.origin[a]) / s.voxel)));
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i)
          if (shape.contains(s.center(i, j, k))) f(s.index(i, j, k));
  }

  const Samples& s;
  const CollisionOptions& mOptions;
  std::vector<std::uint8_t> mCovered;
  std::size_t mInside = 0, mCoveredInside = 0, mCoveredOutside = 0;
};

/// The axis-aligned box grown from voxel (i, j, k): each of its six faces moves out one voxel layer at
/// a time while at least 90 % of the new layer is inside the solid.
CollisionShape growBox(const Samples& s, int i, int j, int k) {
  int lo[3] = {i, j, k}, hi[3] = {i, j, k};
  const auto layerInside = [&](int axis, int at) {
    int inside = 0, total = 0;
    int a0[3] = {lo[0], lo[1], lo[2]}, a1[3] = {hi[0], hi[1], hi[2]};
    a0[axis] = a1[axis] = at;
    for (int z = a0[2]; z <= a1[2]; ++z)
      for (int y = a0[1]; y <= a1[1]; ++y)
        for (int x = a0[0]; x <= a1[0]; ++x) {
          ++total;
          inside += s.distance[s.index(x, y, z)] < 0.0f ? 1 : 0;
        }
    return inside >= 0.9 * total;
  };
  for (bool grew = true; grew;) {
    grew = false;
    for (int axis = 0; axis < 3; ++axis) {
      if (lo[axis] > 0 && layerInside(axis, lo[axis] - 1)) --lo[axis], grew = true;
      if (hi[axis] < s.n[axis] - 1 && layerInside(axis, hi[axis] + 1)) ++hi[axis], grew = true;
    }
  }
  CollisionShape box;
  box.type = CollisionShape::Type::kBox;
  const Vec3 a = s.center(lo[0], lo[1], lo[2]), b = s.center(hi[0], hi[1], hi[2]);
  box.center = 0.5 * (a + b);
  box.halfExtents = 0.5 * (b - a) + Vec3::Constant(0.5 * s.voxel);
  return box;
}

/// The capsule along `axis` through `c` (at depth `depth`) of radius r: each end moves out a voxel at a
/// time while the solid there is as deep as at c, to half a voxel (so a sphere does not grow into a
/// capsule, and a capsule's axis is followed to its caps).
CollisionShape growCapsule(const Samples& s, const Vec3& c, double depth, double r, int axis) {
  const Vec3 direction = Vec3::Unit(axis);
  const auto fits = [&](double t) { return -s.distanceAt(c + t * direction) >= depth - 0.5 * s.voxel; };
  double lo = 0.0, hi = 0.0;
  while (fits(hi + s.voxel) && hi < 1e3 * s.voxel)
    hi += s.voxel;
  while (fits(lo - s.voxel) && lo > -1e3 * s.voxel)
    lo -= s.voxel;
  CollisionShape capsule;
  capsule.type = CollisionShape::Type::kCapsule;
  capsule.center = c + 0.5 * (lo + hi) * direction;
  capsule.radius = r;
  capsule.halfLength = 0.5 * (hi - lo);
  // Local z along the axis: a proper rotation taking z to `direction`.
  if (axis == 0) capsule.rotation << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  if (axis == 1) capsule.rotation << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return capsule;
}

}  // namespace

Result<core::CollisionCompound> fitCollisionCompound(const core::TriangleMesh& surface,
                                                     const CollisionOptions& options) {
  if (options.maxShapes < 1 || options.resolution < 8 || options.resolution > 128 ||
      !(options.targetCoverage > 0.0 && options.targetCoverage <= 1.0) || !(options.overshootPenalty >= 0.0))
    return Error{ErrorCode::kInvalidArgument, "collision options out of range"};
  if (surface.triangles.empty()) return Error{ErrorCode::kEmptyMesh, "mesh has no faces"};
  const Samples samples = sampleSolid(surface, options.resolution);
  Fitter fitter(samples, options);
  if (fitter.insideCount() == 0)
    return Error{ErrorCode::kZeroVolume, "the solid has no voxel inside at collision resolution " +
                                             std::to_string(options.resolution)};

  core::CollisionCompound compound;
  while (static_cast<int>(compound.shapes.size()) < options.maxShapes &&
         fitter.coverage() < options.targetCoverage) {
    int i = 0, j = 0, k = 0;
    if (!fitter.deepestUncovered(i, j, k)) break;
    const Vec3 c = samples.center(i, j, k);
    const double depth = -samples.distance[samples.index(i, j, k)];
    std::vector<CollisionShape> candidates;
    candidates.push_back(growBox(samples, i, j, k));
    // The depth at a voxel centre understates the inscribed radius by up to a voxel's half-diagonal:
    // radii from the sampled depth to a voxel more, and the gain picks.
    for (double extra : {0.0, 0.5, 1.0}) {
      const double r = depth + extra * samples.voxel;
      CollisionShape sphere;
      sphere.type = CollisionShape::Type::kSphere;
      sphere.center = c;
      sphere.radius = r;
      candidates.push_back(sphere);
      for (int axis = 0; axis < 3; ++axis)
        candidates.push_back(growCapsule(samples, c, depth, r, axis));
    }

    double bestGain = 0.0;
    const CollisionShape* best = nullptr;
    for (const CollisionShape& candidate : candidates) {
      const double g = fitter.gain(candidate);
      if (g > bestGain) bestGain = g, best = &candidate;
    }
    // Nothing that pays for itself: a thin sliver the voxels barely resolve.
    if (best == nullptr || bestGain < 1e-3 * static_cast<double>(fitter.insideCount())) break;
    fitter.add(*best);
    compound.shapes.push_back(*best);
  }
  compound.coverage = fitter.coverage();
  compound.overshoot = fitter.overshoot();
  return compound;
}

}  // namespace shapedb::volume
