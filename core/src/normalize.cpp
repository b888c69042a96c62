#include <array>
#include <cmath>
#include <complex>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include <shapedb/core/chunks.h>
#include <shapedb/core/normalize.h>

namespace shapedb::core {
namespace {

// Third moments ∫(u·(p−c))³ dV along two axes, by the fan of tetrahedra from c. For a simplex with a
// vertex at c and the others at wᵢ = u·(vᵢ − c): ∫(u·p)³ dV = V/20 · h₃(w₁, w₂, w₃), h₃ the complete
// homogeneous symmetric polynomial of degree 3 (the Dirichlet integral over the simplex); by Newton's
// identities 6 h₃ = p₁³ + 3 p₁ p₂ + 2 p₃, with pₖ the power sums of the wᵢ.
std::array<double, 2> thirdMomentsExact(const TriangleMesh& mesh, const Vec3& c, const Vec3& ux,
                                        const Vec3& uy) {
  // Every vertex once in the frame (ux, uy, ux × uy) about c; determinants do not depend on the frame.
  // Large meshes in core::Chunks, in parallel (the sums do not depend on the threads).
  thread_local std::vector<Vec3> local;
  local.resize(mesh.vertices.size());
  Mat3 frameFromMesh;
  frameFromMesh.row(0) = ux;
  frameFromMesh.row(1) = uy;
  frameFromMesh.row(2) = ux.cross(uy);
  Vec3* q = local.data();
  Chunks(mesh.vertices.size()).run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      q[i] = frameFromMesh * (mesh.vertices[i] - c);
  });
  const auto sixH3 = [](double w1, double w2, double w3) {
    const double p1 = w1 + w2 + w3, p2 = w1 * w1 + w2 * w2 + w3 * w3,
                 p3 = w1 * w1 * w1 + w2 * w2 * w2 + w3 * w3 * w3;
    return p1 * p1 * p1 + 3.0 * p1 * p2 + 2.0 * p3;
  };
  const Eigen::Vector2d sums =
      Chunks(mesh.triangles.size()).sum<Eigen::Vector2d>([&](std::size_t begin, std::size_t end) {
        double sumX = 0.0, sumY = 0.0;
        for (std::size_t i = begin; i < end; ++i) {
          const auto& t = mesh.triangles[i];
          const Vec3& a = q[t[0]];
          const Vec3& b = q[t[1]];
          const Vec3& d = q[t[2]];
          const double det = a.dot(b.cross(d));
          sumX += det * sixH3(a.x(), b.x(), d.x());
          sumY += det * sixH3(a.y(), b.y(), d.y());
        }
        return Eigen::Vector2d(sumX, sumY);
      });
  // det/6 is the tet volume, so V/20 · h₃ = det/720 · 6 h₃.
  return {sums.x() / 720.0, sums.y() / 720.0};
}

// The same moments for the approximate properties: the vertex point masses, scaled to a volume
// integral as the approximate inertia was.
std::array<double, 2> thirdMomentsOfVertices(const TriangleMesh& mesh, const MassProperties& mp,
                                             const Vec3& ux, const Vec3& uy) {
  const std::vector<double> weight = vertexAreaWeights(mesh);
  double sumX = 0.0, sumY = 0.0, total = 0.0;
  for (std::size_t v = 0; v < weight.size(); ++v) {
    const Vec3 r = mesh.vertices[v] - mp.centerOfMass;
    sumX += weight[v] * std::pow(ux.dot(r), 3);
    sumY += weight[v] * std::pow(uy.dot(r), 3);
    total += weight[v];
  }
  const double toVolume = mp.volume / total;
  return {sumX * toVolume, sumY * toVolume};
}

