#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

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

}  // namespace shapedb::core
