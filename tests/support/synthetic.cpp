#include "synthetic.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/volume/describe.h>

namespace shapedb::test {

core::Mat3 randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

core::TriangleMesh makeTorus(double major, double minor, int rings, int segments) {
  core::TriangleMesh m;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double u = 2.0 * std::numbers::pi * i / rings, v = 2.0 * std::numbers::pi * j / segments;
      m.vertices.emplace_back((major + minor * std::cos(v)) * std::cos(u),
                              (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v));
    }
  const auto at = [&](int i, int j) {
    return static_cast<std::uint32_t>(((i + rings) % rings) * segments + (j + segments) % segments);
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

core::TriangleMesh makeLopsidedBlob(const core::Vec3& radii, int subdivisions) {
  core::TriangleMesh mesh = core::makeIcosphere(1.0, subdivisions);
  // Tapers make it pear-shaped along x and along y; the bump breaks every remaining symmetry.
  for (core::Vec3& p : mesh.vertices) {
    const double bump = 1.0 + 0.1 * p.z() + 0.1 * p.x() * p.z() + 0.05 * p.y() * p.y();
    p = core::Vec3(p.x(), p.y() * (1.0 + 0.5 * p.x()), p.z() * (1.0 + 0.4 * p.x()) * (1.0 + 0.45 * p.y())) *
        bump;
    p = radii.cwiseProduct(p);
  }
  return mesh;
}

core::TriangleMesh makeRandomShape(std::mt19937_64& rng, int subdivisions) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto logUniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
  const core::Vec3 size(logUniform(0.2, 2.0), logUniform(0.2, 2.0), logUniform(0.2, 2.0));
  const int kind = static_cast<int>(unit(rng) * 8.0);
  if (kind == 0) return core::makeBox(size);
  if (kind == 1) return core::makeUvEllipsoid(size, 24, 12);
  if (kind == 2) return core::makeCylinder(size.x(), size.z(), 24);

  // A radial wave: r = 1 + Σ a sin(f d·p̂ + φ), |Σ a| < 1 keeps it star-shaped, hence closed and simple.
  struct Wave {
    core::Vec3 direction;
    double amplitude, frequency, phase;
  };
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Wave> waves(3);
  for (Wave& w : waves) {
    w.direction = core::Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    w.amplitude = 0.2 * unit(rng);
    w.frequency = 1.0 + 3.0 * unit(rng);
    w.phase = 2.0 * std::numbers::pi * unit(rng);
  }
  core::TriangleMesh mesh = core::makeIcosphere(1.0, subdivisions);
  for (core::Vec3& p : mesh.vertices) {
    double r = 1.0;
    for (const Wave& w : waves)
      r += w.amplitude * std::sin(w.frequency * w.direction.dot(p) + w.phase);
    p = size.cwiseProduct(p * r);
  }
  return mesh;
}

core::DescriptorOptions descriptorOptions(core::DescriptorKind kind, core::Sampling sampling, int gridSize) {
  core::DescriptorOptions o;
  o.kind = kind;
  o.sampling = sampling;
  o.gridSize = gridSize;
  return o;
}

Result<DescribedMesh> describeMesh(const core::TriangleMesh& mesh, const core::DescriptorOptions& options) {
  Result<core::MassProperties> mp = core::computeMassProperties(mesh);
  if (!mp) return mp.error();
  Result<core::Normalization> n = core::normalize(mesh, *mp);
  if (!n) return n.error();
  Result<core::Descriptor> d = volume::describe(mesh, *n, options);
  if (!d) return d.error();
  return DescribedMesh{std::move(n).value(), std::move(d).value()};
}

core::Descriptor jitterDescriptor(const core::Descriptor& d, std::mt19937_64& rng, int flips,
                                  double centroidNoise) {
  core::Descriptor out = d;
  if (d.kind == core::DescriptorKind::kMoment || d.gridSize == 0) {
    std::normal_distribution<double> noise(0.0, centroidNoise);
    for (int i = 0; i < 3; ++i)
      out.moments[i] *= 1.0 + noise(rng);
    std::sort(out.moments.data(), out.moments.data() + 3);
    return out;
  }
  // A nearby shape is also proportioned a little differently.
  std::normal_distribution<double> momentNoise(0.0, 0.5 * centroidNoise);
  for (int i = 0; i < 3; ++i)
    out.moments[i] *= std::exp(momentNoise(rng));
  std::sort(out.moments.data(), out.moments.data() + 3);
  const int n = d.gridSize;
  std::uniform_real_distribution<double> offset(-centroidNoise, centroidNoise);
  std::vector<std::pair<std::uint32_t, core::Vec3>> cells;
  for (std::size_t i = 0; i < d.cells.size(); ++i)
    cells.emplace_back(
        d.cells[i],
        (d.centroids[i] + core::Vec3(offset(rng), offset(rng), offset(rng))).cwiseMax(0.0).cwiseMin(1.0));
  // Flip cells next to a filled one: remove it, or fill a face neighbour.
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int f = 0; f < flips && !cells.empty(); ++f) {
    const std::size_t pick =
        static_cast<std::size_t>(unit(rng) * static_cast<double>(cells.size())) % cells.size();
    if (unit(rng) < 0.5) {
      cells.erase(cells.begin() + static_cast<std::ptrdiff_t>(pick));
      continue;
    }
    const int cell = static_cast<int>(cells[pick].first);
    std::array<int, 3> ijk = core::cellCoordinates(static_cast<std::uint32_t>(cell), n);
    const auto axis = static_cast<std::size_t>(unit(rng) * 3.0) % 3;
    ijk[axis] = std::clamp(ijk[axis] + (unit(rng) < 0.5 ? -1 : 1), 0, n - 1);
    const std::uint32_t neighbour = core::linearCell(ijk[0], ijk[1], ijk[2], n);
    if (std::none_of(cells.begin(), cells.end(), [&](const auto& c) { return c.first == neighbour; }))
      cells.emplace_back(neighbour, core::Vec3(unit(rng), unit(rng), unit(rng)));
  }
  std::sort(cells.begin(), cells.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.cells.clear();
  out.centroids.clear();
  out.weights.clear();
  for (const auto& [cell, centroid] : cells) {
    out.cells.push_back(cell);
    out.centroids.push_back(centroid);
    out.weights.push_back(1.0);
  }
  return out;
}

}  // namespace shapedb::test