// The strongest angular harmonic of the surface about axis d, over the plane basis (e1, e2):
// μ_m = Σ A (u + i v)^m over triangle centroids (u, v) about c, normalized by Σ A |u + i v|^m.
// Returns {m, phase} of the largest normalized magnitude of order 2..6, or m = 0 if none reaches
// `tolerance`.
std::pair<int, double> strongestHarmonic(const TriangleMesh& mesh, const Vec3& c, const Vec3& e1,
                                         const Vec3& e2, double tolerance) {
  constexpr int kMaxOrder = 6;
  std::array<std::complex<double>, kMaxOrder + 1> sum{};
  std::array<double, kMaxOrder + 1> norm{};
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& d = mesh.vertices[t[2]];
    const double area = 0.5 * (b - a).cross(d - a).norm();
    const Vec3 r = (a + b + d) / 3.0 - c;
    const std::complex<double> z(r.dot(e1), r.dot(e2));
    const double radius = std::abs(z);
    std::complex<double> power = z;
    double radiusPower = radius;
    for (int m = 2; m <= kMaxOrder; ++m) {
      power *= z;
      radiusPower *= radius;
      sum[static_cast<std::size_t>(m)] += area * power;
      norm[static_cast<std::size_t>(m)] += area * radiusPower;
    }
  }
  int best = 0;
  double bestStrength = tolerance;
  for (int m = 2; m <= kMaxOrder; ++m) {
    const auto i = static_cast<std::size_t>(m);
    const double strength = norm[i] > 0.0 ? std::abs(sum[i]) / norm[i] : 0.0;
    if (strength >= bestStrength * (1.0 + 1e-9)) {
      best = m;
      bestStrength = strength;
    }
  }
  return {best, best > 0 ? std::arg(sum[static_cast<std::size_t>(best)]) : 0.0};
}

}  // namespace

