#include <cmath>
#include <string>

#include <shapedb/core/chunks.h>
#include <shapedb/core/mass_properties.h>

namespace shapedb::core {
namespace {

// Volume integrals of 1, p and p pᵀ over the solid (unit density), relative to a reference point.
struct VolumeIntegrals {
  double volume = 0.0;          // ∫ 1 dV
  double absoluteVolume = 0.0;  // Σ |tet volume|: the scale against which a near-zero volume is judged
  Vec3 first = Vec3::Zero();    // ∫ p dV
  Mat3 second = Mat3::Zero();   // ∫ p pᵀ dV
  double area = 0.0;
};

// Sum over the fan of tetrahedra (r, a, b, c), one per triangle; closed surfaces make it exact for any r.
// For a tet with one vertex at the origin and det d = a·(b×c): V = d/6, ∫p = d/24 (a+b+c),
// ∫p pᵀ = d/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a+b+c (Tonon 2004, the covariance of a simplex).
// Written out per component, with the six distinct entries of the symmetric sum: this loop is the
// whole cost of the stage (about 5 ns per triangle). Large meshes in core::Chunks, in parallel.
struct FanSums {
  double det = 0.0, absDet = 0.0, twiceArea = 0.0;
  double fx = 0.0, fy = 0.0, fz = 0.0;
  double xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, yz = 0.0, zx = 0.0;

  FanSums& operator+=(const FanSums& o) {
    det += o.det;
    absDet += o.absDet;
    twiceArea += o.twiceArea;
    fx += o.fx;
    fy += o.fy;
    fz += o.fz;
    xx += o.xx;
    yy += o.yy;
    zz += o.zz;
    xy += o.xy;
    yz += o.yz;
    zx += o.zx;
    return *this;
  }
};

FanSums fanSums(const TriangleMesh& mesh, const Vec3& reference, std::size_t begin, std::size_t end) {
  FanSums f;
  const Vec3* v = mesh.vertices.data();
  for (std::size_t i = begin; i < end; ++i) {
    const auto& t = mesh.triangles[i];
    const Vec3 a = v[t[0]] - reference, b = v[t[1]] - reference, c = v[t[2]] - reference;
    const Vec3 bc = b.cross(c);
    const double d = a.dot(bc);
    f.twiceArea += (b - a).cross(c - a).norm();
    f.det += d;
    f.absDet += std::abs(d);
    const double sx = a.x() + b.x() + c.x(), sy = a.y() + b.y() + c.y(), sz = a.z() + b.z() + c.z();
    f.fx += d * sx;
    f.fy += d * sy;
    f.fz += d * sz;
    f.xx += d * (a.x() * a.x() + b.x() * b.x() + c.x() * c.x() + sx * sx);
    f.yy += d * (a.y() * a.y() + b.y() * b.y() + c.y() * c.y() + sy * sy);
    f.zz += d * (a.z() * a.z() + b.z() * b.z() + c.z() * c.z() + sz * sz);
    f.xy += d * (a.x() * a.y() + b.x() * b.y() + c.x() * c.y() + sx * sy);
    f.yz += d * (a.y() * a.z() + b.y() * b.z() + c.y() * c.z() + sy * sz);
    f.zx += d * (a.z() * a.x() + b.z() * b.x() + c.z() * c.x() + sz * sx);
  }
  return f;
}

VolumeIntegrals integrateFan(const TriangleMesh& mesh, const Vec3& reference) {
  const FanSums f = Chunks(mesh.triangles.size()).sum<FanSums>([&](std::size_t begin, std::size_t end) {
    return fanSums(mesh, reference, begin, end);
  });
  VolumeIntegrals out;
  out.volume = f.det / 6.0;
  out.absoluteVolume = f.absDet / 6.0;
  out.first = Vec3(f.fx, f.fy, f.fz) / 24.0;
  out.second << f.xx, f.xy, f.zx, f.xy, f.yy, f.yz, f.zx, f.yz, f.zz;
  out.second /= 120.0;
  out.area = 0.5 * f.twiceArea;
  return out;
}

// The paper's approximation for surfaces that enclose no well-defined volume (§4.1): the mass spread
// over the vertices, each weighted by a third of its triangles' area; the volume estimated by the fan
// from the area-weighted centroid, which is exact when the surface is in fact closed.
Result<MassProperties> approximateFromVertices(const TriangleMesh& mesh, double density) {
  const std::vector<double> weight = vertexAreaWeights(mesh);
  double totalWeight = 0.0;
  for (double w : weight)
    totalWeight += w;
  if (!(totalWeight > 0.0)) return Error{ErrorCode::kZeroVolume, "mesh has zero surface area"};

  Vec3 centroid = Vec3::Zero();
  for (std::size_t v = 0; v < weight.size(); ++v)
    centroid += weight[v] * mesh.vertices[v];
  centroid /= totalWeight;

  const VolumeIntegrals fan = integrateFan(mesh, centroid);
  const double volume = std::abs(fan.volume);
  if (!(volume > 1e-9 * std::pow(fan.area, 1.5)))
    return Error{ErrorCode::kZeroVolume, "cannot estimate a volume from this open surface"};

  // Point-mass covariance scaled so that the total mass is density · volume.
  Mat3 covariance = Mat3::Zero();
  for (std::size_t v = 0; v < weight.size(); ++v) {
    const Vec3 r = mesh.vertices[v] - centroid;
    covariance.noalias() += weight[v] * r * r.transpose();
  }
  MassProperties out;
  out.density = density;
  out.volume = volume;
  out.mass = density * volume;
  out.area = fan.area;
  out.centerOfMass = centroid;
  out.inertia = inertiaFromCovariance(covariance * (out.mass / totalWeight));
  out.isApproximate = true;
  return out;
}

}  // namespace

std::vector<double> vertexAreaWeights(const TriangleMesh& mesh) {
  std::vector<double> weight(mesh.vertices.size(), 0.0);
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const double third = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm() / 6.0;
    for (std::uint32_t v : t)
      weight[v] += third;
  }
  return weight;
}

