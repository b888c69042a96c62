#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <shapedb/core/fidelity.h>

namespace shapedb::core {

std::vector<Vec3> sampleSurface(const TriangleMesh& mesh, int count) {
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    total += 0.5 * (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a).norm();
    cumulative[t] = total;
  }
  std::vector<Vec3> points;
  if (count <= 0 || cumulative.empty() || !(total > 0.0)) return points;
  points.reserve(static_cast<std::size_t>(count));
  constexpr double kA1 = 0.7548776662466927, kA2 = 0.5698402909980532;  // R2: 1/g, 1/g², g³ = g + 1
  for (int i = 0; i < count; ++i) {
    const double target = (i + 0.5) / count * total;
    const auto t = static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), target) -
                                            cumulative.begin());
    const auto& tri = mesh.triangles[std::min(t, cumulative.size() - 1)];
    double u = std::fmod(0.5 + kA1 * (i + 1), 1.0), v = std::fmod(0.5 + kA2 * (i + 1), 1.0);
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    const Vec3& a = mesh.vertices[tri[0]];
    points.push_back(a + u * (mesh.vertices[tri[1]] - a) + v * (mesh.vertices[tri[2]] - a));
  }
  return points;
}

Fidelity assessFidelity(const TriangleMesh& query, const ClosestPointTree& queryTree,
                        const Normalization& normalization, const TetLocator& entry,
                        const MassProperties& entryMass, const Placement& placement,
                        double descriptorDistance, const FidelityOptions& options) {
  Fidelity f;
  f.descriptorDistance = descriptorDistance;
  f.queryMoments = normalization.canonicalMoments;
  // The entry's tets at unit density in a unit-volume frame: the same normalization as the query's.
  Eigen::SelfAdjointEigenSolver<Mat3> eig(
      entryMass.inertia / (entryMass.density * std::pow(entryMass.volume, 5.0 / 3.0)),
      Eigen::EigenvaluesOnly);
  f.entryMoments = eig.eigenvalues();
  f.momentError = (f.entryMoments - f.queryMoments).cwiseQuotient(f.queryMoments);
  f.maxMomentError = f.momentError.cwiseAbs().maxCoeff();

  // Distances in the entry's frame are in canonical units: one canonical unit is L metres, and the
  // deviation is reported relative to L, so the entry side needs no scaling.
  double sum = 0.0, worst = 0.0;
  int n = 0;
  if (!entry.boundaryTree().empty())
    for (const Vec3& p : sampleSurface(query, options.samples)) {
      const double d = std::sqrt(entry.boundaryTree().closest(placement.toEntry(p)).closest.squaredDistance);
      sum += d;
      worst = std::max(worst, d);
      ++n;
    }
  if (!queryTree.empty())
    for (const Vec3& e : sampleSurface(entry.boundary(), options.samples)) {
      const double d =
          std::sqrt(queryTree.closest(placement.toQuery(e)).closest.squaredDistance) / placement.scale;
      sum += d;
      worst = std::max(worst, d);
      ++n;
    }
  f.samples = n;
  f.meanDeviation = n > 0 ? sum / n : 0.0;
  f.maxDeviation = worst;
  return f;
}

VolumeOverlap sampleOverlap(const SampledSolid& a, const SampledSolid& b, int resolution) {
  resolution = std::clamp(resolution, 8, 512);
  const Vec3 lo = a.bounds.min.cwiseMin(b.bounds.min);
  const Vec3 extent = a.bounds.max.cwiseMax(b.bounds.max) - lo;
  const double cell = extent.maxCoeff() / resolution;
  VolumeOverlap overlap;
  if (!(cell > 0.0) || !std::isfinite(cell)) return overlap;
  Eigen::Array3i n;
  for (int k = 0; k < 3; ++k)
    n[k] = std::max(1, static_cast<int>(std::ceil(extent[k] / cell - 1e-9)));
  // Counts per slice: inside A, inside B, inside both.
  using Counts = std::array<long, 3>;
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, n[2]), Counts{},
      [&](const tbb::blocked_range<int>& slices, Counts c) {
        for (int z = slices.begin(); z != slices.end(); ++z)
          for (int y = 0; y < n[1]; ++y)
            for (int x = 0; x < n[0]; ++x) {
              const Vec3 p = lo + cell * Vec3(x + 0.5, y + 0.5, z + 0.5);
              const bool inA = a.contains(p), inB = b.contains(p);
              c[0] += inA;
              c[1] += inB;
              c[2] += inA && inB;
            }
        return c;
      },
      [](const Counts& l, const Counts& r) {
        return Counts{l[0] + r[0], l[1] + r[1], l[2] + r[2]};
      });
  const double voxel = cell * cell * cell;
  overlap.samples = static_cast<long>(n.prod());
  overlap.volumeA = counts[0] * voxel;
  overlap.volumeB = counts[1] * voxel;
  const long unionCount = counts[0] + counts[1] - counts[2];
  overlap.iou = unionCount > 0 ? static_cast<double>(counts[2]) / unionCount : 0.0;
  if (counts[0] > 0) {
    overlap.coverage = static_cast<double>(counts[2]) / counts[0];
    overlap.overshoot = static_cast<double>(counts[1] - counts[2]) / counts[0];
  }
  return overlap;
}

Bounds compoundBounds(const CollisionCompound& compound) {
  Bounds box{Vec3::Constant(std::numeric_limits<double>::infinity()),
             Vec3::Constant(-std::numeric_limits<double>::infinity())};
  for (const CollisionShape& shape : compound.shapes) {
    const Vec3 half = shape.halfSpan();
    box.min = box.min.cwiseMin(shape.center - half);
    box.max = box.max.cwiseMax(shape.center + half);
  }
  if (compound.shapes.empty()) box = Bounds{};
  return box;
}

SampledSolid sampledSolid(const CollisionCompound& compound) {
  return {[&compound](const Vec3& p) {
            return std::any_of(compound.shapes.begin(), compound.shapes.end(),
                               [&](const CollisionShape& shape) { return shape.contains(p); });
          },
          compoundBounds(compound)};
}

namespace {
Vec3 equivalentHalfAxes(const Vec3& moments, double mass, double k) {
  Vec3 axes;
  for (int i = 0; i < 3; ++i) {
    const double sum = moments[(i + 1) % 3] + moments[(i + 2) % 3] - moments[i];
    axes[i] = std::sqrt(std::max(0.0, k * sum / (2.0 * mass)));
  }
  return axes;
}
}  // namespace

Vec3 inertiaEquivalentEllipsoid(const Vec3& principalMoments, double mass) {
  return equivalentHalfAxes(principalMoments, mass, 5.0);
}

Vec3 inertiaEquivalentBox(const Vec3& principalMoments, double mass) {
  return equivalentHalfAxes(principalMoments, mass, 3.0);
}

}  // namespace shapedb::core
