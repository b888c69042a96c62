#pragma once

#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/topology.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// How computeMassProperties treats its input.
struct MassPropertiesOptions {
  double density = 1.0;  ///< kg/m³, finite and > 0
  /// A mesh whose signed volume is negative (faces wound inward) is an error unless this is set; when it
  /// is, the mesh is treated as flipped and the result says so.
  bool flipInsideOut = false;
  /// An open, non-manifold or inconsistently oriented mesh is an error unless this is set; when it is,
  /// the paper's vertex point-mass approximation (§4.1) is used and the result says it is approximate.
  bool allowApproximate = false;
};

/// Mass properties of a solid bounded by a triangle mesh, in the mesh's frame. Plain value type.
struct MassProperties {
  double density = 0.0;              ///< kg/m³
  double volume = 0.0;               ///< m³, > 0
  double mass = 0.0;                 ///< kg, density · volume
  double area = 0.0;                 ///< m², surface area
  Vec3 centerOfMass = Vec3::Zero();  ///< m, mesh frame
  Mat3 inertia = Mat3::Zero();       ///< kg m², about the centre of mass, mesh frame axes
  bool isApproximate = false;        ///< from vertex point masses, not exact surface integrals
  bool wasFlipped = false;           ///< the mesh was inside out and was flipped on request
};

/// Exact mass properties of the solid enclosed by a closed, consistently oriented triangle mesh, by
/// surface integrals (divergence theorem over the fan of tetrahedra from a vertex of the mesh), O(F).
/// `topology` must be analyzeTopology(mesh); preconditions: validateMesh(mesh) passed.
/// Errors: kNotClosed / kNonManifold / kInconsistentOrientation (unless allowApproximate), kInsideOut
/// (unless flipInsideOut), kZeroVolume, kInvalidArgument (density). Thread-safe (pure function).
Result<MassProperties> computeMassProperties(const TriangleMesh& mesh, const TopologyReport& topology,
                                             const MassPropertiesOptions& options = {});

/// As above, analyzing the topology first (O(F log F)); use the overload above when the report is at hand.
Result<MassProperties> computeMassProperties(const TriangleMesh& mesh,
                                             const MassPropertiesOptions& options = {});

/// The paper's point masses (§4.1), lumped by area: each vertex gets a third of the area of every
/// triangle it belongs to, m². Sums to the surface area. Used by the approximate fallback.
std::vector<double> vertexAreaWeights(const TriangleMesh& mesh);

/// Inertia tensor about the centre of mass from the volume covariance C = ∫ρ (p-c)(p-c)ᵀ dV:
/// I = tr(C)·Id − C.
inline Mat3 inertiaFromCovariance(const Mat3& covariance) {
  return covariance.trace() * Mat3::Identity() - covariance;
}
/// The inverse: C = tr(I)/2·Id − I (tr(I) = 2 tr(C)).
inline Mat3 covarianceFromInertia(const Mat3& inertia) {
  return 0.5 * inertia.trace() * Mat3::Identity() - inertia;
}

}  // namespace shapedb::core