Result<MassProperties> computeMassProperties(const TriangleMesh& mesh, const TopologyReport& topology,
                                             const MassPropertiesOptions& options) {
  if (!(std::isfinite(options.density) && options.density > 0.0))
    return Error{ErrorCode::kInvalidArgument, "density must be finite and positive"};
  if (mesh.triangles.empty()) return Error{ErrorCode::kEmptyMesh, "mesh has no faces"};

  // Surfaces that bound no well-defined solid: an error, or the approximation when asked for.
  if (Status closed = requireClosedOriented(topology); !closed) {
    if (!options.allowApproximate) return closed.error();
    return approximateFromVertices(mesh, options.density);
  }

  // Integrate relative to a vertex of the mesh, so that a mesh far from the origin keeps its precision.
  const Vec3 reference = mesh.vertices[mesh.triangles.front()[0]];
  VolumeIntegrals fan = integrateFan(mesh, reference);

  if (!(std::abs(fan.volume) > 1e-12 * fan.absoluteVolume) || !(fan.absoluteVolume > 0.0))
    return Error{ErrorCode::kZeroVolume, "mesh encloses no volume"};
  MassProperties out;
  if (fan.volume < 0.0) {
    if (!options.flipInsideOut) {
      return Error{ErrorCode::kInsideOut,
                   "mesh is inside out (signed volume " + std::to_string(fan.volume) + " m³)"};
    }
    // Reversing every face negates every integral.
    fan.volume = -fan.volume;
    fan.first = -fan.first;
    fan.second = -fan.second;
    out.wasFlipped = true;
  }

  // Centre of mass, then the covariance moved to it (parallel-axis theorem).
  const Vec3 comFromReference = fan.first / fan.volume;
  const Mat3 covariance = fan.second - fan.volume * comFromReference * comFromReference.transpose();
  out.density = options.density;
  out.volume = fan.volume;
  out.mass = options.density * fan.volume;
  out.area = fan.area;
  out.centerOfMass = reference + comFromReference;
  out.inertia = inertiaFromCovariance(options.density * covariance);
  return out;
}

Result<MassProperties> computeMassProperties(const TriangleMesh& mesh, const MassPropertiesOptions& options) {
  return computeMassProperties(mesh, analyzeTopology(mesh), options);
}

}  // namespace shapedb::core