Result<Normalization> normalize(const TriangleMesh& mesh, const MassProperties& massProperties,
                                const NormalizeOptions& options) {
  const MassProperties& mp = massProperties;
  if (!(std::isfinite(mp.volume) && mp.volume > 0.0 && mp.density > 0.0 && mp.centerOfMass.allFinite() &&
        mp.inertia.allFinite()))
    return Error{ErrorCode::kInvalidArgument, "mass properties are not finite and positive"};

  // Principal moments and axes, ascending; x the axis of the smallest moment.
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(mp.inertia);
  if (eigen.info() != Eigen::Success)
    return Error{ErrorCode::kInvalidArgument, "inertia tensor has no eigen-decomposition"};
  Normalization out;
  out.isApproximate = mp.isApproximate;
  out.principalMoments = eigen.eigenvalues();
  Vec3 x = eigen.eigenvectors().col(0);
  Vec3 y = eigen.eigenvectors().col(1);

  // Conditioning: relative gaps between consecutive moments.
  const Vec3& m = out.principalMoments;
  out.momentGaps = {(m[1] - m[0]) / m[2], (m[2] - m[1]) / m[2]};
  const bool lowPair = out.momentGaps[0] < options.degeneracyTolerance;
  const bool highPair = out.momentGaps[1] < options.degeneracyTolerance;
  out.degeneracy = lowPair && highPair ? AxisDegeneracy::kAll
                   : lowPair           ? AxisDegeneracy::kXY
                   : highPair          ? AxisDegeneracy::kYZ
                                       : AxisDegeneracy::kNone;

  // Sign rule: positive third moment along two axes; skewness says how reliable that is. In a
  // degenerate plane only the distinct axis takes it (the pair below is set by the harmonic).
  const Vec3 zEigen = eigen.eigenvectors().col(2);
  const bool pairXY = out.degeneracy == AxisDegeneracy::kXY, pairYZ = out.degeneracy == AxisDegeneracy::kYZ;
  Vec3 first = pairXY ? zEigen : x;  // the axis whose moment is m[iFirst]
  Vec3 second = pairXY ? x : y;
  const std::array<int, 2> moment = {pairXY ? 2 : 0, pairXY ? 0 : 1};
  const std::array<double, 2> m3 = mp.isApproximate ? thirdMomentsOfVertices(mesh, mp, first, second)
                                                    : thirdMomentsExact(mesh, mp.centerOfMass, first, second);
  // Second moments along an axis (unit density): σ² V = ∫(u·r)² dV = (tr(I) / 2 − λ) / ρ.
  const double halfTrace = 0.5 * m.sum();
  Vec3* axes[2] = {&first, &second};
  std::array<double, 2> skewness{};
  for (int i = 0; i < 2; ++i) {
    const double m2 = (halfTrace - m[moment[static_cast<std::size_t>(i)]]) / mp.density;
    const double sigma = std::sqrt(std::max(m2, 0.0) / mp.volume);
    const double skew =
        sigma > 0.0 ? m3[static_cast<std::size_t>(i)] / (mp.volume * sigma * sigma * sigma) : 0.0;
    if (skew < 0.0) *axes[i] = -*axes[i];
    skewness[static_cast<std::size_t>(i)] = std::abs(skew);
  }
  if (pairXY || pairYZ) {
    // The distinct axis d keeps its sign rule; (e1, e2, d) right-handed spans the plane, turned so that
    // the surface's strongest angular harmonic has phase 0: u' + i v' = e^{iθ}(u + i v), θ = −φ/m.
    const Vec3 d = first;
    Vec3 e1 = pairXY ? second : y;  // an eigenvector, orthogonal to d
    Vec3 e2 = d.cross(e1);
    const auto [order, phase] = strongestHarmonic(mesh, mp.centerOfMass, e1, e2, options.harmonicTolerance);
    if (order > 0) {
      const double theta = -phase / order;
      const Vec3 r1 = std::cos(theta) * e1 - std::sin(theta) * e2,
                 r2 = std::sin(theta) * e1 + std::cos(theta) * e2;
      e1 = r1;
      e2 = r2;
    }
    out.planeSymmetry = order;
    out.distinctAxisAmbiguous = skewness[0] < options.signTolerance;
    if (pairXY) {
      x = e1;
      y = e2;
      out.skewness = {0.0, 0.0};
      out.signAmbiguous = {order == 0, order == 0};
    } else {
      x = d;
      y = e1;
      out.skewness = {skewness[0], 0.0};
      out.signAmbiguous = {out.distinctAxisAmbiguous, order == 0};
    }
  } else {
    x = first;
    y = second;
    out.skewness = skewness;
    for (int i = 0; i < 2; ++i)
      out.signAmbiguous[static_cast<std::size_t>(i)] =
          skewness[static_cast<std::size_t>(i)] < options.signTolerance;
  }
  const Vec3 z = x.cross(y);
  out.principalAxes.col(0) = x;
  out.principalAxes.col(1) = y;
  out.principalAxes.col(2) = z;

  // T = canonicalFromMesh: p' = s Rᵀ (p − c); T⁻¹: p = R p' / s + c.
  out.scale = std::cbrt(1.0 / mp.volume);
  const Mat3 rotation = out.principalAxes.transpose();
  out.canonicalFromMesh.setIdentity();
  out.canonicalFromMesh.topLeftCorner<3, 3>() = out.scale * rotation;
  out.canonicalFromMesh.topRightCorner<3, 1>() = -out.scale * (rotation * mp.centerOfMass);
  out.meshFromCanonical.setIdentity();
  out.meshFromCanonical.topLeftCorner<3, 3>() = out.principalAxes / out.scale;
  out.meshFromCanonical.topRightCorner<3, 1>() = mp.centerOfMass;

  // Moments of the unit-volume, unit-density shape: inertia scales with ρ L⁵.
  out.canonicalMoments = m * std::pow(out.scale, 5) / mp.density;
  return out;
}

const char* toString(AxisDegeneracy degeneracy) {
  switch (degeneracy) {
    case AxisDegeneracy::kNone:
      return "none";
    case AxisDegeneracy::kXY:
      return "xy";
    case AxisDegeneracy::kYZ:
      return "yz";
    case AxisDegeneracy::kAll:
      return "all";
  }
  return "unknown";
}

}  // namespace shapedb::core
